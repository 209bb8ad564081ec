// The checkpoint keeps the processor grid (group /decomposition, dem/io/checkpoint.hpp;
// docs/parallel.md, "The default grid"), on 2 ranks.
//
// The scene: 1500 spheres (r = 0.5 mm) stirred at 0.5 m/s in the lowest 12 mm of a walled
// 20 x 20 x 80 mm box under 10 g, frictional (springs in the checkpoint). The default grid
// cuts across the bed at the particles' median, a plane that moves as the particles do.
//
// 1. Restart on as many ranks: the stored grid and planes are the ones the restart uses
//    (compared to the writer's planes exactly), and the restart continues bit for bit.
//    Reference: the uninterrupted run, tolerance 0 (a dense frictional bed is chaotic, so no
//    small non-zero tolerance would mean anything; see restart_run_mpi_test). The planes a
//    fresh choice would take from the checkpoint's particles (their median, computed directly
//    here) differ from the stored ones. Control: the same restart on another 2-rank grid (the
//    domain's least-cut-area grid, 1 x 1 x 2 with uniform planes) differs from the uninterrupted
//    run, so the grid does change the bits and keeping it is what makes the restart exact.
// 2. A checkpoint without the group (as written before it existed) restarts with a grid chosen
//    afresh for its particles: the plane lies midway between the 750th and 751st particle along
//    the cut axis (sorted directly here) and each rank holds 750.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

#include "dem/io/checkpoint.hpp"
#include "tests/dem/parallel/support.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

const std::string kDir = std::string(GRAINFLOW_BINARY_DIR) + "/test_output/grid_checkpoint_mpi";
constexpr double kDt = 4e-6;  // Hertz contact time at 0.5 m/s: 1.2e-4 s, 30 steps
constexpr int kHalf = 1000;   // steps before and after the checkpoint
constexpr long kCount = 1500;  // spheres: 16 % of the bed's region

Scene stirred_bed() {
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.6, 0.4);
  s.domain.lo = Vec3(0, 0, 0);
  s.domain.hi = Vec3(0.02, 0.02, 0.08);
  s.gravity = Vec3(0, 0, -98.1);
  s.contact.tangential = TangentialModel::history;
  s.walls.push_back(test::plane(Vec3::Zero(), Vec3::UnitZ()));
  for (int a = 0; a < 2; ++a) {
    s.walls.push_back(test::plane(Vec3::Zero(), Vec3::Unit(a)));
    s.walls.push_back(test::plane(s.domain.hi, -Vec3::Unit(a)));
  }
  for (std::size_t k = 0; k < s.walls.size(); ++k) s.walls[k].name = std::string(1, "abcde"[k]);
  Insertion fill;
  fill.kind = Insertion::Kind::fill;
  fill.region.lo = Vec3(0, 0, 0);
  fill.region.hi = Vec3(0.02, 0.02, 0.012);
  fill.count = kCount;
  fill.radius.value = 0.5e-3;
  fill.seed = 5;
  fill.source = "test";
  s.insertions.push_back(fill);
  return s;
}

void stir(Simulation& sim) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (auto& v : sim.particles().v) v = 0.5 / std::sqrt(3.0) * Vec3(u(rng), u(rng), u(rng));
}

int world_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

// The one axis the 2-rank grid cuts.
int cut_axis(const std::array<int, 3>& dims) {
  return static_cast<int>(std::find(dims.begin(), dims.end(), 2) - dims.begin());
}

// The particles' median along `axis`: midway between the two middle coordinates.
double median_plane(const Particles& p, int axis) {
  std::vector<double> x;
  for (const Vec3& c : p.x) x.push_back(c[axis]);
  std::sort(x.begin(), x.end());
  const std::size_t m = x.size() / 2;
  return 0.5 * (x[m - 1] + x[m]);
}

struct Written {
  std::string path;
  std::array<int, 3> dims{};
  std::array<std::vector<double>, 3> cuts;
  std::vector<test::State> end;  // of the uninterrupted run (rank 0)
};

const Written& uninterrupted() {
  static Written w = [] {
    Written r;
    r.path = kDir + "/bed.h5";
    if (world_rank() == 0) std::filesystem::create_directories(kDir);
    MPI_Barrier(MPI_COMM_WORLD);
    Simulation sim(stirred_bed());
    stir(sim);
    sim.set_dt(kDt);
    sim.initialise();
    EXPECT_EQ(sim.grid_choice(), Simulation::GridChoice::particles);
    for (int k = 0; k < kHalf; ++k) sim.step();
    r.dims = sim.decomposition().dims();
    for (int a = 0; a < 3; ++a) r.cuts[a] = sim.decomposition().cuts(a);
    sim.write_checkpoint(r.path);
    for (int k = 0; k < kHalf; ++k) sim.step();
    EXPECT_EQ(sim.global_state().particles, kCount);
    EXPECT_GT(sim.global_state().contacts, 100) << "too few contacts: the test shows little";
    r.end = test::gather_states(sim.particles(), MPI_COMM_WORLD);
    return r;
  }();
  return w;
}

std::vector<test::State> finish(Simulation& sim) {
  sim.initialise();
  for (int k = 0; k < kHalf; ++k) sim.step();
  EXPECT_EQ(sim.counters().steps, 2 * kHalf);
  return test::gather_states(sim.particles(), MPI_COMM_WORLD);
}

TEST(GridCheckpoint, RestartOnAsManyRanksUsesTheStoredPlanesBitForBit) {
  const Written& w = uninterrupted();
  const int axis = cut_axis(w.dims);
  ASSERT_LT(axis, 3) << "the default grid of the bed is not 2 x 1 x 1 or 1 x 2 x 1";
  // Particle-aware: not the uniform plane of the domain (10 mm).
  EXPECT_NE(w.cuts[axis][1], 0.01);

  const CheckpointData c = read_checkpoint(w.path);
  EXPECT_GT(c.springs.size(), 100u) << "no springs in the checkpoint: the test shows little";
  ASSERT_TRUE(c.grid.has_value());
  EXPECT_EQ(c.grid->ranks, 2);
  EXPECT_EQ(c.grid->dims, w.dims);
  for (int a = 0; a < 3; ++a) EXPECT_EQ(c.grid->cuts[a], w.cuts[a]) << "axis " << a;

  Simulation restarted(stirred_bed(), false);
  restarted.set_dt(kDt);
  restarted.restore(c);
  const std::vector<test::State> end = finish(restarted);
  EXPECT_EQ(restarted.grid_choice(), Simulation::GridChoice::checkpoint);
  EXPECT_EQ(restarted.decomposition().dims(), w.dims);
  for (int a = 0; a < 3; ++a) EXPECT_EQ(restarted.decomposition().cuts(a), w.cuts[a]);

  // The planes a fresh choice would take now (the checkpoint's median) are other planes.
  const double fresh = median_plane(c.particles, axis);
  EXPECT_NE(fresh, w.cuts[axis][1]);
  // Control: another grid.
  Simulation control(stirred_bed(), false, MPI_COMM_WORLD, {1, 1, 2});
  control.set_dt(kDt);
  control.restore(c);
  const std::vector<test::State> moved = finish(control);

  if (world_rank() != 0) return;
  ASSERT_EQ(end.size(), w.end.size());
  ASSERT_EQ(moved.size(), w.end.size());
  const double same = test::largest_difference(w.end, end, 0.02, 0.5, 0.5e-3);
  const double other = test::largest_difference(w.end, moved, 0.02, 0.5, 0.5e-3);
  std::printf("stored plane %.17g, median at the checkpoint %.17g; restart on the stored "
              "grid: %.3g, on 1 x 1 x 2: %.3g (relative to 20 mm, 0.5 m/s)\n",
              w.cuts[axis][1], fresh, same, other);
  EXPECT_EQ(same, 0.0);
  EXPECT_GT(other, 0.0);
}

TEST(GridCheckpoint, ACheckpointWithoutTheGridIsCutAfresh) {
  const Written& w = uninterrupted();
  const std::string old = kDir + "/bed_without_grid.h5";
  if (world_rank() == 0) {
    std::filesystem::copy_file(w.path, old, std::filesystem::copy_options::overwrite_existing);
    const hid_t f = H5Fopen(old.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    EXPECT_GE(H5Ldelete(f, "/decomposition", H5P_DEFAULT), 0);
    H5Fclose(f);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  const CheckpointData c = read_checkpoint(old);
  ASSERT_FALSE(c.grid.has_value());
  Simulation restarted(stirred_bed(), false);
  restarted.set_dt(kDt);
  restarted.restore(c);
  restarted.initialise();
  EXPECT_EQ(restarted.grid_choice(), Simulation::GridChoice::particles);
  const int axis = cut_axis(restarted.decomposition().dims());
  ASSERT_LT(axis, 3);
  EXPECT_EQ(restarted.decomposition().cuts(axis)[1], median_plane(c.particles, axis));
  long counts[2] = {0, 0};
  const long mine = static_cast<long>(restarted.particles().size());
  MPI_Allgather(&mine, 1, MPI_LONG, counts, 1, MPI_LONG, MPI_COMM_WORLD);
  EXPECT_EQ(counts[0], kCount / 2);
  EXPECT_EQ(counts[1], kCount / 2);
  for (int k = 0; k < 100; ++k) restarted.step();
  EXPECT_EQ(restarted.global_state().particles, kCount);
}

// 3. The grid given (1 x 1 x 2, uniform planes at 40 mm) with parallel.balance: the bed in the
//    lowest 12 mm is all on one rank, and the balancing moves the plane down by at most half
//    a box per check (every 10th rebuild), so it is still moving when the checkpoint is
//    written. The restart takes the scene's grid with the checkpoint's planes, and the
//    rebuild count that paces the balancing, and continues bit for bit (found by the restart
//    check of the hard-scene generator: such a restart started from the uniform planes and
//    its own count, and diverged).
TEST(GridCheckpoint, BalancedGivenGridRestartsBitForBit) {
  Scene s = stirred_bed();
  s.parallel.balance = true;
  const std::string path = kDir + "/balanced.h5";
  if (world_rank() == 0) std::filesystem::create_directories(kDir);
  MPI_Barrier(MPI_COMM_WORLD);
  Simulation sim(s, true, MPI_COMM_WORLD, {1, 1, 2});
  stir(sim);
  sim.set_dt(kDt);
  sim.initialise();
  for (int k = 0; k < kHalf; ++k) sim.step();
  const std::vector<double> planes = sim.decomposition().cuts(2);
  const long rebuilds = sim.counters().rebuilds;
  sim.write_checkpoint(path);
  for (int k = 0; k < kHalf; ++k) sim.step();
  const std::vector<double> final_planes = sim.decomposition().cuts(2);
  const std::vector<test::State> whole = test::gather_states(sim.particles(), MPI_COMM_WORLD);

  const CheckpointData c = read_checkpoint(path);
  EXPECT_EQ(c.rebuilds, rebuilds);
  Simulation restarted(s, false, MPI_COMM_WORLD, {1, 1, 2});
  restarted.set_dt(kDt);
  restarted.restore(c);
  const std::vector<test::State> end = finish(restarted);
  EXPECT_EQ(restarted.grid_choice(), Simulation::GridChoice::given_checkpoint);
  EXPECT_EQ(restarted.counters().rebuilds, sim.counters().rebuilds);
  EXPECT_EQ(restarted.decomposition().cuts(2), final_planes);
  if (world_rank() != 0) return;
  std::printf(
      "[ measured ] plane at the checkpoint %.6g m (40 mm at the start), at the end "
      "%.6g m; %ld rebuilds before the checkpoint, %ld in all\n",
      planes[1], final_planes[1], rebuilds, sim.counters().rebuilds);
  EXPECT_LT(planes[1], 0.04);             // the balancing has moved it
  EXPECT_NE(final_planes[1], planes[1]);  // and moves it after the checkpoint
  ASSERT_EQ(end.size(), whole.size());
  EXPECT_EQ(test::largest_difference(whole, end, 0.02, 0.5, 0.5e-3), 0.0);
}

}  // namespace
}  // namespace grainflow
