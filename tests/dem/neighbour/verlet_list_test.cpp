// The binned Verlet lists find exactly the pairs a brute-force O(N^2) search finds
// (gap below the skin, minimum image on periodic axes), on random polydisperse
// configurations. Periodic pairs are found through ghost images made by the
// exchange on one rank. Reference: brute_force_pairs, an independent double loop.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
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

// Issue 17 item 6: a clustered heap in a huge domain. 3000 spheres (r = 0.2-0.5 mm) in a
// 12 mm cube inside a domain 2 km on a side, periodic along x with the heap across the
// periodic side (so ghosts are images). The lattice has ~(2000 m / 1.3 mm)^3 = 4e18 bins
// at the bin edge of the interaction range (capped at 2^20 per axis); only the bins that
// hold particles may cost memory. Reference: brute_force_pairs. The grid's memory must stay
// within 48 bytes per particle and ghost (its work arrays are three 8-byte keys and three
// 4-byte indices per particle or ghost at most), where one byte per lattice bin would be
// ~1e18 bytes.
TEST(VerletLists, ClusteredHeapInAHugeDomain) {
  Domain d;
  d.lo = Vec3(-1000, -1000, -1000);
  d.hi = Vec3(1000, 1000, 1000);
  d.periodic = {true, false, false};
  const Box box(d);
  Decomposition decomposition(MPI_COMM_SELF, d);
  Exchange exchange(decomposition);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-0.006, 0.006), ur(2e-4, 5e-4);
  Particles p;
  for (int i = 0; i < 3000; ++i) {
    // x across the periodic side at -1000 = +1000: the heap is split in two there.
    Vec3 x(-1000 + u(rng), 3 + u(rng), 500 + u(rng));
    if (x[0] < -1000) x[0] += 2000;
    p.add(1 + i, x, Vec3::Zero(), Vec3::Zero(), ur(rng), 0, 1000);
  }
  const double skin = 0.3e-3, cutoff = 2 * 5e-4 + skin;
  BinGrid grid(d.lo - Vec3::Constant(cutoff), d.hi + Vec3::Constant(cutoff), cutoff);
  for (int a = 0; a < 3; ++a) EXPECT_GE(grid.bins()[a], 1 << 20);
  p.permute(grid.sort_permutation(p));
  Ghosts g;
  exchange.borders(p, cutoff, g);
  ASSERT_GT(g.size(), 500u);  // the images across the periodic side
  NeighbourList local, ghost;
  grid.build(p, g, skin, local, ghost);
  std::set<std::pair<GlobalId, GlobalId>> all;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (int k = local.offsets[i]; k < local.offsets[i + 1]; ++k)
      all.emplace(std::min(p.id[i], p.id[local.j[k]]), std::max(p.id[i], p.id[local.j[k]]));
    for (int k = ghost.offsets[i]; k < ghost.offsets[i + 1]; ++k)
      all.emplace(std::min(p.id[i], g.id[ghost.j[k]]), std::max(p.id[i], g.id[ghost.j[k]]));
  }
  const auto expected = brute_force_pairs(p, box, skin);
  ASSERT_GT(expected.size(), 3000u);
  EXPECT_EQ(std::vector(all.begin(), all.end()), expected);
  const std::size_t held = p.size() + g.size();
  std::printf(
      "[ measured ] %zu pairs; grid memory %zu bytes for %zu particles and ghosts "
      "(%.1f per item)\n",
      expected.size(), grid.memory_bytes(), held,
      static_cast<double>(grid.memory_bytes()) / static_cast<double>(held));
  EXPECT_LE(grid.memory_bytes(), 48 * held);
}

// A flat or long lattice orders its bins along its widest axis first when that axis has
// more than twice z's bins (BinGrid::choose_axes: the memory layer between a particle and its
// partners along the slowest axis is then the smaller one); other lattices keep z, y, x. The
// lists stay exactly those of the brute-force search (brute_force_pairs), and the sort puts
// the particles in order of their bin along the chosen slowest axis.
TEST(VerletLists, WideLatticesTakeTheirWidestAxisFirst) {
  struct Shape {
    Vec3 hi;
    std::array<bool, 3> periodic;
    std::array<int, 3> axes;  // expected, fastest first
  };
  const double r = 5e-4, skin = 2e-4, cutoff = 2 * r + skin;
  for (const Shape& shape : {
           Shape{Vec3(0.06, 0.03, 0.006), {true, true, false}, {1, 2, 0}},    // flat, wide in x
           Shape{Vec3(0.012, 0.06, 0.008), {false, true, false}, {0, 2, 1}},  // long in y
           Shape{Vec3(0.02, 0.02, 0.06), {false, false, false}, {0, 1, 2}},   // a column
           Shape{Vec3(0.02, 0.02, 0.012), {false, false, false}, {0, 1, 2}},  // under twice
       }) {
    Domain d;
    d.lo = Vec3::Zero();
    d.hi = shape.hi;
    d.periodic = shape.periodic;
    const Box box(d);
    Decomposition decomposition(MPI_COMM_SELF, d);
    Exchange exchange(decomposition);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(0, 1), ur(0.6 * r, r);
    Particles p;
    for (int i = 0; i < 4000; ++i)
      p.add(1 + i, d.hi.cwiseProduct(Vec3(u(rng), u(rng), u(rng))), Vec3::Zero(), Vec3::Zero(),
            ur(rng), 0, 1000);
    const Vec3 lo = d.lo - Vec3::Constant(cutoff), hi = d.hi + Vec3::Constant(cutoff);
    BinGrid grid(lo, hi, cutoff);
    EXPECT_EQ(grid.axes(), shape.axes) << "domain " << d.hi.transpose();
    p.permute(grid.sort_permutation(p));
    const int slow = grid.axes()[2];
    const double inv = grid.bins()[slow] / (hi[slow] - lo[slow]);
    for (std::size_t i = 1; i < p.size(); ++i)
      ASSERT_LE(std::floor((p.x[i - 1][slow] - lo[slow]) * inv),
                std::floor((p.x[i][slow] - lo[slow]) * inv));
    Ghosts g;
    exchange.borders(p, cutoff, g);
    NeighbourList local, ghost;
    grid.build(p, g, skin, local, ghost);
    std::set<std::pair<GlobalId, GlobalId>> all;
    std::size_t entries = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      for (int k = local.offsets[i]; k < local.offsets[i + 1]; ++k, ++entries)
        all.emplace(std::min(p.id[i], p.id[local.j[k]]), std::max(p.id[i], p.id[local.j[k]]));
      for (int k = ghost.offsets[i]; k < ghost.offsets[i + 1]; ++k)
        all.emplace(std::min(p.id[i], g.id[ghost.j[k]]), std::max(p.id[i], g.id[ghost.j[k]]));
    }
    const auto expected = brute_force_pairs(p, box, skin);
    ASSERT_GT(expected.size(), 1000u);
    EXPECT_EQ(std::vector(all.begin(), all.end()), expected) << "domain " << d.hi.transpose();
    EXPECT_EQ(entries, local.j.size());  // each local pair once
  }
}

// The lists hold the same entries in the same order as a dense array of all the lattice's
// bins gives (the binning before the keyed bins, when its bin count stayed under its cap):
// particles by bin, then id; each particle's partners bin by bin, z then y then x. The order
// of a particle's contacts is the order of its force sum, so where the lattice is the same,
// trajectories are the same bit for bit. Reference: that dense binning, written out here.
TEST(VerletLists, SameOrderAsDenseBins) {
  Domain d;
  d.lo = Vec3(0, 0, 0);
  d.hi = Vec3(0.02, 0.015, 0.03);
  d.periodic = {true, false, false};
  Decomposition decomposition(MPI_COMM_SELF, d);
  Exchange exchange(decomposition);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1), ur(3e-4, 1e-3);
  Particles p;
  for (int i = 0; i < 1500; ++i)
    p.add(7 + i, d.lo + (d.hi - d.lo).cwiseProduct(Vec3(u(rng), u(rng), u(rng))), Vec3::Zero(),
          Vec3::Zero(), ur(rng), 0, 1000);
  const double skin = 3e-4, cutoff = 2e-3 + skin;
  const Vec3 lo = d.lo - Vec3::Constant(cutoff), hi = d.hi + Vec3::Constant(cutoff);
  BinGrid grid(lo, hi, cutoff);
  const std::vector<std::size_t> perm = grid.sort_permutation(p);

  // Dense bins: n = floor(length / edge) per axis, bin (z n_y + y) n_x + x.
  int n[3];
  for (int a = 0; a < 3; ++a) n[a] = static_cast<int>(std::floor((hi[a] - lo[a]) / cutoff));
  auto coord = [&](const Vec3& x, int a) {
    const int k = static_cast<int>(std::floor((x[a] - lo[a]) * (n[a] / (hi[a] - lo[a]))));
    return std::clamp(k, 0, n[a] - 1);
  };
  auto bin = [&](const Vec3& x) { return (coord(x, 2) * n[1] + coord(x, 1)) * n[0] + coord(x, 0); };
  std::vector<std::size_t> dense(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) dense[i] = i;
  std::sort(dense.begin(), dense.end(), [&](std::size_t a, std::size_t b) {
    return std::pair(bin(p.x[a]), p.id[a]) < std::pair(bin(p.x[b]), p.id[b]);
  });
  ASSERT_EQ(perm, dense);

  p.permute(perm);
  Ghosts g;
  exchange.borders(p, cutoff, g);
  ASSERT_GT(g.size(), 100u);
  NeighbourList local, ghost;
  grid.build(p, g, skin, local, ghost);
  std::vector<int> ref_local, ref_ghost, bin_l(p.size()), bin_g(g.size());
  for (std::size_t j = 0; j < p.size(); ++j) bin_l[j] = bin(p.x[j]);
  for (std::size_t k = 0; k < g.size(); ++k) bin_g[k] = bin(g.position(k));
  for (std::size_t i = 0; i < p.size(); ++i) {
    const int c[3] = {coord(p.x[i], 0), coord(p.x[i], 1), coord(p.x[i], 2)};
    for (int z = std::max(0, c[2] - 1); z <= std::min(n[2] - 1, c[2] + 1); ++z)
      for (int y = std::max(0, c[1] - 1); y <= std::min(n[1] - 1, c[1] + 1); ++y)
        for (int x = std::max(0, c[0] - 1); x <= std::min(n[0] - 1, c[0] + 1); ++x) {
          const int b = (z * n[1] + y) * n[0] + x;
          for (std::size_t j = i + 1; j < p.size(); ++j) {
            const double cut = p.radius[i] + p.radius[j] + skin;
            if (bin_l[j] == b && (p.x[i] - p.x[j]).squaredNorm() < cut * cut)
              ref_local.push_back(static_cast<int>(j));
          }
          for (std::size_t k = 0; k < g.size(); ++k) {  // exchange order within a bin
            const double cut = p.radius[i] + g.radius[k] + skin;
            if (bin_g[k] == b && (p.x[i] - g.position(k)).squaredNorm() < cut * cut)
              ref_ghost.push_back(static_cast<int>(k));
          }
        }
  }
  EXPECT_EQ(local.j, ref_local);
  EXPECT_EQ(ghost.j, ref_ghost);
}

INSTANTIATE_TEST_SUITE_P(
    Configurations, VerletVsBruteForce,
    ::testing::Values(Case{{false, false, false}, 800, 2e-4, 1e-3},
                      Case{{true, true, true}, 800, 2e-4, 1e-3},
                      Case{{true, false, true}, 1500, 1e-4, 1e-3},   // 10:1 radius ratio
                      Case{{true, true, false}, 300, 2e-3, 4e-3}));  // few bins per axis

}  // namespace
}  // namespace grainflow
