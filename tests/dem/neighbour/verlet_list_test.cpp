// The binned Verlet lists find exactly the pairs a brute-force O(N^2) search finds
// (gap below the skin, minimum image on periodic axes), on random polydisperse
// configurations. Periodic pairs are found through ghost images made by the
// exchange on one rank. Reference: brute_force_pairs, an independent double loop.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include "dem/neighbour/verlet_list.hpp"
#include "dem/parallel/exchange.hpp"

namespace grainflow {
namespace {

struct Case {
  std::array<bool, 3> periodic;
  int n;
  double r_min, r_max;
};

class VerletVsBruteForce : public ::testing::TestWithParam<Case> {};

TEST_P(VerletVsBruteForce, SamePairs) {
  const Case c = GetParam();
  Domain d;
  d.lo = Vec3(-0.01, 0, 0.02);
  d.hi = Vec3(0.03, 0.025, 0.05);
  d.periodic = c.periodic;
  const Box box(d);
  Decomposition decomposition(MPI_COMM_SELF, d);
  Exchange exchange(decomposition);
  for (unsigned seed = 1; seed <= 5; ++seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1), ur(c.r_min, c.r_max);
    Particles p;
    for (int i = 0; i < c.n; ++i) {
      const Vec3 x = d.lo + (d.hi - d.lo).cwiseProduct(Vec3(u(rng), u(rng), u(rng)));
      p.add(1000 + i, x, Vec3::Zero(), Vec3::Zero(), ur(rng), 0, 1000);
    }
    const double skin = 0.3 * c.r_max, cutoff = 2 * c.r_max + skin;
    BinGrid grid(d.lo - Vec3::Constant(cutoff), d.hi + Vec3::Constant(cutoff), cutoff);
    p.permute(grid.sort_permutation(p));
    Ghosts g;
    exchange.borders(p, cutoff, g);
    NeighbourList local, ghost;
    grid.build(p, g, skin, local, ghost);

    std::vector<std::pair<GlobalId, GlobalId>> half;
    std::set<std::pair<GlobalId, GlobalId>> all;
    // Each entry names its owner (the sweeps' one loop over all entries relies on it).
    ASSERT_EQ(local.owner.size(), local.j.size());
    ASSERT_EQ(ghost.owner.size(), ghost.j.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
      for (int k = local.offsets[i]; k < local.offsets[i + 1]; ++k)
        EXPECT_EQ(local.owner[k], static_cast<int>(i));
      for (int k = ghost.offsets[i]; k < ghost.offsets[i + 1]; ++k)
        EXPECT_EQ(ghost.owner[k], static_cast<int>(i));
    }
    for (std::size_t i = 0; i < p.size(); ++i) {
      for (int k = local.offsets[i]; k < local.offsets[i + 1]; ++k) {
        const GlobalId a = p.id[i], b = p.id[local.j[k]];
        half.emplace_back(std::min(a, b), std::max(a, b));
        all.emplace(std::min(a, b), std::max(a, b));
      }
      for (int k = ghost.offsets[i]; k < ghost.offsets[i + 1]; ++k) {
        const GlobalId a = p.id[i], b = g.id[ghost.j[k]];
        all.emplace(std::min(a, b), std::max(a, b));
      }
    }
    const auto expected = brute_force_pairs(p, box, skin);
    ASSERT_GT(expected.size(), 10u) << "configuration too sparse to test anything";
    EXPECT_EQ(std::vector(all.begin(), all.end()), expected) << "seed " << seed;
    // The local half list holds every local pair once.
    std::sort(half.begin(), half.end());
    EXPECT_EQ(std::adjacent_find(half.begin(), half.end()), half.end());
    if (c.periodic == std::array<bool, 3>{false, false, false}) {
      EXPECT_EQ(g.size(), 0u);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Configurations, VerletVsBruteForce,
    ::testing::Values(Case{{false, false, false}, 800, 2e-4, 1e-3},
                      Case{{true, true, true}, 800, 2e-4, 1e-3},
                      Case{{true, false, true}, 1500, 1e-4, 1e-3},   // 10:1 radius ratio
                      Case{{true, true, false}, 300, 2e-3, 4e-3}));  // few bins per axis

}  // namespace
}  // namespace grainflow
