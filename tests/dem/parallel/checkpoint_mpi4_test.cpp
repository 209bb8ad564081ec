// A checkpoint written on 2 ranks continues on 1, 2 and 4 ranks.
//
// Reference: the uninterrupted 2-rank run. The dense frictional gas runs 400 steps,
// writes a checkpoint and runs 400 more. Restarts from the checkpoint on 1, 2 and 4
// ranks run the same 400 steps. Every particle and every contact spring comes back,
// so the restarts follow the uninterrupted run up to round-off: the restart rebuilds
// its neighbour lists at the checkpoint (the uninterrupted run did not), which
// changes the order of force sums (~1e-16); 400 steps of dense contacts amplify that
// far less than the 1e-10 tolerance (relative to box size and 0.5 m/s). A spring
// lost at the restart would show as ~1e-3.
#include <gtest/gtest.h>

#include <filesystem>

#include "tests/dem/parallel/gas_scene.hpp"
#include "tests/dem/parallel/support.hpp"

namespace grainflow {
namespace {

const std::string kPath = std::string(GRAINFLOW_BINARY_DIR) + "/test_output/checkpoint_mpi4/gas.h5";

std::vector<test::State> uninterrupted() {
  MPI_Comm comm = test::first_ranks(2);
  if (comm == MPI_COMM_NULL) return {};
  Simulation sim(test::gas_scene(), true, comm);
  test::stir(sim);
  sim.set_dt(2e-6);
  sim.initialise();
  for (int k = 0; k < 400; ++k) sim.step();
  sim.write_checkpoint(kPath);
  for (int k = 0; k < 400; ++k) sim.step();
  EXPECT_NEAR(sim.time(), 800 * 2e-6, 1e-15);
  auto s = test::gather_states(sim.particles(), comm);
  MPI_Comm_free(&comm);
  return s;
}

std::vector<test::State> restarted(int ranks) {
  MPI_Comm comm = test::first_ranks(ranks);
  if (comm == MPI_COMM_NULL) return {};
  Simulation sim(test::gas_scene(), false, comm);
  const CheckpointData c = read_checkpoint(kPath);
  EXPECT_EQ(c.particles.size(), 2000u);
  EXPECT_GT(c.springs.size(), 100u) << "the checkpoint holds no springs; nothing is tested";
  EXPECT_EQ(c.step, 400);
  sim.restore(c);
  sim.initialise();
  for (int k = 0; k < 400; ++k) sim.step();
  EXPECT_NEAR(sim.time(), 800 * 2e-6, 1e-15);
  EXPECT_EQ(sim.counters().steps, 800);
  auto s = test::gather_states(sim.particles(), comm);
  MPI_Comm_free(&comm);
  return s;
}

TEST(Checkpoint, ContinuesOnOtherRankCounts) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0) std::filesystem::create_directories(std::filesystem::path(kPath).parent_path());
  MPI_Barrier(MPI_COMM_WORLD);
  const auto reference = uninterrupted();
  MPI_Barrier(MPI_COMM_WORLD);
  const auto four = restarted(4);
  const auto two = restarted(2);
  const auto one = restarted(1);
  if (rank != 0) return;
  ASSERT_EQ(reference.size(), 2000u);
  for (const auto* run : {&four, &two, &one}) {
    ASSERT_EQ(run->size(), reference.size());
    const double d = test::largest_difference(reference, *run, 0.03, 0.5, 0.6e-3);
    std::printf("restart on %d ranks vs uninterrupted on 2: %.3e\n",
                run == &four ? 4 : run == &two ? 2 : 1, d);
    EXPECT_LT(d, 1e-10);
  }
  // On the same rank count the restart is bit-identical: writing the checkpoint
  // rebuilt the lists exactly as the restart does.
  EXPECT_EQ(test::largest_difference(reference, two, 0.03, 0.5, 0.6e-3), 0.0);
}

TEST(Checkpoint, BrokenFileIsAClearError) {
  const std::string bad = std::string(GRAINFLOW_BINARY_DIR) + "/test_output/checkpoint_mpi4/not_h5.txt";
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0) {
    std::filesystem::create_directories(std::filesystem::path(bad).parent_path());
    std::FILE* f = std::fopen(bad.c_str(), "w");
    std::fputs("not a checkpoint\n", f);
    std::fclose(f);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  try {
    read_checkpoint(bad);
    FAIL() << "expected OutputError";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace grainflow
