// A snapshot insertion takes every particle a run writes (docs/scene-reference.md,
// `type: snapshot`): a run keeps a particle until its centre leaves a bounded side, so a bead
// on its way out through a side without a wall crosses that side in the run's snapshot. The
// reading scene continues it (the bead leaves at the time its speed gives); with a wall on
// that side the reader refuses it as lying inside the wall, naming the wall and the overlap;
// a centre beyond a bounded side is refused naming the axis and the range.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <filesystem>
#include <sstream>
#include <string>

#include "dem/engine/run.hpp"
#include "dem/engine/simulation.hpp"
#include "dem/scene/scene_parser.hpp"

namespace grainflow {
namespace {

namespace fs = std::filesystem;

constexpr double kRadius = 1e-3, kSpeed = 1, kSide = 0.01;

std::string head(const std::string& walls = "") {
  return R"(domain: {min: [0, 0, 0], max: [0.01, 0.01, 0.01]}
gravity: [0, 0, 0]
time: {step: 1e-5, end: 0.0045}
materials:
  - {name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}
interaction_defaults: {restitution: 0.5, friction: 0.3}
contact: {normal: hertz}
)" + walls;
}

// One bead (r = 1 mm) from the centre at 1 m/s along +x: at t = 4.5 ms, when the run writes
// its snapshot, its centre is at x = 9.5 mm and it crosses the side x = 10 mm by 0.5 mm.
// `name`: the test's own folder (ctest runs the tests of this file in parallel).
std::string write_leaving_bead(const std::string& name) {
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "snapshot_domain" / name;
  fs::remove_all(dir);
  const Scene s = parse_scene(head() + R"(insert:
  - {type: fill, region: {box: {min: [0.004, 0.004, 0.004], max: [0.006, 0.006, 0.006]}},
     count: 1, material: glass, radius: {distribution: constant, value: 1e-3},
     velocity: [1, 0, 0]}
output: {snapshot_interval: 0.0045, progress: false}
)",
                              "writer.yaml");
  RunOptions options;
  options.output_directory = dir.string();
  options.progress = false;
  options.handle_stop_signals = false;
  std::ostringstream log;
  run_scene(s, options, MPI_COMM_WORLD, log);
  return (dir / "particles_000001.h5").string();
}

Scene reader(const std::string& file, const std::string& walls = "") {
  return parse_scene(
      head(walls) + "insert:\n  - {type: snapshot, file: " + file + ", keep_velocity: true}\n",
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

TEST(SnapshotDomain, ALeavingBeadOfTheRunsOwnSnapshotContinuesAndLeaves) {
  const std::string file = write_leaving_bead("continues");
  ASSERT_TRUE(fs::exists(file));
  Simulation sim(reader(file), true, MPI_COMM_SELF);
  ASSERT_EQ(sim.particles().size(), 1u);
  const double x0 = sim.particles().x[0][0];
  EXPECT_NEAR(x0, 0.005 + kSpeed * 0.0045, 1e-12);
  EXPECT_GT(x0 + kRadius, kSide);  // crosses the bounded side: the case this test is about
  EXPECT_EQ(sim.particles().v[0][0], kSpeed);
  // Its centre reaches the side 0.5 ms later: still there just before, removed just after.
  sim.advance_to(sim.time() + 0.00049);
  EXPECT_EQ(sim.particles().size(), 1u);
  sim.advance_to(sim.time() + 0.00002);
  EXPECT_EQ(sim.particles().size(), 0u);
}

TEST(SnapshotDomain, AWallOnThatSideRefusesItNamingTheWallAndTheOverlap) {
  const std::string file = write_leaving_bead("wall");
  const std::string e = error_of(
      reader(file,
             "walls:\n  - {type: plane, name: right, point: [0.01, 0, 0], normal: [-1, 0, 0], "
             "material: glass}\n"));
  EXPECT_NE(e.find("lies inside wall 'right': it overlaps it by 0.0005 m, 50 % of its radius"),
            std::string::npos)
      << e;
}

TEST(SnapshotDomain, ACentreBeyondABoundedSideIsRefusedNamingTheAxisAndRange) {
  const std::string file = write_leaving_bead("beyond");
  {  // move the bead's centre 0.1 mm beyond x = 10 mm
    const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    const hid_t d = H5Dopen2(f, "/position", H5P_DEFAULT);
    double x[3] = {0.0101, 0.005, 0.005};
    ASSERT_GE(H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, x), 0);
    H5Dclose(d);
    H5Fclose(f);
  }
  const std::string e = error_of(reader(file));
  EXPECT_NE(e.find("the particle lies outside the domain: its centre x = 0.0101 is outside the "
                   "bounded range [0, 0.01]"),
            std::string::npos)
      << e;
}

}  // namespace
}  // namespace grainflow
