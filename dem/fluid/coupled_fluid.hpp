#pragma once
// The fluid state at this rank's particles when a fluid solver supplies it (two-way
// coupling, coupling/dem_link.hpp): the coupling samples the fluid at every local
// particle once per fluid step; the DEM then advances several sub-steps with those
// samples. Between two fluid steps particles may be re-sorted or migrate between ranks,
// so samples are kept by global id and re-mapped to the particles' current order when
// the order changes. A particle that arrived from another rank during the interval has
// no sample here: it is sampled on arrival through the coupling's sampler (it now lies
// in this rank's cells) and counted (late_samples).
//
// The fluid-force term writes back, per particle, the explicit part of the force that
// the fluid gets through the exchange term (exchange_force, in the particles' order of
// the last step): which forces that includes depends on the VANS model (vans_model.hpp).
#include <array>
#include <functional>
#include <unordered_map>
#include <vector>

#include "dem/core/particles.hpp"
#include "dem/fluid/fluid_sample.hpp"
#include "dem/fluid/self_disturbance.hpp"

namespace grainflow {

// What the fluid solver gives per particle: the fields that vary from particle to particle
// (80 B). The fluid's density and viscosity are the run's constants (set_constants), the
// vorticity is kept beside the records only when a force needs it, and the material
// derivative is not sampled (zero). Written once per fluid step for every particle and read
// at every DEM sub-step, so its size is the coupling's memory traffic.
struct CoupledSample {
  Vec3 velocity = Vec3::Zero();                   // u_f [m/s]
  double void_fraction = 1;                       // ε in (0, 1]
  Vec3 pressure_gradient = Vec3::Zero();          // ∇p [Pa/m]
  Vec3 viscous_stress_divergence = Vec3::Zero();  // ∇·τ [Pa/m]
};

// What the coupling knows of a particle's own disturbance of the fluid it samples, when the
// drag is to see the undisturbed velocity (couplingProperties undisturbedVelocity;
// self_disturbance.hpp): the size of the cells the footprint covers, the footprint's own
// spread and the drag coefficient per volume of the other particles around it (Brinkman
// screening), and where it sits in its cells. cell = 0: no correction for this particle.
struct SelfDisturbance {
  double cell = 0;       // h [m]
  double spread = 0;     // s [m], standard deviation per axis of the footprint's points
  double screening = 0;  // beta [kg/m^3/s]
  double smoothing = 0;  // sigma [m] of diffusionBandwidth's averaging (b / sqrt 2), 0 none
  // Per mesh axis x, y, z: the coefficients a_0..a_2 of the footprint's weight marginal on
  // the cells at offsets -1, 0, 1 from the particle's own (transverse_coefficients in
  // self_disturbance.hpp); the two axes across the motion are used. placed = false: not
  // known, or the footprint reaches further than one cell from the particle's own on some
  // axis; the place-averaged factor is used.
  std::array<std::array<double, 3>, 3> transverse{};
  bool placed = false;
  // sampling cellPoint (lattice_self_disturbance_cellpoint): the particle reads at its centre.
  // place: its offset from its cell's centre per mesh axis [cells]; marginals: the
  // footprint's weight marginal per axis on the cells -1, 0, 1 (weights, not coefficients).
  bool cell_point = false;
  std::array<double, 3> place{};
  std::array<std::array<double, 3>, 3> marginals{};
  // sampling cellPoint with diffusionBandwidth: the read's geometry for motion along each
  // mesh axis (cell_point_read), set with the rest (cell_point_reads_set).
  std::array<CellPointRead, 3> cell_point_reads{};
  bool cell_point_reads_set = false;
};

class CoupledFluid {
 public:
  using Sampler = std::function<FluidSample(const Vec3& x)>;
  // The samples in the particles' current order (at_particles): `vorticity` is null when
  // the set carries none (the forces that read it then see zero).
  struct View {
    const CoupledSample* samples = nullptr;
    const Vec3* vorticity = nullptr;
    const SelfDisturbance* disturbance = nullptr;  // null: no correction
    // Coupled heat (set with temperatures): the fluid temperature T_f [K] at each particle,
    // and each particle's entry in the set (for add_heat); null entry: entry i is particle i.
    const double* temperature = nullptr;
    const std::size_t* entry = nullptr;
    std::size_t size = 0;
    // sampling cellPoint: the footprint-weighted cell velocity U_fp at each particle, null
    // otherwise. The fluid's implicit exchange takes K (v - U_fp) from the cells; the rest of
    // the particle's drag, K (u_f - U_fp), goes back through exchange_force, so that the
    // fluid gets exactly the drag the particle feels.
    const Vec3* cell_velocity = nullptr;
  };

  void set_constants(double density, double viscosity) {
    density_ = density;
    viscosity_ = viscosity;
  }
  // Samples of the particles `ids` (any order), with their vorticity when `vorticity` is not
  // empty and their self-disturbance when `disturbance` is not empty (then one per id).
  // Replaces the previous set.
  // With `temperature` (one per id; coupled heat), the set also keeps, per entry, the
  // convective heat the particle took from the fluid during the DEM steps until the next
  // set (add_heat), where it last took it, and its last conductance h A. With
  // `cell_velocity` (one per id; sampling cellPoint) the footprint's cell velocity (View).
  void set(std::vector<GlobalId> ids, std::vector<CoupledSample> samples,
           std::vector<Vec3> vorticity = {}, std::vector<SelfDisturbance> disturbance = {},
           std::vector<double> temperature = {}, std::vector<Vec3> cell_velocity = {});
  // The storage of the set before the last set() (its values stale), for the next set to
  // be written into without a new allocation each fluid step; empty if taken already.
  std::vector<CoupledSample> take_spare() { return std::move(spare_); }
  std::vector<Vec3> take_spare_vorticity() { return std::move(spare_vorticity_); }
  std::vector<SelfDisturbance> take_spare_disturbance() { return std::move(spare_disturbance_); }
  std::vector<Vec3> take_spare_cell_velocity() { return std::move(spare_cell_velocity_); }
  void set_sampler(Sampler sampler) { sampler_ = std::move(sampler); }
  // The samples in the current order of `p` (cheap when the order has not changed).
  View at_particles(const Particles& p);
  // Sample i of a view as the force terms read it.
  FluidSample sample(const View& v, std::size_t i) const {
    const CoupledSample& c = v.samples[i];
    FluidSample f;
    f.velocity = c.velocity;
    f.void_fraction = c.void_fraction;
    f.pressure_gradient = c.pressure_gradient;
    f.viscous_stress_divergence = c.viscous_stress_divergence;
    f.density = density_;
    f.viscosity = viscosity_;
    if (v.vorticity) f.vorticity = v.vorticity[i];
    return f;
  }
  long late_samples() const { return late_; }

  // Coupled heat: particle `entry` (View::entry) took `joules` from the fluid at x in a DEM
  // step, with conductance h A = `conductance` [W/K].
  void add_heat(std::size_t entry, double joules, const Vec3& x, double conductance) {
    heat_[entry] += joules;
    heat_x_[entry] = x;
    heat_conductance_[entry] = conductance;
  }
  // Per entry of the set (ids in the set's order, late arrivals appended): the heat taken
  // since set() [J], the position of its last exchange and the last conductance [W/K].
  const std::vector<GlobalId>& entry_ids() const { return ids_; }
  const std::vector<double>& entry_heat() const { return heat_; }
  const std::vector<Vec3>& entry_heat_position() const { return heat_x_; }
  const std::vector<double>& entry_conductance() const { return heat_conductance_; }
  std::vector<double> take_spare_temperature() { return std::move(spare_temperature_); }
  void reset_late_samples() { late_ = 0; }

  // Per particle of the last step, in its order: the explicit force on the particle
  // that the fluid gets back (with opposite sign) through the exchange term [N].
  std::vector<Vec3> exchange_force;

 private:
  double density_ = 0, viscosity_ = 0;
  std::vector<GlobalId> ids_;
  std::vector<CoupledSample> samples_;
  std::vector<Vec3> vorticity_;  // empty, or one per entry of samples_
  std::vector<SelfDisturbance> disturbance_;  // empty, or one per entry of samples_
  std::vector<CoupledSample> spare_;  // the previous samples_ (take_spare)
  std::vector<Vec3> spare_vorticity_;
  std::vector<SelfDisturbance> spare_disturbance_;
  std::vector<double> temperature_, spare_temperature_;  // empty, or one per entry
  std::vector<Vec3> cell_velocity_, spare_cell_velocity_;  // empty, or one per entry
  std::vector<double> heat_, heat_conductance_;         // coupled heat, per entry
  std::vector<Vec3> heat_x_;
  std::unordered_map<GlobalId, std::size_t> index_;  // built on the first re-map after set()
  // After a re-sort, migration or late arrival: the samples in the particles' new order.
  // Until then the samples are served as set (no copy per fluid step).
  bool remapped_ = false;
  std::vector<GlobalId> mapped_ids_;                 // order of `mapped_`
  std::vector<CoupledSample> mapped_;
  std::vector<Vec3> mapped_vorticity_;
  std::vector<SelfDisturbance> mapped_disturbance_;
  std::vector<double> mapped_temperature_;
  std::vector<Vec3> mapped_cell_velocity_;
  std::vector<std::size_t> mapped_entry_;
  Sampler sampler_;
  long late_ = 0;
};

}  // namespace grainflow
