// A bed of spheres with a 10:1 radius ratio settling under gravity (issue 8).
//
// Radii 0.2, 0.5, 1 and 2 mm (number fractions 0.7, 0.2, 0.07, 0.03: similar volumes
// of each size) poured by random fill into a box periodic along x and y, floor and
// lid along z. The neighbour grid is sized by the largest sphere (bins of
// 2 r_max + skin = 4.8 mm), so one bin holds dozens of the smallest; the time step
// by the smallest (0.2 t_R at 0.2 mm).
//
// Invariants:
// - no NaN / Inf in any position, velocity or spin (every 100 steps);
// - the particle count is conserved, nothing is removed;
// - no sphere sits inside another beyond time.max_overlap, by a brute-force search
//   over all pairs with periodic images (every 1000 steps and at the end);
// - the neighbour list is complete: at the end the engine's contact count equals a
//   brute-force count of touching pairs and wall contacts on the same positions
//   (exact: both evaluate the same overlap sign at the same positions).
#include <gtest/gtest.h>

#include <cstdio>

#include "dem/insert/insertion.hpp"
#include "tests/dem/stress/stress_support.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

Scene wide_bed() {
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5, 0.5, 0.0);
  const double L = 0.02, H = 0.05;
  s.domain.lo = Vec3::Zero();
  s.domain.hi = Vec3(L, L, H);
  s.domain.periodic = {true, true, false};
  s.contact.tangential = TangentialModel::history;
  s.gravity = Vec3(0, 0, -9.81);
  s.walls = {test::plane(Vec3::Zero(), Vec3::UnitZ()), test::plane(Vec3(0, 0, H), -Vec3::UnitZ())};
  s.time.step.reset();
  s.time.rayleigh_fraction = 0.2;
  Insertion fill;
  fill.region.lo = Vec3(0, 0, 0);
  fill.region.hi = Vec3(L, L, 0.01);
  fill.count = 800;
  fill.radius.kind = SizeDistribution::Kind::discrete;
  fill.radius.values = {0.2e-3, 0.5e-3, 1e-3, 2e-3};
  fill.radius.weights = {0.7, 0.2, 0.07, 0.03};
  fill.seed = 3;
  fill.source = "test";
  s.insertions.push_back(fill);
  return s;
}

TEST(WideSizeDistribution, TenToOneBedSettlesCleanly) {
  const Scene s = wide_bed();
  Simulation sim(s);
  sim.initialise();
  const long n = static_cast<long>(sim.particles().size());
  double r_min = 1, r_max = 0;
  for (double r : sim.particles().radius) {
    r_min = std::min(r_min, r);
    r_max = std::max(r_max, r);
  }
  ASSERT_NEAR(r_max / r_min, 10.0, 1e-9);
  const double limit = s.time.max_overlap;
  double worst_overlap = 0;
  const long chunks = 300 * test::stress_scale();
  for (long c = 0; c < chunks; ++c) {
    for (int k = 0; k < 100; ++k) sim.step();
    ASSERT_TRUE(test::all_finite(sim.particles())) << "step " << sim.counters().steps;
    worst_overlap = std::max(worst_overlap, sim.counters().max_overlap_ratio);
    if (c % 10 == 9) {
      const auto brute = test::census(test::gather_grains(sim.particles(), MPI_COMM_SELF), s);
      ASSERT_LT(brute.max_overlap_ratio, limit) << "step " << sim.counters().steps;
    }
  }
  const GlobalState g = sim.global_state();
  EXPECT_EQ(g.particles, n);
  EXPECT_EQ(g.removed, 0);
  const auto grains = test::gather_grains(sim.particles(), MPI_COMM_SELF);
  const auto brute = test::census(grains, s);
  EXPECT_EQ(sim.counters().contacts, brute.contacts) << "the neighbour list missed contacts";
  EXPECT_LT(brute.max_overlap_ratio, limit);
  EXPECT_NEAR(brute.max_overlap_ratio, sim.counters().max_overlap_ratio, 1e-12);
  double top = 0;
  for (const auto& q : grains) top = std::max(top, q.x[2] + q.r);
  std::printf(
      "%ld spheres, r %.1f-%.1f mm, dt = %.3e s, %ld steps (%.3f s), %ld rebuilds: %ld "
      "contacts (brute force %ld), largest overlap %.2e r (run max %.2e r), bed top %.1f mm, "
      "kinetic energy %.3e J\n",
      n, 1e3 * r_min, 1e3 * r_max, sim.dt(), sim.counters().steps, sim.time(),
      sim.counters().rebuilds, sim.counters().contacts, brute.contacts, brute.max_overlap_ratio,
      worst_overlap, 1e3 * top, g.kinetic_translational + g.kinetic_rotational);
}

}  // namespace
}  // namespace grainflow
