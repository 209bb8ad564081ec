// output.wall_loads: each wall's mean load (the force the particles exert on it by contact)
// over a log interval, summed over 2 ranks.
//
// References, independent of the engine's sums:
//  * Newton's third law and a bed at rest: the walls together carry the particles' weight,
//    sum of the z loads = M g, and no net sideways load. Checked for planes on the lanes
//    path of the wall sweep (Hertz + history), and for a cylinder and a triangle-mesh floor
//    on the contact-by-contact path (with rolling resistance). Tolerance 1e-3 of M g: what
//    the bed still moves after settling (its momentum change over the interval).
//  * A sphere sliding on a floor (Coulomb friction, mu): until it rolls, at
//    t_roll = 2 v0 / (7 mu g), the floor feels mu m g along the motion and m g down. Mean over
//    the first 0.6 t_roll, tolerance 1 %.
//  * A restart from a checkpoint written between log rows reports the loads of the
//    uninterrupted run (the checkpoint carries the sums since the last row): the same rows,
//    bit for bit on the same ranks.
//  * A checkpoint whose attribute 'wall_impulse' is damaged or from another scene is refused,
//    naming the attribute.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <mpi.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "dem/engine/run.hpp"
#include "dem/engine/simulation.hpp"
#include "dem/scene/scene_parser.hpp"

namespace grainflow {
namespace {

namespace fs = std::filesystem;

const fs::path kWork = fs::path(GRAINFLOW_BINARY_DIR) / "test_output/wall_loads_mpi";

int rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

// Writes `text` to `path` on rank 0; every rank waits for it.
void write_file(const fs::path& path, const std::string& text) {
  if (rank() == 0) {
    fs::create_directories(path.parent_path());
    std::ofstream(path) << text;
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

double total_mass(const Simulation& sim) {
  double m = 0;
  for (double x : sim.particles().mass) m += x;
  MPI_Allreduce(MPI_IN_PLACE, &m, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  return m;
}

// 400 beads poured into a 7 x 7 mm box or an 8 mm silo, settled for 0.3 s; then the mean loads
// over 0.05 s.
void expect_walls_carry_the_bed(const std::string& name, const std::string& walls,
                                const std::string& contact, bool mesh) {
  const fs::path dir = kWork / name;
  if (mesh)  // a 20 x 20 mm square floor at z = 0, two triangles, normal +z
    write_file(dir / "floor.stl",
               "solid floor\n"
               " facet normal 0 0 1\n  outer loop\n   vertex -0.01 -0.01 0\n"
               "   vertex 0.01 -0.01 0\n   vertex 0.01 0.01 0\n  endloop\n endfacet\n"
               " facet normal 0 0 1\n  outer loop\n   vertex -0.01 -0.01 0\n"
               "   vertex 0.01 0.01 0\n   vertex -0.01 0.01 0\n  endloop\n endfacet\n"
               "endsolid floor\n");
  write_file(dir / "scene.yaml",
             "domain: {min: [-0.005, -0.005, 0], max: [0.005, 0.005, 0.03]}\n"
             "gravity: [0, 0, -9.81]\n"
             "time: {rayleigh_fraction: 0.15, end: 1}\n"
             "materials:\n"
             "  - {name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}\n"
             "interactions:\n"
             "  - {materials: [glass, glass], restitution: 0.5, friction: 0.5, "
             "rolling_friction: 0.1}\n"
             "contact: " +
                 contact +
                 "\n"
                 "walls:\n" +
                 walls +
                 "insert:\n"
                 "  - type: fill\n"
                 "    region: {box: {min: [-0.0025, -0.0025, 0.001], max: [0.0025, 0.0025, "
                 "0.029]}}\n"
                 "    count: 400\n"
                 "    material: glass\n"
                 "    radius: {distribution: uniform, min: 3e-4, max: 4e-4}\n"
                 "output: {wall_loads: true}\n");
  Simulation sim(load_scene((dir / "scene.yaml").string()));
  sim.advance_to(0.3);
  const double settled = sim.time();
  (void)sim.take_wall_loads();  // the pour
  sim.advance_to(0.35);
  const Simulation::WallLoads loads = sim.take_wall_loads();
  const double weight = total_mass(sim) * 9.81;
  ASSERT_EQ(loads.force.size(), sim.walls().walls().size());
  EXPECT_NEAR(loads.interval, sim.time() - settled, 1e-12);
  Vec3 total = Vec3::Zero();
  for (const Vec3& f : loads.force) total += f;
  if (rank() == 0) {
    std::printf("%s: walls carry (%.6g %.6g %.6g) M g over %.4g s:", name.c_str(),
                total[0] / weight, total[1] / weight, total[2] / weight, loads.interval);
    for (std::size_t w = 0; w < loads.force.size(); ++w)
      std::printf(" %s %.6g", sim.walls().walls()[w].name.c_str(), -loads.force[w][2] / weight);
    std::printf("\n");
  }
  EXPECT_NEAR(total[2] / weight, -1.0, 1e-3) << name;
  EXPECT_NEAR(total[0] / weight, 0.0, 1e-3) << name;
  EXPECT_NEAR(total[1] / weight, 0.0, 1e-3) << name;
  // The lid, above the bed, is never touched: exactly zero.
  for (std::size_t w = 0; w < loads.force.size(); ++w)
    if (sim.walls().walls()[w].name == "lid") {
      EXPECT_EQ(loads.force[w], Vec3::Zero());
    }
}

TEST(WallLoads, PlaneBoxCarriesTheSettledBed) {
  expect_walls_carry_the_bed(
      "planes",
      "  - {type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass}\n"
      "  - {type: plane, name: left, point: [-0.0035, 0, 0], normal: [1, 0, 0], material: glass}\n"
      "  - {type: plane, name: right, point: [0.0035, 0, 0], normal: [-1, 0, 0], material: "
      "glass}\n"
      "  - {type: plane, name: back, point: [0, -0.0035, 0], normal: [0, 1, 0], material: glass}\n"
      "  - {type: plane, name: front, point: [0, 0.0035, 0], normal: [0, -1, 0], material: "
      "glass}\n"
      "  - {type: plane, name: lid, point: [0, 0, 0.03], normal: [0, 0, -1], material: glass}\n",
      "{normal: hertz, tangential: history}", false);
}

TEST(WallLoads, CylinderAndMeshFloorCarryTheSettledBed) {
  expect_walls_carry_the_bed(
      "cylinder_mesh",
      "  - {type: mesh, name: floor, file: floor.stl, material: glass}\n"
      "  - {type: cylinder, name: silo, axis_point: [0, 0, 0], axis: [0, 0, 1], radius: 0.004, "
      "side: inside, material: glass}\n"
      "  - {type: plane, name: lid, point: [0, 0, 0.03], normal: [0, 0, -1], material: glass}\n",
      "{normal: hertz, tangential: history, rolling: cdt}", true);
}

TEST(WallLoads, SlidingSphereDragsTheFloorByFriction) {
  const double r = 1e-3, rho = 2500, y = 1e7, nu = 0.3, mu = 0.3, g = 9.81, v0 = 0.5;
  Scene scene = parse_scene(
      "domain: {min: [-0.05, -0.01, 0], max: [0.05, 0.01, 0.01]}\n"
      "gravity: [0, 0, -9.81]\n"
      "time: {step: 2e-6, end: 1}\n"
      "materials:\n"
      "  - {name: glass, youngs_modulus: 1e7, poisson_ratio: 0.3, density: 2500}\n"
      "interactions:\n"
      "  - {materials: [glass, glass], restitution: 0.5, friction: 0.3}\n"
      "contact: {normal: hertz, tangential: history}\n"
      "walls:\n"
      "  - {type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass}\n"
      "output: {wall_loads: true}\n",
      "sliding.yaml");
  Simulation sim(scene, false);
  const double m = rho * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  // At rest on the floor: the Hertz overlap that carries m g, K d^{3/2} = m g with
  // K = (4/3) Y* sqrt(r), Y* = Y / (2 (1 - nu^2)) (wall of the same material).
  const double k = 4.0 / 3.0 * y / (2 * (1 - nu * nu)) * std::sqrt(r);
  const double overlap = std::pow(m * g / k, 2.0 / 3.0);
  sim.particles().add(1, Vec3(-0.03, 0, r - overlap), Vec3(v0, 0, 0), Vec3::Zero(), r, 0, rho);
  sim.initialise();
  const double t_roll = 2 * v0 / (7 * mu * g);
  sim.advance_to(0.6 * t_roll);
  const Simulation::WallLoads loads = sim.take_wall_loads();
  ASSERT_EQ(loads.force.size(), 1u);
  const Vec3 f = loads.force[0];
  if (rank() == 0)
    std::printf("sliding sphere: floor load (%.6g %.6g %.6g) m g over %.4g s, mu = %g\n",
                f[0] / (m * g), f[1] / (m * g), f[2] / (m * g), loads.interval, mu);
  EXPECT_NEAR(f[0] / (mu * m * g), 1.0, 0.01);
  EXPECT_NEAR(f[1] / (m * g), 0.0, 1e-9);
  EXPECT_NEAR(f[2] / (m * g), -1.0, 0.01);
}

std::vector<std::vector<std::string>> csv(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> row;
    std::stringstream s(line);
    for (std::string cell; std::getline(s, cell, ',');) row.push_back(cell);
    rows.push_back(row);
  }
  return rows;
}

// periodic_bed.yaml at ten times Earth's gravity with a log row every 3 ms and a checkpoint
// at 20 ms, between the rows of 18 and 21 ms, on 2 ranks cut along x.
Scene restart_scene() {
  Scene scene = load_scene(std::string(GRAINFLOW_TEST_DATA_DIR) + "/scenes/periodic_bed.yaml");
  scene.gravity = Vec3(0, 0, -98.1);
  scene.time.end = 0.03;
  scene.output.log_interval = 0.003;
  scene.output.snapshot_interval = 0.03;
  scene.output.checkpoint_interval = 0.02;
  scene.output.checkpoint_keep = 1;
  scene.output.wall_loads = true;
  // Cut across the floor (x), so that both ranks hold some of its contacts and the row across
  // the checkpoint adds the ranks' parts (cut along z, the lower rank held them all).
  scene.parallel.grid = {2, 1, 1};
  return scene;
}

RunOptions quiet(const fs::path& dir) {
  RunOptions options;
  options.progress = false;
  options.handle_stop_signals = false;
  options.output_directory = dir.string();
  return options;
}

TEST(WallLoads, RestartBetweenLogRowsReportsTheUninterruptedLoads) {
  const Scene scene = restart_scene();
  const fs::path whole = kWork / "whole", restarted = kWork / "restarted";
  if (rank() == 0) {
    fs::remove_all(whole);
    fs::remove_all(restarted);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  std::ostringstream out;
  (void)run_scene(scene, quiet(whole), MPI_COMM_WORLD, out);
  std::string checkpoint;
  for (const auto& e : fs::directory_iterator(whole))
    if (e.path().filename().string().rfind("checkpoint_", 0) == 0)
      checkpoint = (restarted / e.path().filename()).string();
  ASSERT_FALSE(checkpoint.empty());
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank() == 0) fs::copy(whole, restarted, fs::copy_options::recursive);
  MPI_Barrier(MPI_COMM_WORLD);
  RunOptions options = quiet(restarted);
  options.restart = checkpoint;
  (void)run_scene(scene, options, MPI_COMM_WORLD, out);
  if (rank() != 0) return;

  const auto a = csv(whole / "log.csv"), b = csv(restarted / "log.csv");
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GE(a.size(), 11u);
  const std::vector<std::string>& header = a[0];
  ASSERT_EQ(header.size(), 14u);
  EXPECT_EQ(header[10], "floor_load_x_N");
  EXPECT_EQ(header[12], "floor_load_z_N");
  EXPECT_EQ(header[13], "wall_load_interval_s");
  // Beads of radius 0.4-0.6 mm, glass, 300 of them: their weight at 98.1 m/s^2 bounds the
  // load scale for the round-off tolerance.
  const double weight = 300 * 2500 * 4.0 / 3.0 * std::numbers::pi * 6e-4 * 6e-4 * 6e-4 * 98.1;
  int across = 0;  // rows whose interval contains the checkpoint (t = 0.02 s)
  for (std::size_t i = 1; i < a.size(); ++i) {
    const double t = std::stod(a[i][0]), span = std::stod(a[i][13]);
    if (t - span < 0.02 && t > 0.02) ++across;
    EXPECT_EQ(a[i][0], b[i][0]) << "row " << i;
    // Bit for bit (the 17 digits written): the checkpoint folds the ranks' sums into rank 0
    // in the run that writes it, as the restart holds them.
    for (int c = 10; c < 14; ++c) {
      EXPECT_EQ(a[i][c], b[i][c]) << "row " << i << ", column " << header[c];
      EXPECT_NEAR(std::stod(a[i][c]), std::stod(b[i][c]), 1e-12 * weight);
    }
  }
  EXPECT_EQ(across, 1);
  // The bed has landed by the last rows: the floor carries it (within its bouncing).
  EXPECT_LT(std::stod(a.back()[12]),
            -0.5 * 300 * 2500 * 4.0 / 3.0 * std::numbers::pi * 4e-4 * 4e-4 * 4e-4 * 98.1);
}

// Replaces the root attribute 'wall_impulse' of `path` with `values`.
void rewrite_wall_impulse(const std::string& path, const std::vector<double>& values) {
  const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  if (H5Aexists(f, "wall_impulse") > 0) H5Adelete(f, "wall_impulse");
  const hsize_t n = values.size();
  const hid_t space = H5Screate_simple(1, &n, nullptr);
  const hid_t a = H5Acreate2(f, "wall_impulse", H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(a, H5T_NATIVE_DOUBLE, values.data());
  H5Aclose(a);
  H5Sclose(space);
  H5Fclose(f);
}

TEST(WallLoads, DamagedWallImpulseIsRefused) {
  const Scene scene = restart_scene();
  const fs::path dir = kWork / "damaged";
  if (rank() == 0) fs::remove_all(dir);
  MPI_Barrier(MPI_COMM_WORLD);
  Scene shorter = scene;
  shorter.time.end = 0.021;
  std::ostringstream out;
  (void)run_scene(shorter, quiet(dir), MPI_COMM_WORLD, out);
  std::string checkpoint;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind("checkpoint_", 0) == 0) checkpoint = e.path().string();
  ASSERT_FALSE(checkpoint.empty());
  const struct {
    std::vector<double> values;
    const char* expect;
  } cases[] = {{{1, 2, 3}, "the scene's 1 walls need 4"},
               {{0, std::nan(""), 0, 1e-3}, "non-finite"},
               {{0, 0, 0, -1}, "negative time span"}};
  for (const auto& c : cases) {
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank() == 0) rewrite_wall_impulse(checkpoint, c.values);
    MPI_Barrier(MPI_COMM_WORLD);
    RunOptions options = quiet(dir);
    options.restart = checkpoint;
    try {
      (void)run_scene(scene, options, MPI_COMM_WORLD, out);
      ADD_FAILURE() << "a checkpoint with wall_impulse of " << c.values.size()
                    << " values was taken";
    } catch (const std::exception& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("attribute 'wall_impulse'"), std::string::npos) << what;
      EXPECT_NE(what.find(c.expect), std::string::npos) << what;
      EXPECT_NE(what.find(checkpoint), std::string::npos) << what;
    }
  }
}

}  // namespace
}  // namespace grainflow
