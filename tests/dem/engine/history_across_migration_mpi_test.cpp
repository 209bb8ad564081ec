// Contact springs (tangential and EPSD rolling, pair and wall) survive migration between ranks
// as well as rebuilds and re-sorting: a frictional pile sliding on a floor across the cut
// between two ranks, with a skin so small that the lists are rebuilt (and particles migrate)
// at almost every step, must follow the 1-rank run that rarely rebuilds. The springs travel as
// flat records keyed by global ids (dem/neighbour/carried_springs.hpp); a spring dropped or
// given to the wrong pair would make its sticking contact jump by a fraction of its tangential
// force at once (a relative difference ~1e-3).
// Reference: skin and rank-count independence of the dynamics. Tolerance 1e-8 relative to the
// speed scale, as in history_across_rebuilds_test.cpp: re-sorting and the other rank count
// change the order of force summation (last bits), which the dense pile amplifies over the run.
#include <gtest/gtest.h>

#include <random>

#include "tests/dem/parallel/support.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

std::vector<test::State> run_pile(int ranks, double skin, long* rebuilds, double* crossed) {
  MPI_Comm comm = test::first_ranks(ranks);
  if (comm == MPI_COMM_NULL) return {};
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.4, 0.5, 0.05);
  s.domain.lo = Vec3(0, 0, 0);
  s.domain.hi = Vec3(0.04, 0.02, 0.02);
  s.gravity = Vec3(0, 0, -9.81);
  s.contact.tangential = TangentialModel::history;
  s.contact.rolling = RollingModel::epsd;
  s.neighbour.skin = skin;
  s.walls.push_back(test::plane(Vec3::Zero(), Vec3::UnitZ()));
  Simulation sim(s, false, comm, {ranks, 1, 1});
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  GlobalId id = 1;
  // 4 x 4 x 3 spheres from x = 14.5 mm to 22.7 mm, across the cut at x = 20 mm, moving +x.
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 3; ++k)
        sim.particles().add(id++,
                            Vec3(0.0155 + i * 2.05e-3, 0.006 + j * 2.05e-3, 1.01e-3 + k * 2.05e-3) +
                                2e-5 * Vec3(u(rng), u(rng), 0),
                            Vec3(0.2, 0, 0) + 0.05 * Vec3(u(rng), u(rng), 0), Vec3::Zero(), 1e-3, 0,
                            2500);
  sim.set_dt(5e-6);
  sim.initialise();
  for (int k = 0; k < 4000; ++k) sim.step();
  *rebuilds = sim.counters().rebuilds;
  double past = 0;  // spheres beyond the cut at the end
  for (const Vec3& x : sim.particles().x) past += x[0] > 0.02;
  MPI_Allreduce(MPI_IN_PLACE, &past, 1, MPI_DOUBLE, MPI_SUM, comm);
  *crossed = past;
  auto states = test::gather_states(sim.particles(), comm);
  MPI_Comm_free(&comm);
  return states;
}

TEST(ContactHistory, SurvivesMigrationBetweenRanks) {
  long few = 0, many = 0;
  double crossed_one = 0, crossed_two = 0;
  const auto one = run_pile(1, 0.5e-3, &few, &crossed_one);
  const auto two = run_pile(2, 1e-9, &many, &crossed_two);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank != 0) return;
  ASSERT_GT(many, 3000) << "the small-skin run must rebuild at most steps";
  ASSERT_LT(few, 100);
  EXPECT_GT(crossed_one, 30) << "most of the pile must have crossed the cut";
  EXPECT_EQ(crossed_one, crossed_two);
  ASSERT_EQ(one.size(), 48u);
  ASSERT_EQ(two.size(), 48u);
  const double d = test::largest_difference(one, two, 0.04, 0.2, 1e-3);
  std::printf("sliding pile, 2 ranks small skin vs 1 rank large skin: %.3e\n", d);
  EXPECT_LT(d, 1e-8);
}

}  // namespace
}  // namespace grainflow
