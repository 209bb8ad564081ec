// The binned Verlet list finds exactly the pairs a brute-force O(N^2) search finds
// (gap below the skin, minimum image on periodic axes), on random polydisperse
// configurations. Reference: brute_force_pairs, an independent double loop.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "dem/neighbour/verlet_list.hpp"

namespace grainflow {
namespace {

std::vector<std::pair<GlobalId, GlobalId>> listed_pairs(const Particles& p,
                                                         const NeighbourList& nl) {
  std::vector<std::pair<GlobalId, GlobalId>> out;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int k = nl.offsets[i]; k < nl.offsets[i + 1]; ++k) {
      const GlobalId a = p.id[i], b = p.id[nl.j[k]];
      out.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::sort(out.begin(), out.end());
  return out;
}

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
  for (unsigned seed = 1; seed <= 5; ++seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1), ur(c.r_min, c.r_max);
    Particles p;
    for (int i = 0; i < c.n; ++i) {
      const Vec3 x = d.lo + (d.hi - d.lo).cwiseProduct(Vec3(u(rng), u(rng), u(rng)));
      p.add(1000 + i, x, Vec3::Zero(), Vec3::Zero(), ur(rng), 0, 1000);
    }
    const double skin = 0.3 * c.r_max;
    BinGrid grid(box, 2 * c.r_max + skin);
    p.permute(grid.sort_permutation(p));
    NeighbourList nl;
    grid.build(p, skin, nl);
    const auto expected = brute_force_pairs(p, box, skin);
    ASSERT_GT(expected.size(), 10u) << "configuration too sparse to test anything";
    EXPECT_EQ(listed_pairs(p, nl), expected) << "seed " << seed;
    // Half list: every pair once.
    auto got = listed_pairs(p, nl);
    EXPECT_EQ(std::adjacent_find(got.begin(), got.end()), got.end());
  }
}

INSTANTIATE_TEST_SUITE_P(
    Configurations, VerletVsBruteForce,
    ::testing::Values(Case{{false, false, false}, 800, 2e-4, 1e-3},
                      Case{{true, true, true}, 800, 2e-4, 1e-3},
                      Case{{true, false, true}, 1500, 1e-4, 1e-3},   // 10:1 radius ratio
                      Case{{true, true, false}, 300, 2e-3, 4e-3}));  // few bins per axis

TEST(BinGrid, RefusesPeriodicAxisShorterThanTwoRanges) {
  Domain d;
  d.lo = Vec3::Zero();
  d.hi = Vec3(0.01, 0.1, 0.1);
  d.periodic = {true, false, false};
  EXPECT_THROW(BinGrid(Box(d), 0.006), std::invalid_argument);
}

}  // namespace
}  // namespace grainflow
