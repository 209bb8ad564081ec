#include "coupling/dem_link.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "coupling/floating_point_traps.hpp"
#include "dem/engine/checkpoint_series.hpp"
#include "dem/engine/finite_guard.hpp"
#include "dem/engine/parcel_limits.hpp"
#include "dem/engine/restored_state.hpp"
#include "dem/engine/run.hpp"
#include "dem/engine/simulation.hpp"
#include "dem/fluid/coupled_fluid.hpp"
#include "dem/fluid/fluid_forces.hpp"
#include "dem/fluid/self_disturbance.hpp"
#include "dem/io/output_directory.hpp"
#include "dem/io/snapshot_writer.hpp"
#include "dem/scene/scene_parser.hpp"

namespace grainflow::coupling {
namespace {

Vec3 vec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }
std::array<double, 3> arr(const Vec3& v) { return {v[0], v[1], v[2]}; }

bool close(double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b)); }

}  // namespace

struct DemLink::Impl {
  Scene scene;
  double fluid_density = 0, fluid_viscosity = 0;
  MPI_Comm world = MPI_COMM_NULL;
  MPI_Comm dem_comm = MPI_COMM_NULL;  // ordered to match the fluid's processor boxes
  std::optional<ProcessorGrid> grid;
  std::unique_ptr<Simulation> sim;
  std::shared_ptr<CoupledFluid> fluid = std::make_shared<CoupledFluid>();
  std::unique_ptr<SnapshotWriter> snapshots;
  std::string snapshot_directory;
  std::optional<CheckpointData> restart;  // until initialise()
  long restored_step = -1;                // the checkpoint's DEM step, after a restart
  double restored_time = 0;               // the checkpoint's time, after a restart
  std::unique_ptr<CheckpointSeries> checkpoints;
  std::vector<double> forwarded;     // particles(): the values forwarded to ghosts, reused
  std::vector<CoupledSample> pending;  // begin_fluid() .. end_fluid()
  std::vector<Vec3> pending_vorticity;  // the same, when a force reads the vorticity
  bool curl = false;                    // needs_vorticity()
  std::vector<SelfDisturbance> pending_disturbance;  // when `self`
  bool self = false;                                  // correct_self_disturbance()
  bool heat = false;                     // heat_on()
  std::vector<double> pending_temperature;  // set_fluid_temperatures()
  std::vector<Vec3> pending_cell_velocity;  // set_fluid_cell_velocities()
  // The coupling's sampler of late arrivals (end_fluid), and whether the CoupledFluid's
  // sampler calls it already.
  std::function<FluidAtParticle(const std::array<double, 3>&)> late;
  bool sampler_set = false;

  ~Impl() {
    sim.reset();
    if (dem_comm != MPI_COMM_NULL) MPI_Comm_free(&dem_comm);
  }

  Simulation& simulation() const {
    if (!sim) throw std::logic_error("DemLink: initialise() has not been called");
    return *sim;
  }

  FluidSample to_sample(const FluidAtParticle& f) const {
    FluidSample s;
    s.velocity = vec(f.velocity);
    s.void_fraction = f.void_fraction;
    s.pressure_gradient = vec(f.pressure_gradient);
    s.viscous_stress_divergence = vec(f.viscous_stress_divergence);
    s.vorticity = vec(f.vorticity);
    s.density = fluid_density;
    s.viscosity = fluid_viscosity;
    s.temperature = f.temperature;
    return s;
  }
};

DemLink::DemLink(const std::string& scene_file, double fluid_density, double fluid_viscosity,
                 MPI_Comm world)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.world = world;
  m.fluid_density = fluid_density;
  m.fluid_viscosity = fluid_viscosity;
  try {
    m.scene = load_scene(scene_file);
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
  if (!m.scene.fluid)
    throw std::runtime_error(scene_file +
                             ": error: a coupled run needs a `fluid:` block (drag law, VANS "
                             "model, force list); see docs/scene-reference.md");
  m.fluid->set_constants(fluid_density, fluid_viscosity);
  m.curl = needs_vorticity();
  const FluidSettings& f = *m.scene.fluid;
  std::ostringstream why;
  // 12 digits: the values agree to 1e-9 relative, so the printed one typed back passes.
  why.precision(12);
  if (!close(f.field.density, fluid_density))
    why << f.source << ": error: fluid.density is " << f.field.density
        << " kg/m^3 but the fluid solver's rho is " << fluid_density
        << " kg/m^3 (constant/transportProperties); make them equal (to 1e-9 relative), e.g. "
           "fluid.density: "
        << fluid_density << "\n";
  if (!close(f.field.viscosity, fluid_viscosity))
    why << f.source << ": error: fluid.viscosity is " << f.field.viscosity
        << " Pa s but the fluid solver's rho*nu is " << fluid_viscosity
        << " Pa s (constant/transportProperties); make them equal (to 1e-9 relative), e.g. "
           "fluid.viscosity: "
        << fluid_viscosity << "\n";
  if (f.field.hydrostatic_pressure)
    why << f.source
        << ": error: grainFoam's pressure excludes the hydrostatic part (rho_f g.x); add "
           "`pressure: {hydrostatic: false}` to the fluid block and list buoyancy in "
           "fluid.forces\n";
  // Heat in a coupled run: grainFoam's energy equation exchanges heat with the particles by
  // convection, which needs the fluid's c_p, k_f and Nusselt law from the fluid block.
  if (m.scene.heat && !f.thermal)
    why << f.source
        << ": error: heat is on (" << m.scene.heat->source
        << "), but the fluid block has no convection settings; a coupled run with heat needs "
           "`temperature: <K>`, `heat_capacity: <J/(kg K)>` and `conductivity: <W/(m K)>` in "
           "the fluid block (the fluid temperature itself comes from grainFoam's 0/T; "
           "docs/models/heat-transfer.md, \"Coupled to grainFoam\")\n";
  m.heat = m.scene.heat && f.thermal;
  // The keys that prescribe the fluid for grain's one-way runs: grainFoam solves the fluid.
  for (const auto& [key, where] : f.prescribed_keys) {
    const char* instead =
        key == "void_fraction"
            ? "grainFoam computes the void fraction from the particles on its mesh "
              "(constant/couplingProperties: voidFraction, minVoidFraction)"
        : key == "pressure.gradient"
            ? "the pressure gradient is grainFoam's solved p (drive the flow through the "
              "boundary conditions of 0/U and 0/p, or meanPressureGradient in "
              "constant/couplingProperties for a box periodic along gravity)"
            : "the fluid velocity is grainFoam's solved U (set the flow through 0/U)";
    why << where << ": error: fluid." << key
        << " prescribes the fluid for a one-way `grain run`; a coupled run does not use it: "
        << instead << "; remove it\n";
  }
  // The output keys that belong to grain's own run loop: grainFoam's write times replace them.
  for (const auto& [key, where] : m.scene.output.given) {
    const char* instead = nullptr;
    if (key == "log_interval")
      instead = "grainFoam logs the particles (count, contacts, overlap, time split) at every "
                "write time of system/controlDict (writeControl, writeInterval)";
    else if (key == "progress")
      instead = "grainFoam's progress is OpenFOAM's `Time = ...` line at every fluid step";
    else if (key == "checkpoint_interval")
      instead = "grainFoam writes a DEM checkpoint at every write time of system/controlDict "
                "(writeInterval), next to the fluid fields a restart needs";
    else if (key == "checkpoint_keep")
      instead = "grainFoam keeps the checkpoints of the last purgeWrite write times "
                "(system/controlDict purgeWrite; 0 keeps all)";
    if (instead)
      why << where << ": error: output." << key << " is not used by a coupled run: " << instead
          << "; remove it (grainFoam honours output.directory and output.snapshot_interval)\n";
  }
  // The DEM's processor grid and cut planes are the fluid mesh's (DESIGN.md §2): a grid or
  // a load balancing of the scene's own cannot apply (balancing moved the DEM's planes off
  // the fluid's, and the particles beyond them deposited nothing).
  for (const auto& [key, where] : m.scene.parallel.given) {
    if (key == "grid")
      why << where
          << ": error: parallel.grid is not used by a coupled run: the DEM's processor grid "
             "is the fluid's decomposition (system/decomposeParDict: numberOfSubdomains and "
             "the method's n), read off the processor meshes at start-up; remove it and set "
             "the grid in system/decomposeParDict\n";
    else if (key == "balance" && m.scene.parallel.balance)
      why << where
          << ": error: parallel.balance: true cannot apply to a coupled run: the DEM follows "
             "the fluid's decomposition (system/decomposeParDict), so its cut planes stay the "
             "mesh's; remove it (to share a bed's particles evenly, place the mesh's cut "
             "planes with scripts/balanced_decomposition.py, docs/parallel.md)\n";
  }
  if (!why.str().empty()) throw std::runtime_error(why.str());
  // Checks the force list against the coupled solver (pressure without hydrostatics).
  try {
    (void)make_coupled_fluid_forces(f, m.scene.gravity, m.fluid);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(f.source + ": error: fluid.forces: " + e.what() +
                             " (the coupled solver's pressure excludes the hydrostatic part)");
  }
}

DemLink::~DemLink() = default;

Box DemLink::domain() const {
  return {arr(impl_->scene.domain.lo), arr(impl_->scene.domain.hi)};
}
std::array<bool, 3> DemLink::periodic() const { return impl_->scene.domain.periodic; }
std::array<double, 3> DemLink::gravity() const { return arr(impl_->scene.gravity); }
char DemLink::vans_model() const { return impl_->scene.fluid->model == VansModel::A ? 'A' : 'B'; }
bool DemLink::needs_vorticity() const {
  for (FluidForce f : impl_->scene.fluid->forces)
    if (f == FluidForce::saffman_mei || f == FluidForce::magnus ||
        f == FluidForce::rotational_drag)
      return true;
  return false;
}
std::string DemLink::drag_law() const { return impl_->scene.fluid->drag_law; }
bool DemLink::heat_on() const { return impl_->heat; }
double DemLink::fluid_heat_capacity() const {
  return impl_->heat ? impl_->scene.fluid->thermal->heat_capacity : 0.0;
}
double DemLink::fluid_conductivity() const {
  return impl_->heat ? impl_->scene.fluid->thermal->conductivity : 0.0;
}
std::string DemLink::fluid_source() const { return impl_->scene.fluid->source; }
double DemLink::end_time() const { return impl_->scene.time.end; }
double DemLink::expected_max_speed() const { return impl_->scene.time.expected_max_speed; }
std::string DemLink::end_time_source() const { return impl_->scene.time.end_source; }

namespace {
std::string given_at(const OutputSettings& o, const std::string& key) {
  for (const auto& [k, where] : o.given)
    if (k == key) return where;
  return {};
}
}  // namespace

std::string DemLink::output_directory() const {
  const OutputSettings& o = impl_->scene.output;
  return given_at(o, "directory").empty() ? std::string() : o.directory;
}
std::string DemLink::output_directory_source() const {
  return given_at(impl_->scene.output, "directory");
}
double DemLink::snapshot_interval() const {
  return impl_->scene.output.snapshot_interval.value_or(0);
}
std::string DemLink::snapshot_interval_source() const {
  return given_at(impl_->scene.output, "snapshot_interval");
}

void DemLink::use_processor_grid(const ProcessorGrid& grid) { impl_->grid = grid; }

// The DEM runs with OpenFOAM's floating-point traps off (FloatingPointTrapsOff): a NaN born
// in the DEM would otherwise kill the run with a stack trace before the DEM's own guard could
// name the particle. Everything that runs DEM code (initialise: the first forces; restore;
// advance; write_checkpoint: a list rebuild) does so, and the guard checks every step instead.
// The DEM's pair kernel also relies on it: it evaluates four contacts at a time and computes
// both sides of a branch in every lane (e.g. 0/0 for a fresh spring's rotation), keeping the
// side that applies.
void DemLink::initialise() {
  Impl& m = *impl_;
  const FloatingPointTrapsOff traps_off;
  std::array<int, 3> dims{0, 0, 0};
  if (m.grid) {
    dims = m.grid->dims;
    // Rank order of MPI_Cart_create without reordering: z fastest.
    const auto& c = m.grid->coords;
    const int key = (c[0] * dims[1] + c[1]) * dims[2] + c[2];
    MPI_Comm_split(m.world, 0, key, &m.dem_comm);
  } else {
    MPI_Comm_dup(m.world, &m.dem_comm);
  }
  try {
    m.sim = std::make_unique<Simulation>(m.scene, !m.restart, m.dem_comm, dims);
    if (m.restart) {
      check_restart_step(m.scene, *m.restart);
      m.sim->restore(*m.restart);
      m.restored_step = m.restart->step;
      m.restored_time = m.sim->time();
      m.restart.reset();
    }
    if (m.grid)
      for (int a = 0; a < 3; ++a)
        if (dims[a] > 1) m.sim->set_cut_planes(a, m.grid->cuts[a]);
    m.sim->add_force_term(
        make_coupled_fluid_forces(*m.scene.fluid, m.scene.gravity, m.fluid, m.dem_comm));
    // The first force evaluation, before the fluid is sampled, sees fluid at rest, eps = 1.
    Impl* self = &m;
    m.fluid->set_sampler([self](const Vec3&) { return self->to_sample(FluidAtParticle{}); });
    if (m.heat) m.sim->heat()->couple(m.fluid.get());
    m.sim->record_fluid_force((m.scene.output.fields & snapshot_field_bit("fluid_force")) != 0);
    m.sim->record_contacts(m.scene.output.contacts);
    m.sim->initialise();
    m.fluid->reset_late_samples();
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
  if (m.grid) {
    const Decomposition& d = m.sim->decomposition();
    if (d.coords() != m.grid->coords)
      throw std::logic_error("DemLink: the DEM box of this rank is not the fluid's");
  }
}

void DemLink::restore(const std::string& checkpoint) {
  const FloatingPointTrapsOff traps_off;
  if (!std::filesystem::exists(checkpoint))
    throw std::runtime_error("the DEM checkpoint '" + checkpoint +
                             "' does not exist (a coupled run writes one at every write time; "
                             "was it deleted or moved?)");
  try {
    impl_->restart = read_checkpoint(checkpoint);
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
}

double DemLink::time_step() const { return impl_->simulation().dt(); }
double DemLink::time() const { return impl_->simulation().time(); }
long DemLink::steps() const { return impl_->simulation().counters().steps; }

ParticleSet DemLink::particles(bool with_ghosts_and_exchange) const {
  ParticleSet out;
  particles(with_ghosts_and_exchange, out);
  return out;
}

void DemLink::particles(bool with_ghosts_and_exchange, ParticleSet& out) const {
  const Simulation& sim = impl_->simulation();
  const Particles& p = sim.particles();
  const std::size_t local = p.size();
  const std::size_t n = local + (with_ghosts_and_exchange ? sim.ghosts().size() : 0);
  out.local = local;
  out.id.resize(n);
  out.x.resize(n);
  out.v.resize(n);
  out.radius.resize(n);
  if (!with_ghosts_and_exchange) {
    for (std::size_t i = 0; i < local; ++i) {
      out.id[i] = static_cast<long long>(p.id[i]);
      out.x[i] = arr(p.x[i]);
      out.v[i] = arr(p.v[i]);
      out.radius[i] = p.radius[i];
    }
    out.drag_coefficient.clear();
    out.exchange_force.clear();
    return;
  }
  // K, the exchange force and the velocity at the end of the last step, local first, then
  // forwarded to ghosts (the ghosts' own velocities were forwarded mid-step, before the
  // second half kick). One pass over the local particles.
  const ImplicitDrag& drag = sim.implicit_drag();
  const std::vector<Vec3>& carried = impl_->fluid->exchange_force;
  out.drag_coefficient.resize(n);
  out.exchange_force.resize(n);
  const std::size_t withDrag = std::min(local, drag.coefficient.size());
  const std::size_t withForce = std::min(local, carried.size());
  for (std::size_t i = 0; i < local; ++i) {
    out.id[i] = static_cast<long long>(p.id[i]);
    out.x[i] = arr(p.x[i]);
    out.v[i] = arr(p.v[i]);
    out.radius[i] = p.radius[i];
    out.drag_coefficient[i] = i < withDrag ? drag.coefficient[i] : 0.0;
    out.exchange_force[i] = i < withForce ? arr(carried[i]) : std::array<double, 3>{};
  }
  // One rank without ghosts of its own (no periodic images): nothing to forward, and no
  // other rank waits for this one's values.
  if (n == local && sim.decomposition().dims() == std::array<int, 3>{1, 1, 1}) return;
  constexpr std::size_t W = 7;
  std::vector<double>& values = impl_->forwarded;  // kept: no allocation per fluid step
  values.resize(W * local);
  for (std::size_t i = 0; i < local; ++i) {
    double* v = &values[W * i];
    v[0] = out.drag_coefficient[i];
    for (int c = 0; c < 3; ++c) {
      v[1 + c] = out.exchange_force[i][c];
      v[4 + c] = out.v[i][c];
    }
  }
  const std::vector<double> ghost_values = sim.ghost_values(values, W);
  const Ghosts& g = sim.ghosts();
  for (std::size_t k = 0; k < g.size(); ++k) {
    const double* v = &ghost_values[W * k];
    out.id[local + k] = static_cast<long long>(g.id[k]);
    out.x[local + k] = arr(g.position(k));
    out.radius[local + k] = g.radius[k];
    out.drag_coefficient[local + k] = v[0];
    out.exchange_force[local + k] = {v[1], v[2], v[3]};
    out.v[local + k] = {v[4], v[5], v[6]};
  }
}

void DemLink::view(ParticleView& out) const {
  const Simulation& sim = impl_->simulation();
  const Particles& p = sim.particles();
  // Vec3 (Eigen, fixed size 3, not vectorised) is three packed doubles, so an array of them
  // reads as 3 n doubles (the Eigen::Map view DESIGN.md allows for the SoA arrays).
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 is not three packed doubles");
  const ImplicitDrag& drag = sim.implicit_drag();
  const std::vector<Vec3>& carried = impl_->fluid->exchange_force;
  const std::size_t local = p.size();
  out.local_ = local;
  out.x_ = local ? p.x.data()->data() : nullptr;
  out.v_ = local ? p.v.data()->data() : nullptr;
  out.radius_ = p.radius.data();
  out.drag_ = drag.coefficient.data();
  out.drag_count_ = std::min(local, drag.coefficient.size());
  out.force_ = carried.empty() ? nullptr : carried.data()->data();
  out.force_count_ = std::min(local, carried.size());
  const Ghosts& g = sim.ghosts();
  out.ghost_x_.resize(g.size());
  out.ghost_v_.resize(g.size());
  out.ghost_force_.resize(g.size());
  out.ghost_radius_.resize(g.size());
  out.ghost_drag_.resize(g.size());
  // One rank without ghosts of its own (no periodic images): nothing to forward, and no
  // other rank waits for this one's values.
  if (g.size() == 0 && sim.decomposition().dims() == std::array<int, 3>{1, 1, 1}) return;
  // K, the exchange force and the velocity of the last step, forwarded to the ghosts (as
  // particles(true) does).
  constexpr std::size_t W = 7;
  std::vector<double>& values = impl_->forwarded;
  values.resize(W * local);
  for (std::size_t i = 0; i < local; ++i) {
    double* v = &values[W * i];
    v[0] = out.drag_coefficient(i);
    const std::array<double, 3> f = out.exchange_force(i);
    for (int c = 0; c < 3; ++c) {
      v[1 + c] = f[c];
      v[4 + c] = p.v[i][c];
    }
  }
  const std::vector<double> ghost_values = sim.ghost_values(values, W);
  for (std::size_t k = 0; k < g.size(); ++k) {
    const double* v = &ghost_values[W * k];
    out.ghost_x_[k] = arr(g.position(k));
    out.ghost_radius_[k] = g.radius[k];
    out.ghost_drag_[k] = v[0];
    out.ghost_force_[k] = {v[1], v[2], v[3]};
    out.ghost_v_[k] = {v[4], v[5], v[6]};
  }
}

std::vector<double> DemLink::sum_onto_owners(const std::vector<double>& values,
                                             std::size_t width) const {
  const Simulation& sim = impl_->simulation();
  const std::size_t nlocal = sim.particles().size();
  std::vector<double> local(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(nlocal * width));
  std::vector<double> ghost(values.begin() + static_cast<std::ptrdiff_t>(nlocal * width), values.end());
  sim.add_ghost_values(local, width, std::move(ghost));
  return local;
}

void DemLink::set_fluid(const std::vector<FluidAtParticle>& samples,
                        std::function<FluidAtParticle(const std::array<double, 3>&)> late) {
  begin_fluid();
  for (const FluidAtParticle& f : samples) add_fluid(f);
  end_fluid(std::move(late));
}

void DemLink::correct_self_disturbance(bool on) {
  // The disturbance model (dem/fluid/self_disturbance.hpp) is that of one sphere in its cells;
  // a parcel's k^3 real particles disturb their cells together, which it does not describe.
  if (on)
    for (const grainflow::Insertion& ins : impl_->scene.insertions)
      if (ins.coarse_grain != 1) {
        std::ostringstream why;
        why << ins.source << ": error: insert.coarse_grain " << ins.coarse_grain
            << ": the undisturbed-velocity correction (constant/couplingProperties "
               "undisturbedVelocity oseenBrinkman) models one particle's own disturbance, not "
               "that of a parcel's real particles together; set undisturbedVelocity off, or "
               "use coarse_grain: 1 (docs/models/coarse-graining.md)";
        throw std::runtime_error(why.str());
      }
  impl_->self = on;
}

void DemLink::begin_fluid() {
  Impl& m = *impl_;
  const std::size_t n = m.simulation().particles().size();
  m.pending = m.fluid->take_spare();  // the storage of the set before last, if any
  m.pending.clear();
  m.pending.reserve(n);
  if (m.curl) {
    m.pending_vorticity = m.fluid->take_spare_vorticity();
    m.pending_vorticity.clear();
    m.pending_vorticity.reserve(n);
  }
  if (m.self) {
    m.pending_disturbance = m.fluid->take_spare_disturbance();
    m.pending_disturbance.clear();
    m.pending_disturbance.reserve(n);
  }
}

DemLink::SampleRecords DemLink::fluid_samples() {
  Impl& m = *impl_;
  // A CoupledSample is doubles only (Vec3 = 3 doubles, no padding): a record of doubles.
  static_assert(sizeof(CoupledSample) == 10 * sizeof(double));
  static_assert(sizeof(Vec3) == 3 * sizeof(double));
  const std::size_t n = m.simulation().particles().size();
  // The storage of the set before last (empty at first): every value is written again.
  m.pending = m.fluid->take_spare();
  m.pending.resize(n);
  if (m.curl) {
    m.pending_vorticity = m.fluid->take_spare_vorticity();
    m.pending_vorticity.resize(n);
  }
  if (m.self) {  // the records carry no disturbance: set_fluid_disturbance, or no correction
    m.pending_disturbance = m.fluid->take_spare_disturbance();
    m.pending_disturbance.assign(n, SelfDisturbance{});
  }
  const CoupledSample probe;
  const auto at = [&probe](const auto& member) {
    return static_cast<std::size_t>(reinterpret_cast<const char*>(&member) -
                                    reinterpret_cast<const char*>(&probe)) /
           sizeof(double);
  };
  return SampleRecords{reinterpret_cast<double*>(m.pending.data()),
                       sizeof(CoupledSample) / sizeof(double),
                       at(probe.velocity),
                       at(probe.void_fraction),
                       at(probe.pressure_gradient),
                       at(probe.viscous_stress_divergence),
                       m.curl ? m.pending_vorticity.data()->data() : nullptr};
}

void DemLink::set_fluid_temperatures(std::vector<double> temperatures) {
  impl_->pending_temperature = std::move(temperatures);
}

void DemLink::set_fluid_cell_velocities(std::vector<std::array<double, 3>> velocities) {
  Impl& m = *impl_;
  m.pending_cell_velocity = m.fluid->take_spare_cell_velocity();
  m.pending_cell_velocity.resize(velocities.size());
  for (std::size_t i = 0; i < velocities.size(); ++i) m.pending_cell_velocity[i] = vec(velocities[i]);
}

void DemLink::heat_exchange(int steps, HeatExchange& out) const {
  const Impl& m = *impl_;
  const Simulation& sim = m.simulation();
  const Particles& p = sim.particles();
  const HeatTransfer& heat = *sim.heat();
  const CoupledFluid& fluid = *m.fluid;
  const std::vector<GlobalId>& ids = fluid.entry_ids();
  const std::vector<double>& taken = fluid.entry_heat();
  const std::vector<double>& conductance = fluid.entry_conductance();
  const std::vector<Vec3>& where = fluid.entry_heat_position();
  std::unordered_map<GlobalId, std::size_t> entry;
  entry.reserve(ids.size());
  for (std::size_t k = 0; k < ids.size() && k < taken.size(); ++k) entry.emplace(ids[k], k);
  std::vector<char> used(taken.size(), 0);
  const std::size_t local = p.size();
  const Ghosts& g = sim.ghosts();
  out.heat.assign(local + g.size(), 0.0);
  out.response.assign(local + g.size(), 0.0);
  const double dt = sim.dt();
  for (std::size_t i = 0; i < local; ++i) {
    const auto it = entry.find(p.id[i]);
    if (it == entry.end()) continue;  // came after the last heat pass: nothing taken
    const std::size_t k = it->second;
    used[k] = 1;
    const double c = p.mass[i] * heat.heat_capacity(p.material[i]);
    out.heat[i] = taken[k];
    // N implicit steps at fixed T_f: a change dT_f of the fluid temperature changes T_i
    // by (1 - (1 + dt H / C)^-N) dT_f.
    out.response[i] = -c * std::expm1(-steps * std::log1p(dt * conductance[k] / c));
  }
  out.orphan_position.clear();
  out.orphan_heat.clear();
  for (std::size_t k = 0; k < taken.size(); ++k)
    if (!used[k] && taken[k] != 0) {
      out.orphan_position.push_back(arr(where[k]));
      out.orphan_heat.push_back(taken[k]);
    }
  if (g.size() == 0 && sim.decomposition().dims() == std::array<int, 3>{1, 1, 1}) return;
  std::vector<double> values(2 * local);
  for (std::size_t i = 0; i < local; ++i) {
    values[2 * i] = out.heat[i];
    values[2 * i + 1] = out.response[i];
  }
  const std::vector<double> ghost_values = sim.ghost_values(values, 2);
  for (std::size_t k = 0; k < g.size(); ++k) {
    out.heat[local + k] = ghost_values[2 * k];
    out.response[local + k] = ghost_values[2 * k + 1];
  }
}

void DemLink::add_heat(const std::vector<double>& joules) {
  Simulation& sim = impl_->simulation();
  Particles& p = sim.particles();
  const HeatTransfer& heat = *sim.heat();
  if (joules.size() != p.size())
    throw std::logic_error("DemLink::add_heat: " + std::to_string(joules.size()) +
                           " values for " + std::to_string(p.size()) + " particles");
  for (std::size_t i = 0; i < p.size(); ++i)
    p.temperature[i] += joules[i] / (p.mass[i] * heat.heat_capacity(p.material[i]));
}

std::array<double, 2> DemLink::thermal_energy() const {
  const Simulation& sim = impl_->simulation();
  const Particles& p = sim.particles();
  double sums[2] = {0, 0};
  if (const HeatTransfer* heat = sim.heat()) {
    sums[0] = heat->thermal_energy(p);
    for (std::size_t i = 0; i < p.size(); ++i) sums[1] += p.mass[i] * heat->heat_capacity(p.material[i]);
  }
  MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE, MPI_SUM, impl_->dem_comm);
  return {sums[0], sums[1]};
}

namespace {

SelfDisturbance disturbance_of(const FluidAtParticle& f) {
  SelfDisturbance sd{f.disturbance_cell, f.disturbance_spread, f.disturbance_screening,
                     f.disturbance_smoothing};
  if (f.disturbance_placed) {
    sd.placed = true;
    for (int a = 0; a < 3; ++a) {
      const std::array<double, 3>& w = f.disturbance_weights[a];
      sd.transverse[a] = transverse_coefficients(w[0], w[1], w[2]);
    }
  }
  if (f.disturbance_cell_point) {
    sd.cell_point = true;
    sd.place = f.disturbance_place;
    sd.marginals = f.disturbance_weights;
    if (sd.smoothing > 0 && sd.cell > 0) {
      for (int along = 0; along < 3; ++along) {
        const int ta = (along + 1) % 3, tb = (along + 2) % 3;
        sd.cell_point_reads[along] = cell_point_read(sd.place[ta], sd.place[tb], sd.marginals[ta],
                                                     sd.marginals[tb], sd.spread / sd.cell);
      }
      sd.cell_point_reads_set = true;
    }
  }
  return sd;
}

}  // namespace

void DemLink::add_fluid(const FluidAtParticle& f) {
  Impl& m = *impl_;
  m.pending.push_back(CoupledSample{vec(f.velocity), f.void_fraction, vec(f.pressure_gradient),
                                    vec(f.viscous_stress_divergence)});
  if (m.curl) m.pending_vorticity.push_back(vec(f.vorticity));
  if (m.self) m.pending_disturbance.push_back(disturbance_of(f));
}

void DemLink::set_fluid_disturbance(std::size_t i, const FluidAtParticle& f) {
  Impl& m = *impl_;
  if (!m.self || i >= m.pending_disturbance.size())
    throw std::logic_error("DemLink::set_fluid_disturbance: no correction, or no record " +
                           std::to_string(i));
  m.pending_disturbance[i] = disturbance_of(f);
}

void DemLink::end_fluid(std::function<FluidAtParticle(const std::array<double, 3>&)> late) {
  Impl& m = *impl_;
  m.late = std::move(late);
  end_fluid();
}

void DemLink::end_fluid() {
  Impl& m = *impl_;
  if (!m.late) throw std::logic_error("DemLink::end_fluid(): no sampler for late arrivals yet");
  const Particles& p = m.simulation().particles();
  if (m.pending.size() != p.size())
    throw std::logic_error("DemLink: " + std::to_string(m.pending.size()) + " fluid samples for " +
                           std::to_string(p.size()) + " particles");
  if (m.curl && m.pending_vorticity.size() != p.size())
    throw std::logic_error("DemLink: " + std::to_string(m.pending_vorticity.size()) +
                           " vorticity samples for " + std::to_string(p.size()) + " particles");
  if (m.self && m.pending_disturbance.size() != p.size())
    throw std::logic_error("DemLink: " + std::to_string(m.pending_disturbance.size()) +
                           " self-disturbance samples for " + std::to_string(p.size()) +
                           " particles");
  if (m.heat && m.pending_temperature.size() != p.size())
    throw std::logic_error("DemLink: " + std::to_string(m.pending_temperature.size()) +
                           " fluid temperatures for " + std::to_string(p.size()) + " particles");
  if (!m.pending_cell_velocity.empty() && m.pending_cell_velocity.size() != p.size())
    throw std::logic_error("DemLink: " + std::to_string(m.pending_cell_velocity.size()) +
                           " cell velocities for " + std::to_string(p.size()) + " particles");
  m.fluid->set(p.id, std::move(m.pending),
               m.curl ? std::move(m.pending_vorticity) : std::vector<Vec3>{},
               m.self ? std::move(m.pending_disturbance) : std::vector<SelfDisturbance>{},
               m.heat ? std::move(m.pending_temperature) : std::vector<double>{},
               std::move(m.pending_cell_velocity));
  m.pending_temperature = {};
  m.pending_cell_velocity = {};
  m.pending = {};  // moved from: empty
  m.pending_vorticity = {};
  m.pending_disturbance = {};
  if (!m.sampler_set) {
    Impl* self = &m;
    m.fluid->set_sampler([self](const Vec3& x) { return self->to_sample(self->late(arr(x))); });
    m.sampler_set = true;
  }
}


void DemLink::advance(int steps, const std::string& diagnostic_directory) {
  Simulation& sim = impl_->simulation();
  const FloatingPointTrapsOff traps_off;
  try {
    // A snapshot may follow this advance: the fluid's share of the last sub-step's forces is
    // kept when the scene's output.fields asks for fluid_force, and that sub-step's contact
    // network when output.contacts asks for it (one report pass per advance).
    const bool fluid_force =
        (impl_->scene.output.fields & snapshot_field_bit("fluid_force")) != 0;
    const bool contacts = impl_->scene.output.contacts;
    for (int k = 0; k < steps; ++k) {
      sim.record_fluid_force(fluid_force && k == steps - 1);
      sim.record_contacts(contacts && k == steps - 1);
      sim.step();
      guard_finite_after_step(sim, diagnostic_directory, impl_->dem_comm);
    }
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
}

DemSummary DemLink::summary() const {
  const Simulation& sim = impl_->simulation();
  const GlobalState g = sim.global_state();
  DemSummary s;
  s.particles = g.particles;
  s.contacts = g.contacts;
  s.removed = g.removed;
  s.max_overlap_ratio = g.max_overlap_ratio;
  s.kinetic_energy = g.kinetic_translational + g.kinetic_rotational;
  s.local_particles = static_cast<long>(sim.particles().size());
  s.collective_wait_seconds = sim.collective_wait_seconds();
  long late = impl_->fluid->late_samples();
  MPI_Allreduce(MPI_IN_PLACE, &late, 1, MPI_LONG, MPI_SUM, impl_->dem_comm);
  s.late_samples = late;
  return s;
}

std::vector<WallLoad> DemLink::take_wall_loads(double& interval) {
  const Simulation::WallLoads w = impl_->simulation().take_wall_loads();
  interval = w.interval;
  std::vector<WallLoad> out;
  const auto& walls = impl_->simulation().walls().walls();
  for (std::size_t k = 0; k < w.force.size(); ++k)
    out.push_back({walls[k].name, {w.force[k][0], w.force[k][1], w.force[k][2]}});
  return out;
}

std::array<double, 3> DemLink::buoyant_weight() const {
  const Particles& p = impl_->simulation().particles();
  double excess = 0;  // sum m - rho_f V
  for (std::size_t i = 0; i < p.size(); ++i)
    excess += p.mass[i] - impl_->fluid_density * sphere_volume(p.radius[i]);
  MPI_Allreduce(MPI_IN_PLACE, &excess, 1, MPI_DOUBLE, MPI_SUM, impl_->dem_comm);
  const Vec3& g = impl_->scene.gravity;
  return {excess * g[0], excess * g[1], excess * g[2]};
}

std::array<double, 3> DemLink::momentum() const {
  const Particles& p = impl_->simulation().particles();
  double sum[3] = {0, 0, 0};
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int d = 0; d < 3; ++d) sum[d] += p.mass[i] * p.v[i][d];
  MPI_Allreduce(MPI_IN_PLACE, sum, 3, MPI_DOUBLE, MPI_SUM, impl_->dem_comm);
  return {sum[0], sum[1], sum[2]};
}

std::vector<std::string> DemLink::write_snapshot(const std::string& directory, long step,
                                                 long continue_after) {
  Impl& m = *impl_;
  std::vector<std::string> notes;
  try {
    // The scene's output window: outside it no snapshot is written (the checkpoints are).
    const Simulation& sim = m.simulation();
    const double half = 0.5 * sim.dt();
    if ((m.scene.output.start && sim.time() < *m.scene.output.start - half) ||
        (m.scene.output.stop && sim.time() > *m.scene.output.stop + half))
      return notes;
    if (!m.snapshots || m.snapshot_directory != directory) {
      prepare_output_directory(directory);
      m.snapshots = std::make_unique<SnapshotWriter>(m.dem_comm, directory, "particles",
                                                     m.scene.output.fields);
      // Each material's k, for the coarse_grain and real_count fields (empty: no parcels).
      m.snapshots->set_coarse_grain(m.scene.coarse_grain_table(), m.scene.real_material_table());
      m.snapshots->set_material_names(m.scene.material_names());
      m.snapshot_directory = directory;
      // A restart: the series goes on after the snapshots written up to the checkpoint;
      // those lost since (listed in particles.xdmf up to the checkpoint's time, the restart
      // does not write them again) stay gaps, so later files keep their numbers.
      if (continue_after >= 0) {
        m.snapshots->continue_series(continue_after, m.restored_time + 0.5 * sim.dt());
        for (const std::string& gap : m.snapshots->missing())
          notes.push_back(directory + "/" + gap +
                          " is a gap in the snapshot series (deleted or damaged since it was "
                          "written): particles.xdmf lists the snapshots around it");
        for (const std::string& again : m.snapshots->reused())
          notes.push_back(directory + "/" + again +
                          " comes after the last snapshot this restart takes over, and "
                          "particles.xdmf does not say when it was written: the restart writes "
                          "a snapshot under that number");
      }
    }
    // A restored run's first forces come from the checkpoint, without a network: a snapshot
    // before the first advance has none.
    const bool network = m.scene.output.contacts && sim.contact_network_recorded();
    m.snapshots->write(sim.particles(), sim.time(), step,
                       sim.snapshot_extras(m.snapshots->fields()),
                       network ? &sim.contact_network() : nullptr);
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
  return notes;
}

std::string DemLink::write_checkpoint(const std::string& directory, int keep) {
  Impl& m = *impl_;
  const FloatingPointTrapsOff traps_off;
  try {
    if (!m.checkpoints) {
      prepare_output_directory(directory);
      m.checkpoints =
          std::make_unique<CheckpointSeries>(m.dem_comm, directory, keep, m.restored_step);
    }
    const std::string path = m.checkpoints->write(m.simulation());
    // The rebuild reordered the particles: the exchange forces of the last step are
    // stale until the next advance() recomputes them (only deposits read them).
    m.fluid->exchange_force.clear();
    return std::filesystem::path(path).filename().string();
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
}

std::vector<std::string> DemLink::reports() const { return impl_->simulation().force_term_reports(); }

std::vector<std::string> DemLink::force_limit_notes() const {
  return impl_->simulation().force_limit_notes();
}

std::vector<std::string> DemLink::startup_notes() const {
  const Simulation& sim = impl_->simulation();
  const std::vector<std::string>& fluid = sim.force_limit_notes();
  std::vector<std::string> out;
  for (const std::string& note : sim.time_step_report().notes)
    if (std::find(fluid.begin(), fluid.end(), note) == fluid.end() &&
        !note.starts_with("steps to reach"))
      out.push_back(note);
  using Lines = const std::vector<std::string>*;
  for (Lines notes :
       {Lines{&sim.walls().notes()}, Lines{&sim.insertion_notes()}, Lines{&impl_->scene.notes}})
    out.insert(out.end(), notes->begin(), notes->end());
  return out;
}

std::string DemLink::time_step_refusal(double fluid_dt) const {
  const TimeStepReport& rep = impl_->simulation().time_step_report();
  if (rep.verdict != TimeStepReport::Verdict::refuse) return {};
  std::ostringstream o;
  o.precision(4);
  o << impl_->scene.file << ": error: refusing to run with this DEM time step (see the lines "
    << "above); ";
  // time.step must divide the fluid step: the largest such step the limits allow. (Not
  // time.rayleigh_fraction, as grain's advice offers: the step it gives divides deltaT only
  // by chance, and grainFoam refuses one that does not.)
  if (std::isfinite(rep.refusal_step) && rep.refusal_step > 0 && fluid_dt > 0) {
    const double n = std::ceil(fluid_dt / rep.refusal_step * (1 - 1e-12));
    o << "use a time.step <= " << rep.refusal_step
      << " s, the smallest step proposed above, which every limit above allows, that divides "
         "the fluid step (deltaT "
      << fluid_dt << " s): time.step " << fluid_dt / n << " s (deltaT / " << n << ")";
  } else {
    o << "lower time.step (to a whole fraction of deltaT " << fluid_dt << " s)";
  }
  o << "; or set `allowLargeTimeStep yes;` in constant/couplingProperties to start anyway (the "
       "run-time guards still stop it at the first contact this step does not resolve, keys "
       "time.min_steps_per_contact and time.max_overlap, or the first particle that moves too "
       "far in a step, time.max_step_travel; 0 turns min_steps_per_contact or max_step_travel "
       "off)";
  return o.str();
}

std::vector<std::string> DemLink::parcel_cell_warnings(double smallest_cell,
                                                      double typical_cell) const {
  if (impl_->scene.coarse_grain_table().empty()) return {};
  const std::vector<ParcelClass> classes =
      parcel_classes(impl_->scene, impl_->simulation().particles(), impl_->dem_comm);
  return grainflow::parcel_cell_warnings(classes, smallest_cell, typical_cell, "the fluid cells");
}

std::vector<std::string> DemLink::parcel_domain_warnings() const {
  if (impl_->scene.coarse_grain_table().empty()) return {};
  const std::vector<ParcelClass> classes =
      parcel_classes(impl_->scene, impl_->simulation().particles(), impl_->dem_comm);
  const Vec3 extent = impl_->scene.domain.hi - impl_->scene.domain.lo;
  std::vector<std::string> out =
      grainflow::parcel_domain_warnings(classes, extent, impl_->scene.domain.periodic);
  for (std::string& w : grainflow::parcel_opening_warnings(classes, impl_->simulation().walls(),
                                                           impl_->scene.domain))
    out.push_back(std::move(w));
  return out;
}

}  // namespace grainflow::coupling
