// Regression test for an engine bug found by the issue 8 stress suite
// (docs/stability.md, "Bug found"), fixed in commit f4c4572.
//
// Before the fix: with three or more ranks along a periodic axis, a particle that
// crossed the periodic side was sent the wrong way. Exchange::migrate wraps its position into the
// domain first (x = 80.01 mm -> 0.01 mm) and then picked the direction by comparing
// the wrapped position with its own box: on the last rank (box [60, 80) mm) 0.01 mm is
// "below lo", so the particle goes to the -x neighbour (the box [40, 60) mm) instead of
// the +x neighbour across the periodic side (the box [0, 20) mm). That rank cannot
// place it and the run stops with a false "crossed more than one subdomain" error,
// although the particle moved 0.02 mm since the last rebuild. With two ranks along
// the axis both neighbours are the same rank, which is why the existing two-rank
// periodic tests pass.
//
// Reference: the same single sphere on one rank (tolerance 1e-12 relative: one
// particle, no contacts — the runs should agree bit for bit).
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/dem/parallel/support.hpp"
#include "tests/dem/stress/stress_support.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

std::vector<test::State> run(int ranks, std::array<int, 3> grid, const Vec3& x, const Vec3& v,
                             std::string& error) {
  MPI_Comm comm = test::first_ranks(ranks);
  if (comm == MPI_COMM_NULL) return {};
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.8);
  s.domain.lo = Vec3::Zero();
  s.domain.hi = Vec3(0.08, 0.01, 0.01);
  s.domain.periodic = {true, false, false};
  Simulation sim(s, false, comm, grid);
  sim.particles().add(1, x, v, Vec3::Zero(), 0.5e-3, 0, 2500);
  sim.set_dt(1e-5);
  try {
    sim.initialise();
    for (int k = 0; k < 200; ++k) sim.step();  // 20 mm at 10 m/s
  } catch (const ParallelError& e) {
    error = e.what();
  }
  auto states = test::gather_states(sim.particles(), comm);
  MPI_Comm_free(&comm);
  return states;
}

TEST(PeriodicSideManyRanks, CrossingUpwardWithFourRanksAlongTheAxis) {
  std::string four_error, one_error;
  const Vec3 x(0.0795, 0.005, 0.005), v(10, 0, 0);
  const auto four = run(4, {4, 1, 1}, x, v, four_error);
  const auto one = run(1, {1, 1, 1}, x, v, one_error);
  ASSERT_TRUE(one_error.empty()) << one_error;
  EXPECT_TRUE(four_error.empty()) << "ENGINE BUG (exchange.cpp migrate, periodic side with >= 3 "
                                     "ranks along the axis): "
                                  << four_error;
  if (test::world_rank() != 0 || !four_error.empty()) return;
  ASSERT_EQ(four.size(), 1u);
  EXPECT_LT(test::largest_difference(one, four, 0.08, 10, 0.5e-3), 1e-12);
}

TEST(PeriodicSideManyRanks, CrossingDownwardWithFourRanksAlongTheAxis) {
  std::string four_error, one_error;
  const Vec3 x(0.0005, 0.005, 0.005), v(-10, 0, 0);
  const auto four = run(4, {4, 1, 1}, x, v, four_error);
  const auto one = run(1, {1, 1, 1}, x, v, one_error);
  ASSERT_TRUE(one_error.empty()) << one_error;
  EXPECT_TRUE(four_error.empty()) << "ENGINE BUG (exchange.cpp migrate, periodic side with >= 3 "
                                     "ranks along the axis): "
                                  << four_error;
  if (test::world_rank() != 0 || !four_error.empty()) return;
  ASSERT_EQ(four.size(), 1u);
  EXPECT_LT(test::largest_difference(one, four, 0.08, 10, 0.5e-3), 1e-12);
}

}  // namespace
}  // namespace grainflow
