#pragma once
// The DEM as the fluid solver sees it. This header is C++17-clean (the OpenFOAM side
// compiles as C++17, the DEM core as C++20) and exposes only plain data: the
// implementation (dem_link.cpp) owns a grainflow::Simulation behind a pointer.
//
// One coupled step (DESIGN.md §1), driven by grainFoam through coupling/foam/:
//   sample the fluid at each local particle of the last view() → begin_fluid(),
//   add_fluid() per particle, end_fluid() → advance(N) → view() → void fraction and
//   momentum source on the mesh.
#include <mpi.h>

#include <array>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace grainflow::coupling {

struct Box {
  std::array<double, 3> lo{}, hi{};
};

// The fluid at one particle, SI units (pressure gradient in Pa/m, not kinematic).
struct FluidAtParticle {
  std::array<double, 3> velocity{};
  double void_fraction = 1;
  std::array<double, 3> pressure_gradient{};
  std::array<double, 3> viscous_stress_divergence{};
  std::array<double, 3> vorticity{};
  // The particle's own disturbance of these values (DemLink::correct_self_disturbance):
  // the size h [m] of the cells its footprint covers (0: no correction), the footprint's own
  // spread s [m] (standard deviation per axis of its points) and the drag coefficient per
  // volume of the other particles there [kg/m^3/s].
  double disturbance_cell = 0;
  double disturbance_spread = 0;
  double disturbance_screening = 0;
  // diffusionBandwidth: the averaging's standard deviation per axis sigma = b / sqrt 2 [m].
  double disturbance_smoothing = 0;
  // The footprint's weight marginal on each mesh axis over the cells at offsets -1, 0, 1 from
  // the particle's own (fractions of its weight), when the footprint reaches no further on
  // any axis (disturbance_placed; else the place-averaged disturbance is used).
  std::array<std::array<double, 3>, 3> disturbance_weights{};
  bool disturbance_placed = false;
  // sampling cellPoint: the particle reads at its centre, at disturbance_place from its
  // cell's centre per mesh axis [cells] (self_disturbance.hpp, lattice_self_disturbance_cellpoint).
  bool disturbance_cell_point = false;
  std::array<double, 3> disturbance_place{};
  double temperature = 0;  // T_f [K] (coupled heat; see DemLink::heat_on)
};

// The particles' convective heat exchange with the fluid over the last advance()
// (DemLink::heat_exchange; docs/models/heat-transfer.md, "Coupled"). Entries [0, local) are
// this rank's particles, [local, size) the ghosts, in the order of DemLink::view().
struct HeatExchange {
  std::vector<double> heat;      // taken from the fluid during the advance [J]
  std::vector<double> response;  // G = C (1 - (1 + dt H / C)^-N) [J/K]: the heat the
                                 // particle would have taken more per kelvin of fluid
  // Heat taken on this rank by particles that are no longer local (they left during the
  // advance): where each last took it [m] and how much [J].
  std::vector<std::array<double, 3>> orphan_position;
  std::vector<double> orphan_heat;
};

// Particles as flat arrays: entries [0, local) are this rank's particles, entries
// [local, size) ghosts (copies of neighbours' particles, or periodic images, at their
// image position), present only when asked for.
struct ParticleSet {
  std::size_t local = 0;
  std::vector<long long> id;
  std::vector<std::array<double, 3>> x, v;
  std::vector<double> radius;
  // Filled by particles(true) only, from the last DEM step: drag coefficient K [kg/s] of
  // F = K (u_f − v), and the explicit force on the particle that the fluid gets back
  // through the exchange term (model dependent) [N].
  std::vector<double> drag_coefficient;
  std::vector<std::array<double, 3>> exchange_force;
  std::size_t size() const { return id.size(); }
};

// This rank's particles and their ghosts as the coupling reads them every fluid step
// (DemLink::view()), without copying the local ones: entries [0, local()) read the DEM's own
// arrays and stay valid until the DEM next changes them (advance(), write_checkpoint(),
// restore()); entries [local(), size()) are ghosts, copied (their positions are images).
// The same values as particles(true).
class ParticleView {
 public:
  std::size_t local() const { return local_; }
  std::size_t size() const { return local_ + ghost_radius_.size(); }
  const double* x(std::size_t i) const {
    return i < local_ ? x_ + 3 * i : ghost_x_[i - local_].data();
  }
  const double* v(std::size_t i) const {
    return i < local_ ? v_ + 3 * i : ghost_v_[i - local_].data();
  }
  double radius(std::size_t i) const { return i < local_ ? radius_[i] : ghost_radius_[i - local_]; }
  // K [kg/s] of the last step (0 for a particle that has none yet).
  double drag_coefficient(std::size_t i) const {
    return i < local_ ? (i < drag_count_ ? drag_[i] : 0.0) : ghost_drag_[i - local_];
  }
  // The explicit force the fluid gets back [N] (zero when the last step left none).
  std::array<double, 3> exchange_force(std::size_t i) const {
    if (i >= local_) return ghost_force_[i - local_];
    if (i >= force_count_) return {0, 0, 0};
    return {force_[3 * i], force_[3 * i + 1], force_[3 * i + 2]};
  }

 private:
  friend class DemLink;
  std::size_t local_ = 0, drag_count_ = 0, force_count_ = 0;
  const double* x_ = nullptr;  // 3 per particle
  const double* v_ = nullptr;
  const double* radius_ = nullptr;
  const double* drag_ = nullptr;
  const double* force_ = nullptr;
  std::vector<std::array<double, 3>> ghost_x_, ghost_v_, ghost_force_;
  std::vector<double> ghost_radius_, ghost_drag_;
};

// The processor grid the fluid mesh decomposition implies (shared_decomposition.hpp).
struct ProcessorGrid {
  std::array<int, 3> dims{1, 1, 1};
  std::array<std::vector<double>, 3> cuts;  // dims[a] + 1 planes per axis
  std::array<int, 3> coords{0, 0, 0};       // this rank's box
};

struct DemSummary {
  long particles = 0, contacts = 0, removed = 0, late_samples = 0;
  double max_overlap_ratio = 0, kinetic_energy = 0;
  // This rank's own: particles owned, and the wall-clock seconds its DEM has spent waiting
  // in the steps' collectives for the other ranks (Simulation::collective_wait_seconds).
  long local_particles = 0;
  double collective_wait_seconds = 0;
};

// One wall's load (output.wall_loads): the mean force the particles exerted on it by contact
// over the interval since the last DemLink::take_wall_loads().
struct WallLoad {
  std::string name;             // the scene's wall name
  std::array<double, 3> force;  // [N]
};

class DemLink {
 public:
  // Reads and checks the scene (errors name the scene file, line and key; thrown as
  // std::runtime_error). The scene must have a `fluid:` block whose density and
  // viscosity agree with the fluid solver's (rho_f [kg/m^3], mu [Pa s]).
  DemLink(const std::string& scene_file, double fluid_density, double fluid_viscosity,
          MPI_Comm world);
  ~DemLink();
  DemLink(const DemLink&) = delete;
  DemLink& operator=(const DemLink&) = delete;

  Box domain() const;
  std::array<bool, 3> periodic() const;
  std::array<double, 3> gravity() const;
  char vans_model() const;  // 'A' or 'B'
  bool needs_vorticity() const;
  std::string drag_law() const;
  // Heat transfer coupled to the fluid: the scene has `heat:` (and then, necessarily, the
  // fluid block's convection keys). The fluid's c_p [J/(kg K)] and k_f [W/(m K)] as the
  // scene gives them, and "file:line" of the fluid block.
  bool heat_on() const;
  double fluid_heat_capacity() const;
  double fluid_conductivity() const;
  std::string fluid_source() const;
  double end_time() const;           // the scene's time.end [s]
  double expected_max_speed() const;    // the scene's time.expected_max_speed [m/s] (default 1)
  std::string end_time_source() const;  // "file:line" of time.end
  // The scene's output block as a coupled run honours it: the folder for particle snapshots
  // and checkpoints (empty: not given) and the simulated time between snapshots (0: not
  // given). Its other keys are refused by the constructor (grainFoam writes its log and
  // checkpoints at the fluid's write times).
  std::string output_directory() const;
  std::string output_directory_source() const;  // "file:line" of output.directory
  double snapshot_interval() const;
  std::string snapshot_interval_source() const;  // "file:line" of output.snapshot_interval

  // From now on the drag sees the undisturbed velocity: the samples carry each particle's
  // disturbance width and screening (FluidAtParticle), and the drag law is evaluated at the
  // slip the particle would see without its own feedback (dem/fluid/self_disturbance.hpp).
  void correct_self_disturbance(bool on);

  // Takes the processor grid of the fluid's decomposition (call before initialise());
  // the DEM then runs on a communicator ordered so that this rank owns exactly the box
  // of its fluid cells. Throws std::runtime_error if the grid does not fit the scene.
  void use_processor_grid(const ProcessorGrid& grid);
  // Continues from a checkpoint instead of inserting the scene's particles (call before
  // initialise()). Throws std::runtime_error naming the file if it cannot be read.
  void restore(const std::string& checkpoint);
  // Inserts particles (or takes the checkpoint's), checks the time step, builds lists
  // (collective). Throws std::runtime_error with the DEM's message.
  void initialise();
  double time_step() const;  // dt_DEM [s]
  double time() const;
  long steps() const;  // DEM steps since the start of the run (the checkpoint's count)

  ParticleSet particles(bool with_ghosts_and_exchange) const;
  // The same, written into `out` in place: a set kept from one fluid step to the next is
  // refilled without allocating (its arrays only grow).
  void particles(bool with_ghosts_and_exchange, ParticleSet& out) const;
  // particles(true) as a view (see ParticleView), refreshed in place. Collective.
  void view(ParticleView& out) const;

  // Adds each ghost's `width` values (after the local ones, as in `values` sized
  // set.size()·width for the set of particles(true)) to its owner's entry; returns the
  // local part (local·width). Collective.
  std::vector<double> sum_onto_owners(const std::vector<double>& values, std::size_t width) const;

  // The fluid at each local particle, in the order of particles(false) taken right before.
  // `late` samples a particle that reaches this rank during the next advance().
  void set_fluid(const std::vector<FluidAtParticle>& samples,
                 std::function<FluidAtParticle(const std::array<double, 3>&)> late);
  // The same without a vector of samples in between (it would be written and read again
  // every fluid step): begin_fluid(), then add_fluid() once per local particle in that
  // order, then end_fluid(late).
  void begin_fluid();
  void add_fluid(const FluidAtParticle& f);
  void end_fluid(std::function<FluidAtParticle(const std::array<double, 3>&)> late);
  // The same, keeping the `late` of the previous end_fluid(late) (none before it: an error).
  void end_fluid();
  // Instead of begin_fluid() and add_fluid() per particle: the DEM's own sample storage,
  // one record of `stride` doubles per local particle in the order of particles(false), for
  // the caller to write every field into (and, when needs_vorticity(), 3 doubles per
  // particle at `vorticity`). Then end_fluid(late). No copy and no call per particle; the
  // storage is reused from step to step, so every value must be written each time.
  struct SampleRecords {
    double* records;
    std::size_t stride;  // doubles per particle
    std::size_t velocity, void_fraction, pressure_gradient, viscous_stress_divergence;
    double* vorticity;  // 3 per particle, or null: no force reads it
  };
  SampleRecords fluid_samples();
  // With fluid_samples() and the self-disturbance correction on: local particle i's
  // disturbance (the disturbance_* members of f), which the records do not carry.
  void set_fluid_disturbance(std::size_t i, const FluidAtParticle& f);
  // Heat on: the fluid temperature at each local particle, in the order of the samples;
  // given before each end_fluid().
  void set_fluid_temperatures(std::vector<double> temperatures);
  // sampling cellPoint: the footprint-weighted cell velocity [m/s] at each local particle,
  // in the order of the samples, given before each end_fluid(). The fluid's implicit
  // exchange takes K (v - U_fp) from the footprint's cells; the DEM returns the rest of the
  // drag, K (u_f - U_fp), through the explicit exchange force, so that the fluid gets
  // exactly the drag the particles feel (docs/coupling.md, "Sampling"). Empty: no such term.
  void set_fluid_cell_velocities(std::vector<std::array<double, 3>> velocities);
  // Heat on, after advance(steps): each particle's convective heat of the advance and its
  // response to the fluid temperature (HeatExchange). Collective.
  void heat_exchange(int steps, HeatExchange& out) const;
  // Heat on: adds joules[i] [J] to local particle i (the order of view()); the total is
  // added to the particle side of the heat balance by the caller.
  void add_heat(const std::vector<double>& joules);
  // Heat on: sums over every rank's particles (collective) of m c T [J] and m c [J/K].
  std::array<double, 2> thermal_energy() const;
  // `steps` DEM steps (collective). After each, the NaN / Inf guard: the first non-finite
  // particle state stops the run with the particle, its forces and a diagnostic snapshot
  // of every particle in `diagnostic_directory`. Throws std::runtime_error with the DEM's
  // message.
  void advance(int steps, const std::string& diagnostic_directory);

  DemSummary summary() const;  // collective
  // Sums over every rank's particles (collective): the buoyant weight sum (m - rho_f V) g [N]
  // (the weight a mean pressure gradient must carry in a box periodic along g), and the
  // momentum sum m v [kg m/s].
  std::array<double, 3> buoyant_weight() const;
  std::array<double, 3> momentum() const;
  // Writes a particle snapshot (HDF5 + XDMF index) into `directory` (created if missing).
  // After restore(), the first call continues the series there: snapshots with step <=
  // `continue_after` are kept, later ones (of the stopped run) are overwritten. The files hold
  // the scene's output.fields (fluid_force: the coupling's force on each particle at the end
  // of the last advance) and, with output.contacts, the contact network of the last
  // advance's last sub-step; outside the scene's output.start / output.stop nothing is
  // written. Returns notes for the log (empty but for the first call after restore(): each
  // snapshot lost since it was written, which the series keeps as a gap, and each lost file
  // whose number the series writes again).
  std::vector<std::string> write_snapshot(const std::string& directory, long step,
                                          long continue_after = -1);
  // Writes the complete DEM state to <directory>/checkpoint_<DEM step>.h5 and deletes the
  // oldest beyond `keep` (after restore(), the directory's checkpoints up to the restored
  // step count as the oldest). Rebuilds the neighbour lists as a restart will, so that a
  // restarted run continues bit-identically. Returns the file name (without directory).
  // Collective; throws std::runtime_error if the write fails.
  std::string write_checkpoint(const std::string& directory, int keep);
  std::vector<std::string> reports() const;  // the force terms' closing remarks
  // With output.wall_loads in the scene: each wall's load since the last call (or the start,
  // or the checkpoint restored), in the scene's wall order, and in `interval` that time span
  // [s]; the sums restart. Empty when the scene does not ask for them. Collective.
  std::vector<WallLoad> take_wall_loads(double& interval);
  // Each fluid force's stability time scale and limit at initialise() (before the first
  // fluid sample: fluid at rest), one line each, and an "error: ..." line for a step beyond
  // an explicit force's limit (docs/models/fluid-forces.md).
  std::vector<std::string> force_limit_notes() const;
  // The DEM's start-up findings that `grain check` prints, besides the fluid forces' lines
  // (force_limit_notes) and the step count to the scene's time.end: the time-step check's
  // lines (Rayleigh and contact times, steps per impact and their errors, the guards, an
  // "error: ..." line for a step it refuses), the meshes read (with their warnings), the
  // insertions' notes and the scene's settings without effect (Scene::notes). After
  // initialise(); the same on every rank.
  std::vector<std::string> startup_notes() const;
  // When the time-step check refuses the DEM step, as `grain run` would: what to do, with a
  // step that also divides the fluid step `fluid_dt` [s]; empty when the step is accepted.
  std::string time_step_refusal(double fluid_dt) const;
  // Coarse-grained parcels against the fluid cells, the rule `grain check` applies to its
  // void-fraction cells (dem/engine/parcel_limits.hpp; Radl et al. 2011): one "warning: ..."
  // line per parcel class whose largest parcel is wider than a third of the smallest cell
  // [m], and one more when it is wider than that cell; each names the class (glass[k=3]),
  // its parcel diameter and the smallest and typical cell sizes. Empty without parcels or
  // when they are small enough. Collective (after initialise()).
  std::vector<std::string> parcel_cell_warnings(double smallest_cell, double typical_cell) const;

  // The rule `grain check` and `grain run` apply to the domain (dem/engine/parcel_limits.hpp):
  // one "warning: ..." line when the domain's narrowest side is less than 10 diameters of the
  // widest parcels (in the fluidisedBed column, 9 mm deep, the k = 2 parcels layer against the
  // front and back walls and the gas runs along them; docs/models/coarse-graining.md); and one
  // per mesh wall whose narrowest opening (a hopper's orifice) is under 10 of their diameters.
  // Empty without parcels or when the domain is wide enough. Collective (after initialise()).
  std::vector<std::string> parcel_domain_warnings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace grainflow::coupling
