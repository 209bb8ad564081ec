// Fast particles crossing several ranks and periodic sides, and ranks that become
// empty (issue 8), on 4 ranks.
//
// A cloud of 200 spheres (r = 0.5 mm, 8 mm long) starts inside the x < 40 mm half of
// a 2 x 2 x 1 grid over an 80 mm x 10 mm channel periodic along x and y (walls in z),
// and drifts at (8, 1.5, 0) m/s with 0.3 m/s of random motion on top. Two ranks start
// empty; as the cloud moves on, ranks fill and empty again, and the cloud wraps
// through the periodic sides x = 80 mm -> 0 and y = 10 mm -> 0, which are also rank
// boundaries, crossing rank corners on the way.
//
// The same cloud also runs on a 4 x 1 x 1 grid: four ranks along the periodic axis,
// where migration across the periodic side once went the wrong way
// (periodic_side_many_ranks_mpi4_test.cpp, docs/stability.md).
//
// Invariants (every 100 steps):
// - no error, no NaN / Inf on any rank;
// - the global particle count stays 200, nothing removed;
// - total energy (kinetic + elastic Hertz from gathered positions, no gravity) never
//   exceeds its starting value by more than 1e-9 relative: collisions are dissipative
//   (e = 0.8, mu = 0.3); only the tangential springs, which the brute-force sum does
//   not see, could hand energy back, and far less than this (measured: E never rose).
// The cloud must have crossed more than one full lap of ranks (>= 4 boundaries) and
// at least one rank must have gone from holding particles to holding none.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "tests/dem/stress/stress_support.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

constexpr double kL = 0.08, kW = 0.01, kR = 0.5e-3, kRho = 2500;

Scene channel() {
  Scene s = test::one_material_scene(1e7, 0.3, kRho, 0.8, 0.3);
  s.domain.lo = Vec3::Zero();
  s.domain.hi = Vec3(kL, kW, kW);
  s.domain.periodic = {true, true, false};
  s.contact.tangential = TangentialModel::history;
  s.walls = {test::plane(Vec3::Zero(), Vec3::UnitZ()), test::plane(Vec3(0, 0, kW), -Vec3::UnitZ())};
  s.time.step.reset();
  s.time.rayleigh_fraction = 0.2;
  return s;
}

class FastCrossing : public testing::TestWithParam<std::array<int, 3>> {};

TEST_P(FastCrossing, CloudLapsRanksAndPeriodicSides) {
  const Scene s = channel();
  Simulation sim(s, false, MPI_COMM_WORLD, GetParam());
  // The same cloud on every rank; initialise() keeps each particle on its owner.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1), c(-1, 1);
  const Vec3 drift(8, 1.5, 0);
  GlobalId id = 1;
  while (id <= 200) {
    const Vec3 x(1e-3 + 8e-3 * u(rng), kW * u(rng), kR + (kW - 2 * kR) * u(rng));
    bool clear = true;
    for (std::size_t i = 0; i < sim.particles().size() && clear; ++i) {
      Vec3 d = x - sim.particles().x[i];
      d.y() -= kW * std::round(d.y() / kW);
      clear = d.norm() > 2 * kR + 1e-5;
    }
    if (!clear) continue;
    sim.particles().add(id++, x, drift + 0.3 / std::sqrt(3.0) * Vec3(c(rng), c(rng), c(rng)),
                        Vec3::Zero(), kR, 0, kRho);
  }
  sim.initialise();
  MPI_Comm comm = MPI_COMM_WORLD;
  const int rank = test::world_rank();
  int ranks = 0;
  MPI_Comm_size(comm, &ranks);
  ASSERT_EQ(ranks, 4);
  ASSERT_EQ(sim.global_state().particles, 200);

  auto energy = [&] {
    const auto g = test::gather_grains(sim.particles(), comm);
    double e = rank == 0 ? test::total_energy(g, s) : 0.0;
    MPI_Bcast(&e, 1, MPI_DOUBLE, 0, comm);
    return e;
  };
  const double e0 = energy();
  double worst_rise = 0, travelled = 0;
  int emptied = 0;  // times some rank went from holding particles to none
  std::vector<long> held(4, 0), before(4, 0);
  long local = static_cast<long>(sim.particles().size());
  MPI_Allgather(&local, 1, MPI_LONG, before.data(), 1, MPI_LONG, comm);
  const long chunks = 30 * test::stress_scale();
  for (long k = 0; k < chunks; ++k) {
    for (int j = 0; j < 100; ++j) sim.step();
    ASSERT_TRUE(test::all_finite(sim.particles(), comm)) << "step " << sim.counters().steps;
    const GlobalState g = sim.global_state();
    ASSERT_EQ(g.particles, 200) << "step " << sim.counters().steps;
    ASSERT_EQ(g.removed, 0);
    const double e = energy();
    worst_rise = std::max(worst_rise, e / e0 - 1);
    ASSERT_LE(e, e0 * (1 + 1e-9)) << "step " << sim.counters().steps;
    local = static_cast<long>(sim.particles().size());
    MPI_Allgather(&local, 1, MPI_LONG, held.data(), 1, MPI_LONG, comm);
    for (int r = 0; r < 4; ++r) emptied += before[r] > 0 && held[r] == 0;
    before = held;
  }
  travelled = drift.x() * sim.time();
  EXPECT_GT(travelled, kL) << "the cloud should lap the channel once";
  EXPECT_GE(emptied, 4);
  long rebuilds = sim.counters().rebuilds;
  MPI_Allreduce(MPI_IN_PLACE, &rebuilds, 1, MPI_LONG, MPI_MAX, comm);
  if (rank == 0)
    std::printf(
        "200 spheres at %.1f m/s drift over %d x %d x %d ranks: %ld steps (dt = %.3e s), %.0f mm "
        "travelled (%.2f laps), %d rank emptyings, %ld rebuilds, energy %.6e -> %.6e J, "
        "largest rise %.2e (relative)\n",
        drift.norm(), GetParam()[0], GetParam()[1], GetParam()[2], sim.counters().steps, sim.dt(),
        1e3 * travelled, travelled / kL, emptied, rebuilds, e0, energy(), worst_rise);
  else
    energy();
}

INSTANTIATE_TEST_SUITE_P(Grids, FastCrossing,
                         testing::Values(std::array<int, 3>{2, 2, 1}, std::array<int, 3>{4, 1, 1}),
                         [](const testing::TestParamInfo<std::array<int, 3>>& i) {
                           return std::to_string(i.param[0]) + "x" + std::to_string(i.param[1]) +
                                  "x" + std::to_string(i.param[2]);
                         });

}  // namespace
}  // namespace grainflow
