// A snapshot insertion from snapshots whose scene left fields out of `output.fields`
// (docs/scene-reference.md, `type: snapshot`): what can be had is had — the radius from
// `diameter` (d = 2 r exactly), the mass as rho (4/3) pi r^3 (the closed form every inserted
// particle's mass satisfies), no velocities when the particles start at rest — and what cannot
// (material, any size, velocities with keep_velocity: true) is refused naming the dataset and
// the field to list, with advice that, rerun, works.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <sstream>
#include <string>

#include "dem/engine/run.hpp"
#include "dem/engine/simulation.hpp"
#include "dem/scene/scene_parser.hpp"

namespace grainflow {
namespace {

namespace fs = std::filesystem;

constexpr double kRadius = 5e-4, kDensity = 2500;

std::string head() {
  return R"(domain: {min: [0, 0, 0], max: [0.01, 0.01, 0.02]}
gravity: [0, 0, -9.81]
time: {step: 2e-6, end: 0.002}
materials:
  - {name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}
interaction_defaults: {restitution: 0.5, friction: 0.3}
contact: {normal: hertz}
)";
}

// Runs 12 falling beads with `fields` and returns the last snapshot's path.
std::string write_snapshot(const std::string& name, const std::string& fields) {
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "snapshot_fields" / name;
  fs::remove_all(dir);
  const Scene s = parse_scene(head() + R"(insert:
  - type: fill
    region: {box: {min: [0, 0, 0.005], max: [0.01, 0.01, 0.02]}}
    count: 12
    material: glass
    radius: {distribution: constant, value: 5e-4}
output: {snapshot_interval: 0.002, progress: false, fields: )" +
                                  fields + "}\n",
                              "writer.yaml");
  RunOptions options;
  options.output_directory = dir.string();
  options.progress = false;
  options.handle_stop_signals = false;
  std::ostringstream log;
  run_scene(s, options, MPI_COMM_WORLD, log);
  return (dir / "particles_000001.h5").string();
}

Scene reader(const std::string& file, bool keep_velocity) {
  return parse_scene(head() + "insert:\n  - {type: snapshot, file: " + file +
                         ", keep_velocity: " + (keep_velocity ? "true" : "false") + "}\n",
                     "reader.yaml");
}

std::string error_of(const Scene& s) {
  try {
    Simulation sim(s, true, MPI_COMM_SELF);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}

TEST(SnapshotFields, DiameterAndMaterialSufficeForABedAtRest) {
  const std::string file = write_snapshot("diameter", "[diameter, material]");
  const Scene s = reader(file, false);
  Simulation sim(s, true, MPI_COMM_SELF);
  const Particles& p = sim.particles();
  ASSERT_EQ(p.size(), 12u);
  const double mass = kDensity * 4.0 / 3.0 * std::numbers::pi * std::pow(kRadius, 3);
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_EQ(p.radius[i], kRadius);  // d / 2 of d = 2 r: exact
    EXPECT_NEAR(p.mass[i] / mass, 1, 1e-14);
    EXPECT_NEAR(p.inertia[i] / (0.4 * mass * kRadius * kRadius), 1, 1e-14);
    EXPECT_EQ(p.v[i], Vec3::Zero());
  }
  // Kept velocities need the velocities: refused, naming the dataset and both remedies; the
  // first remedy rerun (keep_velocity: false) is the start above.
  const std::string e = error_of(reader(file, true));
  std::printf("%s\n", e.c_str());
  EXPECT_NE(e.find(file + ": error: no dataset '/velocity': the scene that wrote this snapshot "
                          "left it out of output.fields"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("start them at rest with `keep_velocity: false` (insertion at reader.yaml:9)"),
            std::string::npos)
      << e;
}

TEST(SnapshotFields, KeptVelocitiesComeBackBitForBit) {
  const std::string file =
      write_snapshot("velocities", "[radius, mass, material, velocity, angular_velocity]");
  const std::string full = write_snapshot("full",
                                          "[radius, mass, material, velocity, "
                                          "angular_velocity, force]");
  Simulation a(reader(file, true), true, MPI_COMM_SELF), b(reader(full, true), true, MPI_COMM_SELF);
  ASSERT_EQ(a.particles().size(), 12u);
  ASSERT_EQ(b.particles().size(), 12u);
  double speed = 0;
  for (std::size_t i = 0; i < 12; ++i) {
    EXPECT_EQ(a.particles().x[i], b.particles().x[i]);
    EXPECT_EQ(a.particles().v[i], b.particles().v[i]);
    speed = std::max(speed, a.particles().v[i].norm());
  }
  // Free fall for 2 ms from rest (no bead reaches the floor or another): |v| = g t.
  EXPECT_NEAR(speed, 9.81 * 0.002, 1e-9);
}

TEST(SnapshotFields, MissingMaterialOrSizeIsRefusedNamingTheField) {
  std::string e = error_of(reader(write_snapshot("no_material", "[radius, mass]"), false));
  std::printf("%s\n", e.c_str());
  EXPECT_NE(e.find("error: no dataset '/material' (field material): the scene that wrote this "
                   "snapshot left it out of output.fields, and a snapshot insertion needs it; "
                   "list it there"),
            std::string::npos)
      << e;
  e = error_of(reader(write_snapshot("no_size", "[material, mass]"), false));
  std::printf("%s\n", e.c_str());
  EXPECT_NE(e.find("error: neither dataset '/radius' nor '/diameter' (field radius or diameter)"),
            std::string::npos)
      << e;
}

}  // namespace
}  // namespace grainflow
