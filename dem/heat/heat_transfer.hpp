#pragma once
// Particle temperatures (scene key `heat:`; docs/models/heat-transfer.md): one pass per step
// over the contacts of the step's neighbour lists and walls, after the forces, then one
// over the particles:
//   m_i c_i dT_i/dt = sum_j Q_ij + sum_walls Q_iw + h_i A_i (T_f - T_i) + m_i q_i,
// conduction Q (heat_laws.hpp) explicit at the step's start temperatures and end positions,
// convection implicit in T_i:
//   T_i' = (T_i + dt/C_i (Q_i + m_i q_i + H_i T_f)) / (1 + dt H_i / C_i),  C = m c, H = h A.
// A pair's heat is computed once per rank that holds it, from the same bits on both ranks,
// and added to one partner and subtracted from the other: what one gains the other loses
// exactly, within a rank and across a cut. With parallel.reproducible the pairs are visited
// in the contact sweep's canonical order. The Simulation owns one only when heat is on;
// off, no thermal code runs.
#include <optional>
#include <vector>

#include "dem/core/particles.hpp"
#include "dem/engine/canonical_order.hpp"
#include "dem/fluid/coupled_fluid.hpp"
#include "dem/fluid/void_fraction_grid.hpp"
#include "dem/neighbour/verlet_list.hpp"
#include "dem/neighbour/wall_neighbours.hpp"
#include "dem/parallel/ghosts.hpp"
#include "dem/scene/scene.hpp"
#include "dem/walls/wall_set.hpp"

namespace grainflow {

// The factor f of the contact radius a = f sqrt(R* delta) of each pair of materials
// [a * materials + b] (heat.contact_radius; heat_laws.hpp): 1 with `geometric`, Morris et
// al.'s (2016) correction for the real Young's moduli otherwise.
std::vector<double> contact_radius_factors(const Scene& scene);

class HeatTransfer {
 public:
  explicit HeatTransfer(const Scene& scene);

  // Advances the local particles' temperatures by dt. `ghost_temperature`: each ghost's
  // owner's temperature at the step's start (Exchange::forward_values). `canonical`
  // (parallel.reproducible): the pairs' order of the contact sweep, built for these lists,
  // so that temperatures are the same bit for bit on every decomposition; nullptr: the
  // local list, then the ghost list.
  void step(Particles& p, const Ghosts& g, const std::vector<double>& ghost_temperature,
            const NeighbourList& local, const NeighbourList& ghost, const WallSet& walls,
            const WallNeighbours& wall_neighbours, double dt,
            const CanonicalOrder* canonical = nullptr);

  // Heat that entered this rank's particles through each wall in the last step [W]
  // (negative: left through it), in WallSet order.
  const std::vector<double>& wall_heat() const { return wall_heat_; }
  // Heat that entered this rank's particles from the fluid in the last step [W], and from
  // the materials' sources.
  double fluid_heat() const { return fluid_heat_; }
  double source_heat() const { return source_heat_; }

  double heat_capacity(int material) const { return cp_[material]; }

  // Two-way coupling (grainFoam): convection reads the fluid temperature, velocity and void
  // fraction of each particle from `fluid`'s samples (set with temperatures) instead of the
  // prescribed fluid, and records each particle's heat into the set (CoupledFluid::add_heat)
  // for the fluid's energy equation. Needs the scene's fluid `temperature:` block (the
  // convection law, c_p and k_f); `fluid` must outlive this object.
  void couple(CoupledFluid* fluid) { coupled_ = fluid; }
  // One-way mode with fluid.void_fraction computed from the particles: convection reads each
  // particle's eps from `grid` (the fluid forces' grid, updated in their add() at the step's
  // end positions, before this step) instead of the uniform value. `grid` must outlive this.
  void use_void_fraction(const VoidFractionGrid* grid) { void_fraction_ = grid; }
  // Thermal energy sum m c T of this rank's particles [J].
  double thermal_energy(const Particles& p) const;

 private:
  void coupled_step(Particles& p, double dt);  // the particles' pass with couple()
  void walls_pass(const Particles& p, const WallSet& walls, const WallNeighbours& wn);

  int materials_ = 0;
  bool conduction_ = true;
  // [a * materials + b], symmetric: k* times the contact-radius factor f (the conductance
  // 2 k* f sqrt(R* delta)); f itself for the flux walls' area pi (f a)^2.
  std::vector<double> k_star_, radius_factor_;
  std::vector<double> cp_, source_, k_;
  std::vector<double> coarse_grain_;       // per material: its parcels' k (1: real particles)
  std::vector<WallThermal> wall_thermal_;  // per scene wall (= WallSet entry)
  std::optional<FluidThermal> fluid_thermal_;
  PrescribedFluid field_;
  CoupledFluid* coupled_ = nullptr;
  const VoidFractionGrid* void_fraction_ = nullptr;
  bool computed_void_fraction_ = false;  // the scene's eps comes from the particles
  Vec3 gravity_ = Vec3::Zero();
  std::vector<double> q_;  // heat flow into each local particle in this step [W]
  std::vector<double> wall_heat_;
  double fluid_heat_ = 0, source_heat_ = 0;
};

}  // namespace grainflow
