// Hard crossings on 4 ranks, each checked against the same scene on 1 rank
// (reference: the 1-rank run; tolerance 1e-12 relative — these few-particle runs
// differ only in the order of summing at most a few contact forces).
// - a touching pair sliding on a floor across the corner shared by four ranks keeps
//   its pair spring and its wall springs;
// - a pair crossing a periodic side that is also a rank boundary keeps its spring;
// - ranks that own no particle at all take part without stalling;
// - a particle that jumps over a whole subdomain between two rebuilds stops the run
//   with an error naming the particle, its speed and the fix — never a silent loss.
#include <gtest/gtest.h>

#include "tests/dem/parallel/support.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

Scene floor_scene(bool periodic_x) {
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.6, 0.4, 0.05);
  s.domain.lo = Vec3(0, 0, 0);
  s.domain.hi = Vec3(0.04, 0.04, 0.02);
  s.domain.periodic = {periodic_x, false, false};
  s.contact.tangential = TangentialModel::history;
  s.contact.rolling = RollingModel::epsd;
  s.gravity = Vec3(0, 0, -9.81);
  s.walls.push_back(test::plane(Vec3::Zero(), Vec3::UnitZ()));
  return s;
}

// A touching pair resting on the floor (in gravity equilibrium) moving along `dir`.
void add_sliding_pair(Simulation& sim, const Vec3& start, const Vec3& dir) {
  const double r = 1e-3, z = r - 1.2e-6;
  const Vec3 side = Vec3::UnitZ().cross(dir).normalized() * (r - 1e-6);
  sim.particles().add(1, start + side + Vec3(0, 0, z), 0.3 * dir, Vec3::Zero(), r, 0, 2500);
  sim.particles().add(2, start - side + Vec3(0, 0, z), 0.3 * dir + Vec3(0.01, -0.01, 0),
                      Vec3::Zero(), r, 0, 2500);
}

std::vector<test::State> run(int ranks, std::array<int, 3> grid, bool periodic_x,
                             const Vec3& start, const Vec3& dir, long steps) {
  MPI_Comm comm = test::first_ranks(ranks);
  if (comm == MPI_COMM_NULL) return {};
  Simulation sim(floor_scene(periodic_x), false, comm, grid);
  add_sliding_pair(sim, start, dir.normalized());
  sim.set_dt(1e-6);
  sim.initialise();
  for (long k = 0; k < steps; ++k) sim.step();
  EXPECT_GT(sim.counters().rebuilds, 3);
  auto states = test::gather_states(sim.particles(), comm);
  MPI_Comm_free(&comm);
  return states;
}

int world_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

TEST(Crossings, PairAcrossTheCornerOfFourRanks) {
  // From (18.5, 18.5) mm to about (21.4, 21.4) mm: through the corner (20, 20) of a
  // 2 x 2 grid (the pair slides, then rolls at 5/7 of its speed).
  const Vec3 start(0.0185, 0.0185, 0), dir(1, 1, 0);
  const auto four = run(4, {2, 2, 1}, false, start, dir, 20000);
  const auto one = run(1, {1, 1, 1}, false, start, dir, 20000);
  if (world_rank() != 0) return;
  ASSERT_EQ(four.size(), 2u);
  ASSERT_EQ(one.size(), 2u);
  for (const auto& s : one) {
    EXPECT_GT(s.x[0], 0.0202) << "the pair must have crossed x = 20 mm";
    EXPECT_GT(s.x[1], 0.0202) << "the pair must have crossed y = 20 mm";
  }
  const double d = test::largest_difference(one, four, 0.04, 0.3, 1e-3);
  std::printf("corner crossing, 4 ranks vs 1: %.3e\n", d);
  EXPECT_LT(d, 1e-12);
}

TEST(Crossings, PairAcrossAPeriodicSideThatIsARankBoundary) {
  // Two ranks along periodic x; the pair crosses x = 40 mm -> 0.
  const Vec3 start(0.0385, 0.02, 0), dir(1, 0.2, 0);
  const auto two = run(2, {2, 1, 1}, true, start, dir, 20000);
  const auto one = run(1, {1, 1, 1}, true, start, dir, 20000);
  if (world_rank() != 0) return;
  ASSERT_EQ(two.size(), 2u);
  ASSERT_EQ(one.size(), 2u);
  for (const auto& s : one) EXPECT_LT(s.x[0], 0.01) << "the pair must have wrapped to x ~ 0";
  const double d = test::largest_difference(one, two, 0.04, 0.3, 1e-3);
  std::printf("periodic rank boundary, 2 ranks vs 1: %.3e\n", d);
  EXPECT_LT(d, 1e-12);
}

TEST(Crossings, EmptyRanksDoNotStall) {
  // Everything sits in one quarter of a 2 x 2 grid: three ranks own nothing.
  Simulation sim(floor_scene(false), false, MPI_COMM_WORLD, {2, 2, 1});
  GlobalId id = 1;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      sim.particles().add(id++, Vec3(0.003 + 0.0025 * i, 0.003 + 0.0025 * j, 0.002), Vec3::Zero(),
                          Vec3::Zero(), 1e-3, 0, 2500);
  sim.set_dt(1e-5);
  sim.initialise();
  long owned = static_cast<long>(sim.particles().size()), with_particles = owned > 0;
  MPI_Allreduce(MPI_IN_PLACE, &with_particles, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(with_particles, 1);
  sim.advance_to(0.02);
  EXPECT_EQ(sim.global_state().particles, 25);
  EXPECT_EQ(sim.global_state().removed, 0);
}

TEST(Crossings, JumpOverASubdomainIsAClearError) {
  // Four ranks along x, 10 mm each; a particle at 30 m/s with dt = 1 ms moves 30 mm
  // in one step: it would skip a whole subdomain. The travel guard (30 radii per step,
  // limit 1) would stop it before it moves; off here, to test the migration's own error.
  Scene s = floor_scene(false);
  s.time.max_step_travel = 0;
  s.gravity = Vec3::Zero();
  s.domain.hi = Vec3(0.04, 0.01, 0.01);
  Simulation sim(s, false, MPI_COMM_WORLD, {4, 1, 1});
  sim.particles().add(7, Vec3(0.004, 0.005, 0.005), Vec3(30, 0, 0), Vec3::Zero(), 1e-3, 0, 2500);
  sim.set_dt(1e-3);
  sim.initialise();
  try {
    sim.step();
    FAIL() << "expected ParallelError";
  } catch (const ParallelError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("particle 7"), std::string::npos) << m;
    EXPECT_NE(m.find("30 m/s"), std::string::npos) << m;
    EXPECT_NE(m.find("reduce the time step"), std::string::npos) << m;
  }
}

}  // namespace
}  // namespace grainflow
