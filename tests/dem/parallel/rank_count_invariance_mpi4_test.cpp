// The same scene on 1, 2 and 4 ranks gives the same particles and trajectories.
//
// Scene: a dense, frictional granular gas (2000 spheres at 34 % solids, random
// velocities of 0.5 m/s, Hertz + tangential history + EPSD rolling) in a box that is
// periodic along x and bounded by walls along y and z, for 2000 steps. With 2 and 4
// ranks the x cut is also the periodic side, so pairs cross rank boundaries, periodic
// sides and corners of four ranks.
//
// Reference: the 1-rank run. Pair forces are computed bit-identically on every rank
// (canonical orientation, exact image shifts); what differs between rank counts is
// only the order in which each particle's contact forces are summed, which changes
// the last bit of a sum (~1e-16 relative). Dense contact dynamics amplify such
// differences; the tolerance 1e-9 (relative to box size, 0.5 m/s, and 0.5 m/s / r)
// bounds that growth over 2000 steps.
#include <gtest/gtest.h>

#include "dem/insert/insertion.hpp"
#include "tests/dem/parallel/gas_scene.hpp"
#include "tests/dem/parallel/support.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

std::vector<test::State> run_on(int ranks, std::array<int, 3> grid,
                                const std::vector<double>& x_cuts = {}) {
  MPI_Comm comm = test::first_ranks(ranks);
  if (comm == MPI_COMM_NULL) return {};
  Simulation sim(test::gas_scene(), true, comm, grid);
  if (!x_cuts.empty()) sim.set_cut_planes(0, x_cuts);
  test::stir(sim);
  sim.set_dt(2e-6);
  sim.initialise();
  for (int k = 0; k < 2000; ++k) sim.step();
  EXPECT_GT(sim.global_state().contacts, 150) << "not a dense flow";
  EXPECT_GT(sim.counters().rebuilds, 5);
  auto states = test::gather_states(sim.particles(), comm);
  MPI_Comm_free(&comm);
  return states;
}

TEST(RankCountInvariance, OneTwoFourRanksAgree) {
  int world = 0, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &world);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  ASSERT_EQ(world, 4) << "run under mpirun -np 4";
  const auto four = run_on(4, {2, 2, 1});
  const auto two = run_on(2, {2, 1, 1});
  const auto one = run_on(1, {1, 1, 1});
  const auto uneven = run_on(2, {2, 1, 1}, {0.0, 0.009, 0.03});  // non-uniform cut plane
  if (rank != 0) return;
  ASSERT_EQ(one.size(), 2000u);
  ASSERT_EQ(two.size(), one.size());
  ASSERT_EQ(four.size(), one.size());
  ASSERT_EQ(uneven.size(), one.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    ASSERT_EQ(two[i].id, one[i].id);
    ASSERT_EQ(four[i].id, one[i].id);
  }
  const double d2 = test::largest_difference(one, two, 0.03, 0.5, 0.6e-3);
  const double d4 = test::largest_difference(one, four, 0.03, 0.5, 0.6e-3);
  const double du = test::largest_difference(one, uneven, 0.03, 0.5, 0.6e-3);
  std::printf("largest relative difference to 1 rank: 2 ranks %.3e, 4 ranks %.3e, "
              "2 ranks cut at 30 %% %.3e\n", d2, d4, du);
  EXPECT_LT(d2, 1e-9);
  EXPECT_LT(du, 1e-9);
  EXPECT_LT(d4, 1e-9);
}

}  // namespace
}  // namespace grainflow
