#pragma once
// The DEM engine on one MPI rank's box: local particles, ghosts from neighbouring
// ranks (and periodic images), walls, neighbour lists, the contact sweep and a
// velocity-Verlet integrator for translation and rotation. With one rank the same
// code runs with no neighbours but itself across periodic sides.
#include <mpi.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "dem/contact/contact_geometry.hpp"
#include "dem/contact/pair_coefficients.hpp"
#include "dem/core/particles.hpp"
#include "dem/engine/contact_sweep.hpp"
#include "dem/engine/force_term.hpp"
#include "dem/engine/overload.hpp"
#include "dem/engine/time_step.hpp"
#include "dem/heat/heat_transfer.hpp"
#include "dem/insert/stream_insertion.hpp"
#include "dem/io/checkpoint.hpp"
#include "dem/io/snapshot_writer.hpp"
#include "dem/neighbour/verlet_list.hpp"
#include "dem/neighbour/wall_neighbours.hpp"
#include "dem/parallel/decomposition.hpp"
#include "dem/parallel/exchange.hpp"
#include "dem/parallel/ghosts.hpp"
#include "dem/scene/scene.hpp"
#include "dem/walls/wall_set.hpp"

namespace grainflow {

struct WallTravelReport;  // dem/walls/wall_travel.hpp

// Run-time problem that is the scene's fault but only visible once particles exist
// (periodic box too short for the particles, dt needs particles, ...).
class SetupError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Counters of this rank (local) — see Simulation::global_counters for run totals.
struct Counters {
  long steps = 0;
  long rebuilds = 0;
  long removed = 0;              // particles that left a bounded side of the domain
  long contacts = 0;             // in the last step
  double max_overlap_ratio = 0;  // in the last step
};

struct GlobalState {
  long particles = 0;
  long contacts = 0;
  long removed = 0;
  double max_overlap_ratio = 0;
  double kinetic_translational = 0;
  double kinetic_rotational = 0;
};

// The particle that moved the most of its own radius in the last drift, when any could have
// moved more than time.max_step_travel radii (ratio: travel / (limit r); 0: none), with the
// speed it drifted at.
struct FastParticle {
  double ratio = 0;
  std::size_t index = 0;
  double speed = 0;
};

// What a step's force evaluation found for the guards (Simulation::check_contacts).
struct ContactGuards {
  WorstContact worst;            // the contact with the largest overlap ratio
  UnresolvedContact unresolved;  // the least-resolved Hertz contact
  FastParticle fast;             // the travel guard's candidate
};

class Simulation {
 public:
  // Inserts the scene's particles (every rank inserts the same set; initialise()
  // keeps each on the rank that owns it). `insert = false` starts empty: tests add
  // particles by hand — on every rank alike — before initialise().
  // processor_grid {0,0,0} takes the scene's `parallel.grid`; when that is {0,0,0} too, the
  // grid and its cut planes are chosen by initialise() (docs/parallel.md, "The default
  // grid"): those of the checkpoint restored on as many ranks, else for the particles then
  // present, unless set_cut_planes() imposed planes.
  explicit Simulation(const Scene& scene, bool insert = true, MPI_Comm comm = MPI_COMM_WORLD,
                      std::array<int, 3> processor_grid = {0, 0, 0});

  // Adds a non-contact force term (evaluated every step after contacts); call
  // before initialise().
  // A term that computes the void fraction from the particles (fluid.void_fraction:
  // {cell_size, ...}) lends it to convection (HeatTransfer::use_void_fraction).
  void add_force_term(std::unique_ptr<ForceTerm> term);
  const ImplicitDrag& implicit_drag() const { return drag_; }
  // The force terms' stability limits found at initialise() (TermLimit), the same on every
  // rank, and the same as one line: each term with dt / its time scale, for messages.
  const std::vector<TermLimit>& force_limits() const { return force_limits_; }
  std::string force_limits_summary() const;
  // The lines check_force_limits() added to the time-step report (also for runs that do not
  // print the report, the coupled DEM).
  // Collective: the fluid forces' stability limits at the present state; throws SetupError when
  // dt is beyond one of them (the slip or spin grew since start-up, where check_force_limits
  // looked). Called by the run at each log row.
  void recheck_force_limits();
  const std::vector<std::string>& force_limit_notes() const { return force_limit_notes_; }
  // Lines on fills whose outcome differs from what they asked (insert_particles).
  const std::vector<std::string>& insertion_notes() const { return insertion_notes_; }
  std::vector<std::string> force_term_reports() const {
    std::vector<std::string> out;
    for (const auto& t : terms_) out.push_back(t->report());
    return out;
  }

  // Imposes non-uniform cut planes along one axis (e.g. from a mesh decomposition);
  // call before initialise(). Throws SetupError when they do not fit the grid.
  void set_cut_planes(int axis, const std::vector<double>& planes);

  // Continues from a checkpoint: call before initialise() with the whole checkpoint
  // on every rank (read_checkpoint); each rank keeps what it owns, springs included.
  // The scene must be the one the checkpoint was written with.
  void restore(const CheckpointData& checkpoint);
  // Writes the complete dynamic state, readable on any number of ranks, then
  // rebuilds the neighbour lists exactly as a restart from that file will, so that a
  // run restarted on the same rank count continues bit-identically. Collective.
  void write_checkpoint(const std::string& path);
  // The run's log table as the checkpoints written from now on store it (LogTable::record(),
  // read on rank 0 when a checkpoint is written); null (the default): no log in them.
  void set_log_record(const std::string* record) { log_record_ = record; }

  // Checks the time step, distributes particles to their ranks, builds lists and
  // the first forces. Collective. Called by the first step() if not before.
  void initialise();
  void step();
  void advance_to(double t_end);
  // Wall-clock seconds this rank has spent in the two collectives of every step (the contact
  // guards' reduction at its end and the rebuild check at the next one's start): where a
  // rank that finished its forces early waits for the busiest (load imbalance).
  double collective_wait_seconds() const { return collective_wait_seconds_; }

  Particles& particles() { return p_; }  // this rank's particles
  const Particles& particles() const { return p_; }
  // Whether every position, velocity and spin of this rank's particles was finite at the
  // end of the last step() (checked in its last pass over the particles).
  bool state_finite() const { return state_finite_; }
  // The same for every rank's particles, agreed in the step's one reduction (collective
  // answer, no communication here).
  bool state_finite_everywhere() const { return finite_everywhere_; }
  const Ghosts& ghosts() const { return ghosts_; }
  const Scene& scene() const { return scene_; }
  const WallSet& walls() const { return walls_; }               // current wall positions
  const StreamInsertion& streams() const { return streams_; }  // stream insertion totals
  const Decomposition& decomposition() const { return *decomp_; }
  // `width` values per local particle → the same values at each ghost (Exchange::forward_values).
  // Collective; valid between steps, while the ghost lists of the last rebuild stand.
  std::vector<double> ghost_values(const std::vector<double>& local, std::size_t width) const {
    std::vector<double> out;
    exchange_->forward_values(local, width, out);
    return out;
  }
  // Adds each ghost's `width` values to its owner's `local` values (Exchange::reverse_values).
  void add_ghost_values(std::vector<double>& local, std::size_t width,
                        std::vector<double> ghost) const {
    exchange_->reverse_values(local, width, ghost);
  }
  // Heat transfer (scene key `heat:`), or nullptr when it is off.
  const HeatTransfer* heat() const { return heat_.get(); }
  HeatTransfer* heat() { return heat_.get(); }
  double time() const { return time_; }
  double dt() const { return dt_; }
  void set_dt(double dt) { dt_ = dt; }
  double skin() const { return skin_; }
  // initialise(): the largest radius now, of a stream's particles to come, or of the run a
  // restart continues (the one that sizes the skin and the cutoff).
  double largest_radius() const { return largest_radius_; }
  const Counters& counters() const { return counters_; }
  GlobalState global_state() const;  // collective
  const TimeStepReport& time_step_report() const { return report_; }
  const std::string& contact_law_name() const { return sweep_.name; }
  const NeighbourList& neighbour_list() const { return local_list_; }
  const PairTable& pair_table() const { return table_; }
  GlobalId next_id() const { return next_id_; }
  GlobalId& next_id() { return next_id_; }

  // Snapshot fields beyond the particle state, at the end of the last step (or of
  // initialise()), for the fields of `fields` (others stay empty). force and torque: the
  // totals the next half kick uses, the implicit drag K (u - v) included at the present v;
  // fluid_force: the force terms' part of it (needs record_fluid_force() on for the step
  // that computed the forces; zero without force terms); coordination and overlap_max:
  // one pass over the touching contacts (overlap > 0) of the step's lists and walls.
  // Not collective.
  SnapshotExtras snapshot_extras(SnapshotFieldSet fields) const;
  // Keeps the force terms' explicit part of each particle's force in the force evaluations
  // that follow (one copy of the forces per evaluation), for snapshot_extras' fluid_force.
  void record_fluid_force(bool on) { record_fluid_ = on; }
  // Keeps the contact network (output.contacts) of the force evaluations that follow: one
  // report pass over the contacts before each such evaluation's sweep (ReportFunction,
  // contact_sweep.hpp); off, nothing is done. Turn it on for the steps that end with a
  // snapshot.
  void record_contacts(bool on) { record_contacts_ = on; }
  // The contact network of the last force evaluation, recorded there (see record_contacts).
  // Throws std::logic_error when that evaluation did not record it (off, or the forces
  // came from a checkpoint). Not collective: this rank's contacts.
  const ContactNetwork& contact_network() const;
  // Whether contact_network() holds the last force evaluation's network.
  bool contact_network_recorded() const { return network_recorded_; }

  // output.wall_loads: each wall's load (WallSet order): the mean force the particles
  // exerted on it by contact (minus the sum of the wall's contact forces on them) over
  // `interval`, the simulated time since the last call, the start, or the checkpoint
  // restored (one written with output.wall_loads carries the time before it). Resets the
  // sums, unless `reset` is false (a log row that is not part of the run's record, see
  // LogTable::write). Collective; `force` is empty when output.wall_loads is off.
  struct WallLoads {
    std::vector<Vec3> force;  // [N]
    double interval = 0;      // [s]
  };
  WallLoads take_wall_loads(bool reset = true);

  // Largest over mean particle count per rank (1 = perfectly balanced). Collective.
  double load_imbalance() const;

  // Where initialise() took the processor grid from.
  enum class GridChoice {
    given,             // processor_grid or the scene's `parallel.grid`, uniform planes
    imposed,           // set_cut_planes()
    checkpoint,        // the restored checkpoint's grid and planes (written on as many ranks)
    particles,         // the default rule for the particles present at initialise()
    domain,            // the default rule for the domain alone (no particles yet, or streams)
    given_checkpoint,  // the scene's `parallel.grid`, the planes where the checkpoint's run
                       // had them (moved by parallel.balance): a restart on as many ranks
  };
  GridChoice grid_choice() const { return grid_choice_; }

  double kinetic_energy_translational() const;  // this rank
  double kinetic_energy_rotational() const;     // this rank

 private:
  void rebuild(bool keep_drag = false);
  // Moves cut planes toward equal particle counts (collective); never planes imposed by
  // set_cut_planes().
  void balance_cuts();
  // The bins of the neighbour search: over this rank's box widened by the interaction range,
  // or with parallel.reproducible the lattice anchored at the domain (BinGrid::anchored),
  // the same on every rank, whose bins are the particles' keys (canonical_order.hpp).
  void make_bin_grid();
  // The default grid (automatic grid, no imposed planes, no checkpoint grid for this rank
  // count): the least cut area through the particles' extent among the grids whose boxes are
  // at least as thick as the interaction range, planes at the particle-count quantiles;
  // without particles at the start, or with stream insertions, for the domain alone with
  // uniform planes. Every rank holds every particle when it runs, so all choose the same.
  void fit_grid_to_particles();
  // The checkpoint's grid and planes (restore(), written on as many ranks).
  void take_restored_grid(const CheckpointGrid& grid);
  void remake_decomposition(const std::array<int, 3>& dims);  // uniform planes
  // Gravity, contacts, then the force terms. `advance_springs` false: the forces of the
  // initial state, whose contact springs have not moved (initialise()).
  ContactGuards compute_forces(bool advance_springs = true);
  void finish_forward();
  void apply_force_terms();  // non-contact terms only
  // Heat on: the ghosts' temperatures from their owners, then HeatTransfer::step (collective).
  void advance_temperatures();
  void restore_implicit_drag();  // initialise() after restore()
  // The terms' implicit spin drag at the present state, in the present order (after a
  // checkpoint's rebuild, or a restore); forces, torques and drag unchanged.
  void refresh_spin_drag();
  // Each force term's stability limit at the present state, over every rank; notes in the
  // time-step report, and a refusal there for a step beyond an explicit term's limit.
  void check_force_limits();
  std::vector<TermLimit> gather_force_limits() const;  // collective
  // Stops the run (ParallelError on every rank) when a contact overlaps beyond
  // time.max_overlap, or when a Hertz contact gets fewer than time.min_steps_per_contact
  // steps at its own approach speed; the message names the contact and a time step that
  // would resolve it; and when a particle moved more than time.max_step_travel of its
  // radii in the last drift (`guards.fast`). Returns whether every rank's state is finite
  // (`finite_here`: this rank's). Collective: the step's one reduction.
  bool check_contacts(const ContactGuards& guards, bool finite_here) const;
  // The overlap guard's diagnosis of the contact `w` at `ratio` of the smaller radius
  // (overload.hpp): a step that resolves it, or what carries the load (error path only).
  void describe_overlap(std::ostream& o, const WorstContact& w, double ratio) const;
  FastParticle fastest_particle(double v2_max) const;  // v2_max: largest local |v|^2
  // Whether any contact of this step could fail the steps-per-contact test (else the
  // sweep skips it): a bound from the fastest local (v2_local: its |v|^2) or ghost particle.
  bool contact_may_be_unresolved(double v2_local) const;
  bool needs_rebuild() const;  // collective
  // The walls' travel guard (dem/walls/wall_travel.hpp): notes into the report, SetupError
  // when a wall moves too far per step.
  void check_walls_travel();
  // SetupError when a particle could cross a mesh wall within one step without an overlap
  // above time.max_overlap (r_min: the smallest radius present or to come; 0: none).
  // Keeps mesh_walls_ and mesh_wall_travel_ for the overlap guard's advice.
  void check_mesh_tunnelling(const WallTravelReport& walls, double r_min);
  void mark_leaving();  // particles beyond a bounded side of the domain
  // The first half kick and x += dt v in one pass, with mark_leaving()'s test, the skin test
  // and the largest local |v|^2 (for contact_may_be_unresolved()); forces and torques set to
  // gravity and zero for the next evaluation.
  void kick_and_drift();
  // v += dt/2 F/m (implicit in v where drag is set), same for spin. With Guard: returns
  // whether every position, velocity and spin is finite after it (false otherwise).
  template <bool Guard>
  bool half_kick();
  // Every stretched spring by global ids (CarriedSprings); the lists' and walls' springs are
  // released (a rebuild makes them anew: the old and new copies do not coexist).
  CarriedState take_histories();
  // The springs of the new lists and walls, from `carried` (whose springs it releases).
  void restore_histories(CarriedState& carried);
  void apply_order(const std::vector<std::size_t>& perm, CarriedState& carried);

  Scene scene_;
  MPI_Comm comm_;
  // A forward exchange begun by step() and not yet ended: the ghosts' fields travel while
  // compute_forces sweeps the local pairs; finish_forward() ends it (idempotent).
  bool forward_pending_ = false;
  mutable double collective_wait_seconds_ = 0;  // see collective_wait_seconds()
  std::unique_ptr<Decomposition> decomp_;
  std::unique_ptr<Exchange> exchange_;
  Particles p_;
  Ghosts ghosts_;
  GlobalId next_id_ = 1;
  PairTable table_;
  ContactConstants constants_;
  SweepChoice sweep_;
  double dt_ = 0, time_ = 0, skin_ = 0, cutoff_ = 0;
  // For contact_may_be_unresolved, set at each rebuild: min m^2/r over local and ghost
  // particles, and the largest Y* of a pair involving one of their materials.
  double lightest_q_ = 0, largest_y_star_ = 0;
  double smallest_radius_ = 0;  // of the local particles, set at each rebuild (travel guard)
  std::unique_ptr<BinGrid> grid_;
  NeighbourList local_list_, ghost_list_;
  ListSprings local_springs_, ghost_springs_;              // parallel to the lists' entries
  // [WallSet column][entry of the wall's list, or particle]: the layout of wall_neighbours.hpp
  std::vector<std::vector<ContactHistory>> wall_history_;
  WallNeighbours wall_neighbours_;  // rebuilt with the Verlet lists
  UniformPairs uniform_;            // found with the Verlet lists
  CanonicalOrder canonical_;        // parallel.reproducible: built with the Verlet lists
  WallSet walls_;
  StreamInsertion streams_;
  std::vector<Vec3> x_at_build_;
  std::vector<char> leaving_;
  // Set by needs_rebuild (agreed over the ranks): a particle leaving the domain has its
  // centre behind a plane or cylinder wall, i.e. crossed it within a step; rebuild() stops
  // the run instead of counting it as removed.
  mutable bool left_through_wall_ = false;
  std::string left_through_wall_message() const;
  std::vector<std::unique_ptr<ForceTerm>> terms_;
  std::unique_ptr<HeatTransfer> heat_;       // scene.heat; null: no thermal code runs
  std::vector<double> ghost_temperature_;    // each ghost's, at the step's start (heat on)
  // Each ghost's owner's force (3 per ghost), forwarded on the overlap guard's error path
  // only (check_contacts) for describe_overlap's loads.
  mutable std::vector<double> ghost_force_;
  ImplicitDrag drag_;
  std::vector<TermLimit> force_limits_;
  std::vector<std::string> force_limit_notes_;
  std::vector<std::string> insertion_notes_;
  Counters counters_;
  // record_fluid_force(): the force terms' explicit force on each particle, as of the last
  // force evaluation that recorded it.
  bool record_fluid_ = false;
  std::vector<Vec3> fluid_explicit_;
  // output.wall_loads (else empty): the walls' contact forces on this rank's particles in
  // the last sweep, and their time integral over wall_load_time_ since the last
  // take_wall_loads() (on rank 0 also a restored checkpoint's global sums).
  std::vector<Vec3> wall_forces_, wall_impulse_;
  double wall_load_time_ = 0;
  const std::string* log_record_ = nullptr;  // set_log_record()
  // check_mesh_tunnelling(): the scene has mesh walls (and particles), and the fastest moving
  // mesh's travel per step in smallest radii.
  bool mesh_walls_ = false;
  double mesh_wall_travel_ = 0;
  bool record_contacts_ = false;   // record_contacts()
  bool network_recorded_ = false;  // network_ is the last force evaluation's
  ContactNetwork network_;
  TimeStepReport report_;
  std::vector<CheckpointSpring> restored_springs_;  // from restore(), until initialise()
  // The checkpoint's implicit drag by global id (K, u), until initialise().
  std::unordered_map<GlobalId, std::pair<double, Vec3>> restored_drag_;
  std::optional<CarriedState> pending_carried_;     // springs for the first rebuild
  bool moved_beyond_half_skin_ = false;             // by the last drift(), since the last rebuild
  double local_speed2_ = 0;                         // largest local |v|^2 after this step's drift
  bool fresh_from_kick_ = false;  // kick_and_drift() ran (speeds, gravity) and no rebuild since
  bool state_finite_ = true;                        // after the last step(), this rank's particles
  bool finite_everywhere_ = true;                   // the same, every rank's
  bool restored_ = false;                           // initialise() keeps the forces read
  std::optional<CheckpointGrid> restored_grid_;     // from restore(), until initialise()
  GridChoice grid_choice_ = GridChoice::given;
  bool automatic_grid_ = false;  // neither the caller nor the scene gave the grid
  bool cuts_imposed_ = false;    // set_cut_planes() was called
  bool initialised_ = false;
  double largest_radius_ = 0;  // initialise(): the radius that sets skin_ and cutoff_
  std::optional<double> restored_largest_radius_;  // from restore(): the earlier run's
};

}  // namespace grainflow
