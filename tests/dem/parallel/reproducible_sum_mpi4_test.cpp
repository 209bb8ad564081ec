// parallel: {reproducible: true} on 4 ranks and two-dimensional processor grids: the dense
// frictional gas of gas_scene.hpp (2000 spheres, Hertz + tangential history + EPSD
// rolling resistance, periodic x, walls along y and z) on 1 rank, on 2 x 2 x 1 ranks
// (pairs across corners of four ranks and across the periodic side) and on 1 x 2 x 2 ranks
// with load balancing, 4000 steps.
//
// Reference: exact equality with the 1-rank run (tolerance 0), for the reason given in
// reproducible_sum_mpi3_test.cpp: with canonical summation every particle's floating-point
// operations are the same whatever the decomposition. Without the mode the same runs
// differ by up to 1e-12 after 2000 steps (rank_count_invariance_mpi4_test) and more later.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>

#include "tests/dem/parallel/gas_scene.hpp"
#include "tests/dem/parallel/support.hpp"

namespace grainflow {
namespace {

// Ranks without work wait here without spinning (the test runs oversubscribed).
void wait_for_all() {
  MPI_Request r;
  MPI_Ibarrier(MPI_COMM_WORLD, &r);
  for (int done = 0; MPI_Test(&r, &done, MPI_STATUS_IGNORE), !done;) usleep(2000);
}

std::vector<test::State> run_on(int ranks, std::array<int, 3> grid, bool balance) {
  MPI_Comm comm = test::first_ranks(ranks);
  if (comm == MPI_COMM_NULL) {
    wait_for_all();
    return {};
  }
  Scene scene = test::gas_scene();
  scene.parallel.reproducible = true;
  scene.parallel.balance = balance;
  Simulation sim(scene, true, comm, grid);
  test::stir(sim);
  sim.set_dt(2e-6);
  sim.initialise();
  for (int k = 0; k < 4000; ++k) sim.step();
  EXPECT_GT(sim.global_state().contacts, 150) << "not a dense flow";
  EXPECT_GT(sim.counters().rebuilds, 5);
  auto states = test::gather_states(sim.particles(), comm);
  MPI_Comm_free(&comm);
  wait_for_all();
  return states;
}

TEST(ReproducibleSum, BitIdenticalOnFourRanksInTwoDimensionalGrids) {
  int world = 0, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &world);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  ASSERT_EQ(world, 4) << "run under mpirun -np 4";
  const auto one = run_on(1, {1, 1, 1}, false);
  const auto xy = run_on(4, {2, 2, 1}, false);
  const auto yz = run_on(4, {1, 2, 2}, true);
  if (rank != 0) return;
  ASSERT_EQ(one.size(), 2000u);
  for (const auto* other : {&xy, &yz}) {
    ASSERT_EQ(other->size(), one.size());
    int differing = 0;
    for (std::size_t i = 0; i < one.size(); ++i) {
      const test::State &a = one[i], &b = (*other)[i];
      differing += a.id != b.id || std::memcmp(a.x, b.x, sizeof a.x) != 0 ||
                   std::memcmp(a.v, b.v, sizeof a.v) != 0 || std::memcmp(a.w, b.w, sizeof a.w) != 0;
    }
    EXPECT_EQ(differing, 0) << (other == &xy ? "2 x 2 x 1" : "1 x 2 x 2, balanced");
  }
}

}  // namespace
}  // namespace grainflow
