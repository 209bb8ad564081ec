// Load balancing moves the cut planes so that a bed lying at the bottom of a tall
// domain is shared evenly between two ranks stacked along z. Reference: the even
// split (imbalance = max/mean particle count = 1). Without balancing, the lower rank
// holds everything (imbalance 2); with it, the imbalance must fall below 1.15 — the
// plane lands within one histogram bin (domain/128) of the median, which holds a
// few percent of the particles. The particle count is conserved throughout.
// Imposed planes (set_cut_planes, a coupled run's: the fluid mesh's) are never moved, even
// with balance on: the plane stays at z = 0.04 exactly and the imbalance stays 2.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "tests/dem/parallel/support.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

double imbalance_after(bool balance, long* particles, bool impose = false,
                       std::vector<double>* z_cuts = nullptr) {
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.9, 0.3);
  s.domain.lo = Vec3(0, 0, 0);
  s.domain.hi = Vec3(0.02, 0.02, 0.08);
  s.domain.periodic = {true, true, false};
  s.gravity = Vec3(0, 0, -9.81);
  s.contact.tangential = TangentialModel::history;
  s.walls.push_back(test::plane(Vec3::Zero(), Vec3::UnitZ()));
  s.parallel.grid = {1, 1, 2};
  s.parallel.balance = balance;
  Insertion fill;
  fill.region.lo = Vec3(0, 0, 0);
  fill.region.hi = Vec3(0.02, 0.02, 0.012);
  fill.count = 600;
  fill.radius.value = 0.5e-3;
  fill.source = "test";
  s.insertions.push_back(fill);
  Simulation sim(s);
  if (impose) sim.set_cut_planes(2, {0.0, 0.04, 0.08});
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  for (auto& v : sim.particles().v) v = 0.2 * Vec3(u(rng), u(rng), u(rng));
  sim.set_dt(5e-6);
  sim.initialise();
  sim.advance_to(0.08);
  *particles = sim.global_state().particles;
  if (z_cuts) *z_cuts = sim.decomposition().cuts(2);
  EXPECT_GT(sim.counters().rebuilds, 30);
  return sim.load_imbalance();
}

TEST(LoadBalance, CutPlanesFollowTheBed) {
  long n_off = 0, n_on = 0;
  const double off = imbalance_after(false, &n_off);
  const double on = imbalance_after(true, &n_on);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0) std::printf("imbalance without balancing %.3f, with %.3f\n", off, on);
  EXPECT_EQ(n_off, 600);
  EXPECT_EQ(n_on, 600);
  EXPECT_GT(off, 1.9);
  EXPECT_LT(on, 1.15);
}

TEST(LoadBalance, ImposedCutPlanesStay) {
  long n = 0;
  std::vector<double> cuts;
  const double imbalance = imbalance_after(true, &n, true, &cuts);
  EXPECT_EQ(n, 600);
  EXPECT_EQ(cuts, (std::vector<double>{0.0, 0.04, 0.08}));
  EXPECT_GT(imbalance, 1.9);
}

}  // namespace
}  // namespace grainflow
