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

#include <cmath>
#include <filesystem>
#include <fstream>

#include "coupling/dem_link.hpp"
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

}  // namespace
}  // namespace grainflow::coupling
