#pragma once
// The serial DEM engine: particles, walls, neighbour list, contact sweep and a
// velocity-Verlet integrator for translation and rotation.
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "dem/contact/contact_geometry.hpp"
#include "dem/contact/pair_coefficients.hpp"
#include "dem/core/particles.hpp"
#include "dem/engine/contact_sweep.hpp"
#include "dem/engine/force_term.hpp"
#include "dem/engine/time_step.hpp"
#include "dem/neighbour/verlet_list.hpp"
#include "dem/scene/scene.hpp"

namespace grainflow {

// Run-time problem that is the scene's fault but only visible once particles exist
// (periodic box too short for the particles, dt needs particles, ...).
class SetupError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Counters {
  long steps = 0;
  long rebuilds = 0;
  long removed = 0;   // particles that left a bounded side of the domain
  long contacts = 0;  // in the last step
  double max_overlap_ratio = 0;  // in the last step
};

class Simulation {
 public:
  // Inserts the scene's particles; `insert = false` starts empty (tests add their own).
  explicit Simulation(const Scene& scene, bool insert = true);

  // Adds a non-contact force term (evaluated every step after contacts).
  void add_force_term(std::unique_ptr<ForceTerm> term) { terms_.push_back(std::move(term)); }
  const ImplicitDrag& implicit_drag() const { return drag_; }

  // Call after adding or editing particles by hand, before the first step.
  void initialise();
  void step();
  void advance_to(double t_end);

  Particles& particles() { return p_; }
  const Particles& particles() const { return p_; }
  const Scene& scene() const { return scene_; }
  double time() const { return time_; }
  double dt() const { return dt_; }
  void set_dt(double dt) { dt_ = dt; }
  double skin() const { return skin_; }
  const Counters& counters() const { return counters_; }
  const TimeStepReport& time_step_report() const { return report_; }
  const std::string& contact_law_name() const { return sweep_.name; }
  const NeighbourList& neighbour_list() const { return list_; }
  const PairTable& pair_table() const { return table_; }
  GlobalId next_id() const { return next_id_; }
  GlobalId& next_id() { return next_id_; }

  double kinetic_energy_translational() const;
  double kinetic_energy_rotational() const;

 private:
  void rebuild();
  void compute_forces();
  bool needs_rebuild() const;
  void apply_boundaries();  // periodic wrap; removal of particles that left
  void half_kick();         // v += dt/2 F/m (implicit in v where drag is set), same for spin

  Scene scene_;
  Particles p_;
  GlobalId next_id_ = 1;
  PairTable table_;
  ContactConstants constants_;
  Box box_;
  SweepChoice sweep_;
  double dt_ = 0, time_ = 0, skin_ = 0;
  std::unique_ptr<BinGrid> grid_;
  NeighbourList list_;
  std::vector<ContactHistory> pair_history_;
  std::vector<std::vector<ContactHistory>> wall_history_;
  std::vector<Vec3> x_at_build_;
  std::vector<char> leaving_;
  std::vector<std::unique_ptr<ForceTerm>> terms_;
  ImplicitDrag drag_;
  Counters counters_;
  TimeStepReport report_;
  bool initialised_ = false;
};

}  // namespace grainflow
