// DemLink inside a process that traps floating-point exceptions, as grainFoam is (OpenFOAM's
// FOAM_SIGFPE: division by zero, invalid operation and overflow raise SIGFPE). The DEM's pair
// kernel evaluates four contacts at a time and computes both sides of a branch in every lane
// (0/0 for the rotation of a fresh, zero tangential spring), so every DemLink call that runs
// DEM code must do so with the traps off and give them back afterwards. Before that held for
// initialise(), a bed starting in contact (its springs zero) killed grainFoam at its first
// forces (CI, accuracy_cost.coupled_short).
#include <fenv.h>
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "coupling/dem_link.hpp"
#include "dem/core/number_format.hpp"
#include "dem/core/particles.hpp"
#include "dem/io/output_directory.hpp"
#include "dem/io/snapshot_writer.hpp"

namespace grainflow::coupling {
namespace {

namespace fs = std::filesystem;

constexpr int kTraps = FE_DIVBYZERO | FE_INVALID | FE_OVERFLOW;

// Restores the process's traps however the test ends.
class Traps {
 public:
  Traps() : before_(fegetexcept()) {
    feclearexcept(FE_ALL_EXCEPT);
    feenableexcept(kTraps);
  }
  ~Traps() {
    fedisableexcept(FE_ALL_EXCEPT);
    feenableexcept(before_);
  }

 private:
  int before_;
};

TEST(DemLink, RunsWithTheProcessTrappingFloatingPointExceptions) {
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "dem_link_traps";
  fs::remove_all(dir);
  prepare_output_directory((dir / "bed").string());
  // A 6 x 6 x 6 lattice of 1 mm glass beads, 1.98 mm apart: every neighbour pair overlaps by
  // 1 % of the radius from the start, with zero springs, on a floor.
  const double r = 0.001, spacing = 1.98e-3;
  Particles p;
  GlobalId id = 1;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      for (int k = 0; k < 6; ++k)
        p.add(id++, Vec3(0.002 + i * spacing, 0.002 + j * spacing, r + k * spacing), Vec3::Zero(),
              Vec3::Zero(), r, 0, 2500);
  SnapshotWriter snapshots(MPI_COMM_WORLD, (dir / "bed").string());
  const std::string bed = snapshots.write(p, 0, 0);
  const std::string scene = (dir / "scene.yaml").string();
  std::ofstream(scene) << "domain: {min: [0, 0, 0], max: [0.016, 0.016, 0.016]}\n"
                          "gravity: [0, 0, -9.81]\n"
                          "time: {step: 1.0e-6, end: 1.0}\n"
                          "materials: [{name: glass, youngs_modulus: 1.0e8, poisson_ratio: 0.3, "
                          "density: 2500}]\n"
                          "interaction_defaults: {restitution: 0.5, friction: 0.3}\n"
                          "contact: {normal: hertz, tangential: history}\n"
                          "walls: [{type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], "
                          "material: glass}]\n"
                       << "insert: [{type: snapshot, file: " << bed << ", keep_velocity: false}]\n"
                       << "fluid: {density: 1.2, viscosity: 1.8e-5, drag: di_felice, model: A, pressure: {hydrostatic: false}, "
                          "forces: [drag, pressure_gradient, viscous, buoyancy]}\n";

  const Traps traps;
  DemLink link(scene, 1.2, 1.8e-5, MPI_COMM_WORLD);
  link.initialise();  // the first forces: 540 touching pairs with zero springs
  EXPECT_EQ(fegetexcept(), kTraps) << "initialise() did not give the traps back";
  for (int round = 0; round < 3; ++round) {
    const ParticleSet set = link.particles(false);
    link.begin_fluid();
    for (std::size_t i = 0; i < set.local; ++i) link.add_fluid(FluidAtParticle{});  // air at rest
    link.end_fluid([](const std::array<double, 3>&) { return FluidAtParticle{}; });
    link.advance(20, (dir / "diagnostics").string());
    EXPECT_EQ(fegetexcept(), kTraps) << "advance() did not give the traps back";
  }
  link.write_checkpoint((dir / "checkpoints").string(), 1);
  EXPECT_EQ(fegetexcept(), kTraps) << "write_checkpoint() did not give the traps back";
  const DemSummary s = link.summary();
  EXPECT_EQ(s.particles, 216);
  // 3 x 6 x 6 x 5 = 540 lattice neighbour pairs, all still touching after 60 us.
  EXPECT_EQ(s.contacts, 540 + 36);  // and the bottom layer on the floor
  EXPECT_TRUE(std::isfinite(s.kinetic_energy));
}

// DemLink::fluid_samples() (the coupling writes into the DEM's sample records) serves the DEM
// exactly what add_fluid() per particle does: the same particles after three fluid steps of
// different samples, to the last bit, with the storage reused between the steps (the
// density and viscosity the drag needs are the run's constants in either path).
TEST(DemLink, SampleRecordsActLikeAddFluid) {
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "dem_link_records";
  fs::remove_all(dir);
  prepare_output_directory(dir.string());
  const std::string scene = (dir / "scene.yaml").string();
  std::ofstream(scene) << "domain: {min: [0, 0, 0], max: [0.02, 0.02, 0.04]}\n"
                          "gravity: [0, 0, -9.81]\n"
                          "time: {step: 1.0e-5, end: 1.0}\n"
                          "materials: [{name: glass, youngs_modulus: 1.0e7, poisson_ratio: 0.3, "
                          "density: 2500}]\n"
                          "interaction_defaults: {restitution: 0.5, friction: 0.3}\n"
                          "contact: {normal: hertz, tangential: history}\n"
                          "walls: [{type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], "
                          "material: glass}]\n"
                          "insert: [{type: fill, region: {box: {min: [0, 0, 0], max: [0.02, 0.02, "
                          "0.04]}}, count: 300, material: glass, radius: {distribution: uniform, "
                          "min: 4.0e-4, max: 6.0e-4}}]\n"
                          "fluid: {density: 1.2, viscosity: 1.8e-5, drag: di_felice, model: A, "
                          "pressure: {hydrostatic: false}, forces: [drag, pressure_gradient, "
                          "viscous, buoyancy]}\n";
  // The fluid at particle i in round k: not uniform, so that an entry out of order shows.
  const auto fluid_at = [](std::size_t i, int k) {
    FluidAtParticle f;
    f.velocity = {0.01 * std::sin(0.1 * i + k), -0.02 * std::cos(0.3 * i), 0.5 + 0.001 * i};
    f.void_fraction = 0.4 + 0.5 * std::abs(std::sin(0.7 * i + k));
    f.pressure_gradient = {1.0 * k, 2.0, -30.0 - 0.1 * i};
    f.viscous_stress_divergence = {0.01 * i, -0.5, 0.25 * k};
    return f;
  };
  const auto late = [](const std::array<double, 3>&) { return FluidAtParticle{}; };
  // A third run in still air (eps = 1, no gradients) shows that the samples matter.
  DemLink by_call(scene, 1.2, 1.8e-5, MPI_COMM_WORLD), by_record(scene, 1.2, 1.8e-5, MPI_COMM_WORLD),
      still(scene, 1.2, 1.8e-5, MPI_COMM_WORLD);
  by_call.initialise();
  by_record.initialise();
  still.initialise();
  for (int k = 0; k < 3; ++k) {
    const std::size_t n = by_call.particles(false).local;
    ASSERT_EQ(by_record.particles(false).local, n);
    by_call.begin_fluid();
    for (std::size_t i = 0; i < n; ++i) by_call.add_fluid(fluid_at(i, k));
    by_call.end_fluid(late);
    const DemLink::SampleRecords at = by_record.fluid_samples();
    EXPECT_EQ(at.vorticity, nullptr);  // no lift force in this scene
    for (std::size_t i = 0; i < n; ++i) {
      const FluidAtParticle f = fluid_at(i, k);
      double* r = at.records + at.stride * i;
      for (int d = 0; d < 3; ++d) {
        r[at.velocity + d] = f.velocity[d];
        r[at.pressure_gradient + d] = f.pressure_gradient[d];
        r[at.viscous_stress_divergence + d] = f.viscous_stress_divergence[d];
      }
      r[at.void_fraction] = f.void_fraction;
    }
    by_record.end_fluid(late);
    still.begin_fluid();
    for (std::size_t i = 0; i < n; ++i) still.add_fluid(FluidAtParticle{});
    still.end_fluid(late);
    by_call.advance(50, (dir / "diagnostics").string());
    by_record.advance(50, (dir / "diagnostics").string());
    still.advance(50, (dir / "diagnostics").string());
  }
  const ParticleSet a = by_call.particles(false), b = by_record.particles(false),
                    c = still.particles(false);
  ASSERT_EQ(a.local, b.local);
  ASSERT_EQ(a.local, c.local);
  std::size_t differ_from_still = 0;
  for (std::size_t i = 0; i < a.local; ++i) {
    EXPECT_EQ(a.id[i], b.id[i]);
    EXPECT_EQ(a.x[i], b.x[i]) << "particle " << a.id[i];
    EXPECT_EQ(a.v[i], b.v[i]) << "particle " << a.id[i];
    differ_from_still += a.v[i] != c.v[i];
  }
  EXPECT_EQ(differ_from_still, a.local);
}

// A coupled scene with `heat:` needs the fluid's convection settings (grainFoam's energy
// equation exchanges heat by convection): without them the link refuses it, naming the fluid
// block's file:line, the heat block's and the keys to add.
TEST(DemLink, RefusesHeatWithoutTheFluidsConvectionSettings) {
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "dem_link_heat";
  fs::create_directories(dir);
  const std::string scene = (dir / "scene.yaml").string();
  std::ofstream(scene) << "domain: {min: [0, 0, 0], max: [0.016, 0.016, 0.016]}\n"
                          "time: {step: 1.0e-6, end: 1.0}\n"
                          "heat: {}\n"
                          "materials: [{name: glass, youngs_modulus: 1.0e8, poisson_ratio: 0.3, "
                          "density: 2500, heat_capacity: 840, conductivity: 1}]\n"
                          "interaction_defaults: {restitution: 0.5, friction: 0.3}\n"
                          "contact: {normal: hertz}\n"
                          "fluid: {density: 1.2, viscosity: 1.8e-5, drag: di_felice, model: A, "
                          "pressure: {hydrostatic: false}, forces: [drag, pressure_gradient, "
                          "viscous]}\n";
  std::string message = "no error";
  try {
    DemLink link(scene, 1.2, 1.8e-5, MPI_COMM_WORLD);
  } catch (const std::runtime_error& e) {
    message = e.what();
  }
  // The fluid block (line 7) is named, with the heat block (line 3) and the keys to add.
  EXPECT_NE(message.find(scene + ":7: error: heat is on (" + scene + ":3)"), std::string::npos)
      << message;
  for (const char* key : {"`temperature: <K>`", "`heat_capacity: <J/(kg K)>`",
                          "`conductivity: <W/(m K)>`", "docs/models/heat-transfer.md"})
    EXPECT_NE(message.find(key), std::string::npos) << key << " in " << message;
}

// Coarse-grained parcels in a coupled run (docs/models/coarse-graining.md, "Coupled"): the
// drag coefficient the coupling deposits (K on the fluid's diagonal, ParticleView) is the real
// particle's at the parcel's slip times k^3, and the explicit force it returns (model B:
// pressure gradient and viscous force) acts on the parcel's volume, k^3 real volumes.
// Reference: Schiller-Naumann's K = 3 pi mu d (1 + 0.15 Re^0.687), Re = rho d U / mu, for the
// real d, and -V grad p + V div(tau) with V = 4/3 pi (k r)^3, computed here.
const char* kParcelScene =
    "domain: {min: [0, 0, 0], max: [0.02, 0.02, 0.04]}\n"
    "gravity: [0, 0, 0]\n"
    "time: {step: 1e-5, end: 0.01}\n"
    "materials:\n"
    "  - {name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}\n"
    "interaction_defaults: {restitution: 0.5}\n"
    "contact: {normal: hertz}\n"
    "insert:\n"
    "  - type: fill\n"
    "    region: {box: {min: [0, 0, 0], max: [0.02, 0.02, 0.02]}}\n"
    "    count: 10\n"
    "    material: glass\n"
    "    radius: {distribution: constant, value: 3e-4}\n"
    "    coarse_grain: 2\n"
    "  - {type: fill, region: {box: {min: [0, 0, 0.02], max: [0.02, 0.02, 0.04]}}, count: 10,\n"
    "     material: glass, radius: {distribution: constant, value: 3e-4}}\n"
    "fluid: {density: 1000, viscosity: 1e-3, drag: schiller_naumann, model: B,\n"
    "        pressure: {hydrostatic: false},\n"
    "        forces: [drag, pressure_gradient, viscous, buoyancy]}\n";

// kParcelScene after one DEM step from rest (v = 0: K and the forces of the first step) with
// the same fluid at every particle; `cell_velocity` (by particle id), when given, is handed
// to the DEM as the footprint's cell velocities (sampling cellPoint).
struct ParcelStep {
  static constexpr double rho = 1000, mu = 1e-3, r = 3e-4;
  static constexpr std::array<double, 3> u{0.004, -0.003, 0.012}, grad_p{20, -10, -150},
      div_tau{0.5, 1, -2};
  std::unique_ptr<DemLink> link;
  ParticleView view;
  ParticleSet after;  // the view's order, with the ids

  ParcelStep(const std::string& name,
             std::function<std::array<double, 3>(long long)> cell_velocity = nullptr) {
    const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / name;
    fs::create_directories(dir);
    const fs::path scene = dir / "parcels.yaml";
    std::ofstream(scene) << kParcelScene;
    link = std::make_unique<DemLink>(scene.string(), rho, mu, MPI_COMM_WORLD);
    link->initialise();
    const FluidAtParticle f = fluid();
    const ParticleSet set = link->particles(false);
    link->begin_fluid();
    std::vector<std::array<double, 3>> cells;
    for (std::size_t i = 0; i < set.local; ++i) {
      link->add_fluid(f);
      if (cell_velocity) cells.push_back(cell_velocity(set.id[i]));
    }
    if (cell_velocity) link->set_fluid_cell_velocities(cells);
    link->end_fluid([f](const std::array<double, 3>&) { return f; });
    link->advance(1, (dir / "diagnostics").string());
    link->view(view);
    after = link->particles(false);
  }
  FluidAtParticle fluid() const {
    FluidAtParticle f;
    f.velocity = u;
    f.void_fraction = 0.7;
    f.pressure_gradient = grad_p;
    f.viscous_stress_divergence = div_tau;
    return f;
  }
  // Schiller & Naumann's K of a real particle at slip u.
  double k_real() const {
    const double pi = std::acos(-1.0), d = 2 * r;
    const double re = rho * d * std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]) / mu;
    return 3 * pi * mu * d * (1 + 0.15 * std::pow(re, 0.687));
  }
  // The explicit force the fluid gets back from the pressure and viscous forces.
  double carried(double volume, int c) const { return -volume * grad_p[c] + volume * div_tau[c]; }
};

TEST(DemLink, ParcelsCarryTheRealDragTimesK3AndTheirOwnVolume) {
  const ParcelStep step("dem_link_parcels");
  const double r = ParcelStep::r, pi = std::acos(-1.0);
  int parcels = 0, reals = 0;
  for (std::size_t i = 0; i < step.view.local(); ++i) {
    const double k = step.view.radius(i) / r;  // 2 for a parcel, 1 for a real particle
    ASSERT_TRUE(std::abs(k - 2) < 1e-12 || std::abs(k - 1) < 1e-12) << step.view.radius(i);
    (k > 1.5 ? parcels : reals) += 1;
    EXPECT_NEAR(step.view.drag_coefficient(i) / (k * k * k * step.k_real()), 1, 1e-13) << "k = " << k;
    const double volume = 4.0 / 3.0 * pi * std::pow(k * r, 3);
    const std::array<double, 3> carried = step.view.exchange_force(i);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(carried[c], step.carried(volume, c), 1e-13 * volume * std::abs(step.grad_p[2]))
          << "k = " << k << ", component " << c;
  }
  EXPECT_EQ(parcels, 10);
  EXPECT_EQ(reals, 10);
}

// sampling cellPoint: the fluid's implicit term takes K (v - U_fp) at the footprint's cells,
// so the particle's exchange force must carry the rest of its drag, K (u_f - U_fp), or the
// fluid would not get the drag the particle feels. Reference: K from Schiller & Naumann's
// closed form (times k^3 for the parcels) at the first step (v = 0), U_fp chosen per particle
// from its id (so that a value served to the wrong particle shows).
TEST(DemLink, CellPointReturnsTheDragsRemainderExplicitly) {
  constexpr std::array<double, 3> u = ParcelStep::u;
  const auto cell_velocity = [u](long long id) {
    const double x = static_cast<double>(id);
    return std::array<double, 3>{u[0] - 1e-4 * x, u[1] + 2e-4, u[2] - 3e-5 * x};
  };
  const ParcelStep step("dem_link_cell_velocity", cell_velocity);
  const double r = ParcelStep::r, pi = std::acos(-1.0);
  ASSERT_EQ(step.view.local(), 20u);
  ASSERT_EQ(step.after.local, 20u);
  for (std::size_t i = 0; i < step.view.local(); ++i) {
    const double k = step.view.radius(i) / r;
    const double K = k * k * k * step.k_real(), volume = 4.0 / 3.0 * pi * std::pow(k * r, 3);
    const std::array<double, 3> uc = cell_velocity(step.after.id[i]);
    const std::array<double, 3> carried = step.view.exchange_force(i);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(carried[c], step.carried(volume, c) + K * (u[c] - uc[c]),
                  1e-12 * volume * std::abs(step.grad_p[2]))
          << "particle " << step.after.id[i] << ", component " << c;
  }
  // A count that does not match the particles is refused at end_fluid().
  const FluidAtParticle f = step.fluid();
  step.link->begin_fluid();
  for (std::size_t i = 0; i < step.after.local; ++i) step.link->add_fluid(f);
  step.link->set_fluid_cell_velocities(std::vector<std::array<double, 3>>(3));
  EXPECT_THROW(step.link->end_fluid(), std::logic_error);
}

// The fluidisedBed tutorial's beads (d = 1.14-1.26 mm glass in air, cells of 3 mm) as parcels
// of k = 1, 2, 3: grainFoam's start-up warning (DemLink::parcel_cell_warnings, the rule of
// grain check; Radl et al. 2011). k = 1: real beads, no warning. k = 2: parcels up to 2.52 mm,
// cells of 1.19 parcel diameters, one warning (fewer than 3). k = 3: parcels up to 3.78 mm,
// wider than the cells: both warnings, each naming the class glass[k=3], the largest parcel
// diameter (from the particles, independently of the link) and the cell sizes. The domain's
// warning (its 9 mm depth under 10 parcel diameters) for k = 2 and 3, not for the beads.
std::string fluidised_bed_scene(double k) {
  std::ostringstream s;
  s << "domain: {min: [0, 0, 0], max: [0.06, 0.009, 0.06]}\n"
       "gravity: [0, 0, -9.81]\n"
       "time: {step: 1.5e-5, end: 0.01}\n"
       "materials:\n"
       "  - {name: glass, youngs_modulus: 2e6, poisson_ratio: 0.25, density: 2500}\n"
       "interaction_defaults: {restitution: 0.9, friction: 0.3}\n"
       "contact: {normal: hertz, tangential: history}\n"
       "insert:\n"
       "  - type: fill\n"
       "    region: {box: {min: [0, 0, 0.002], max: [0.06, 0.009, 0.05]}}\n"
       "    count: 30\n"
       "    material: glass\n"
       "    radius: {distribution: uniform, min: 0.57e-3, max: 0.63e-3}\n"
       "    coarse_grain: "
    << k << "\n"
       "    seed: 1\n"
       "fluid: {density: 1.2, viscosity: 1.8e-5, drag: di_felice, model: A,\n"
       "        pressure: {hydrostatic: false},\n"
       "        forces: [drag, pressure_gradient, viscous, buoyancy]}\n";
  return s.str();
}

TEST(DemLink, WarnsOfParcelsLargeAgainstTheCells) {
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "dem_link_parcels";
  fs::create_directories(dir);
  const double cell = 0.003;
  for (const int k : {1, 2, 3}) {
    const fs::path scene = dir / ("fluidised_bed_k" + std::to_string(k) + ".yaml");
    std::ofstream(scene) << fluidised_bed_scene(k);
    DemLink link(scene.string(), 1.2, 1.8e-5, MPI_COMM_WORLD);
    link.initialise();
    const std::vector<std::string> warnings = link.parcel_cell_warnings(cell, cell);
    const ParticleSet set = link.particles(false);
    double widest = 0;
    for (std::size_t i = 0; i < set.local; ++i) widest = std::max(widest, 2 * set.radius[i]);
    MPI_Allreduce(MPI_IN_PLACE, &widest, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    ASSERT_GT(widest, k * 1.14e-3);
    ASSERT_LE(widest, k * 1.26e-3 * (1 + 1e-12));
    // The domain's rule (grain check's): its 9 mm depth is less than 10 parcel diameters for
    // k = 2 and 3 (3.6 and 2.4 parcels deep), not a concern for the beads.
    const std::vector<std::string> domain = link.parcel_domain_warnings();
    if (k == 1) {
      EXPECT_TRUE(warnings.empty()) << warnings.front();
      EXPECT_TRUE(domain.empty()) << domain.front();
      continue;
    }
    ASSERT_EQ(domain.size(), 1u);
    EXPECT_EQ(domain[0].rfind("warning: the domain's narrowest side (0.009 m) is less than 10 "
                              "diameters of parcels 'glass[k=" +
                                  std::to_string(k) + "]' (" + significant(widest) + " m)",
                              0),
              0u)
        << domain[0];
    const std::string cls = "parcels 'glass[k=" + std::to_string(k) + "]' (diameter up to " +
                            significant(widest) + " m)";
    const std::string cells = "(smallest 0.003 m, typical 0.003 m)";
    ASSERT_EQ(warnings.size(), k == 3 ? 2u : 1u);
    EXPECT_EQ(warnings[0].rfind("warning: " + cls + " are wider than a third of the fluid cells " +
                                    cells + ": cells of " + significant(cell / widest, 3) +
                                    " parcel diameters, fewer than 3;",
                                0),
              0u)
        << warnings[0];
    EXPECT_NE(warnings[0].find("(Radl et al. 2011)"), std::string::npos) << warnings[0];
    if (k == 3) {
      EXPECT_EQ(warnings[1].rfind("warning: " + cls + " are wider than the fluid cells " + cells,
                                  0),
                0u)
          << warnings[1];
    }
  }
}

// The undisturbed-velocity correction models one particle's own disturbance: with parcels
// the link refuses it, naming the insertion's file:line and the key.
TEST(DemLink, RefusesTheUndisturbedVelocityWithParcels) {
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "dem_link_parcels";
  fs::create_directories(dir);
  const fs::path scene = dir / "parcels_undisturbed.yaml";
  std::ofstream(scene) << kParcelScene;
  DemLink link(scene.string(), 1000, 1e-3, MPI_COMM_WORLD);
  link.correct_self_disturbance(false);  // off: nothing to refuse
  std::string message;
  try {
    link.correct_self_disturbance(true);
  } catch (const std::runtime_error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("parcels_undisturbed.yaml:9: error: insert.coarse_grain 2: the "
                         "undisturbed-velocity correction (constant/couplingProperties "
                         "undisturbedVelocity oseenBrinkman)"),
            std::string::npos)
      << message;
}

}  // namespace
}  // namespace grainflow::coupling
