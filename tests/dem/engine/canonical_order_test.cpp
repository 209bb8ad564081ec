// parallel.reproducible sums each particle's pair forces in one order: by ascending key of
// the partner, key = (bin of the anchored lattice that holds the partner's original
// position, global id), docs/parallel.md. CanonicalOrder arranges the entries of the
// neighbour lists so that the pair sweep, which adds each pair's force to both particles
// at once, meets every local particle's partners in that order.
//
// Reference: the rule itself, applied independently. For every local particle, its
// partners as the lists hold them, sorted by key with std::sort (an image's key taken from
// the local particle it is an image of), must be the partners in the order the sweep meets
// them. Exact comparison (keys are integers). Random polydisperse spheres in a box periodic
// along x and y (one rank: every ghost is a periodic image, some particles pair with
// several images), several seeds.
#include "dem/engine/canonical_order.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <tuple>

#include "dem/parallel/exchange.hpp"

namespace grainflow {
namespace {

using Key = std::tuple<std::uint64_t, GlobalId>;

TEST(canonical_order, EveryParticleMeetsItsPartnersByAscendingKey) {
  Domain d;
  d.lo = Vec3(-0.004, 0.001, 0);
  d.hi = Vec3(0.008, 0.013, 0.008);
  d.periodic = {true, true, false};
  Decomposition decomposition(MPI_COMM_SELF, d);
  Exchange exchange(decomposition);
  const double r_min = 0.4e-3, r_max = 0.8e-3, skin = 0.3e-3, cutoff = 2 * r_max + skin;
  for (unsigned seed = 1; seed <= 4; ++seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1), ur(r_min, r_max);
    Particles p;
    for (int i = 0; i < 700; ++i) {
      const Vec3 x = d.lo + (d.hi - d.lo).cwiseProduct(Vec3(u(rng), u(rng), u(rng)));
      p.add(5000 - 3 * i, x, Vec3::Zero(), Vec3::Zero(), ur(rng), 0, 1000);  // ids not in order
    }
    const BinGrid anchored = BinGrid::anchored(d.lo, d.hi, cutoff);
    BinGrid grid = anchored;
    p.permute(grid.sort_permutation(p));
    Ghosts g;
    exchange.borders(p, cutoff, g);
    NeighbourList local, ghost;
    grid.build(p, g, skin, local, ghost);
    CanonicalOrder order;
    order.build(p, g, local, ghost, grid);

    const std::size_t n = p.size();
    std::map<GlobalId, Key> key_of_id;
    for (std::size_t i = 0; i < n; ++i) key_of_id[p.id[i]] = {anchored.key_of(p.x[i]), p.id[i]};
    ASSERT_GT(g.size(), 100u) << "too few images to test the ghost rows";

    // The sweep's order: each run's local entries, then its ghost entries.
    std::vector<std::vector<Key>> met(n);
    std::vector<int> ghost_seen(ghost.pairs(), 0);
    int k = 0, t = 0;
    for (const CanonicalOrder::Run& run : order.runs) {
      ASSERT_GE(run.local_end, k);
      ASSERT_GE(run.ghost_end, t);
      for (; k < run.local_end; ++k) {
        const int i = local.owner[k], j = local.j[k];
        met[i].push_back(key_of_id.at(p.id[j]));
        met[j].push_back(key_of_id.at(p.id[i]));
      }
      for (; t < run.ghost_end; ++t) {
        const int e = order.ghost_entries[t];
        ++ghost_seen[e];
        met[ghost.owner[e]].push_back(key_of_id.at(g.id[ghost.j[e]]));
      }
    }
    // Every entry exactly once.
    EXPECT_EQ(k, static_cast<int>(local.pairs()));
    EXPECT_EQ(t, static_cast<int>(ghost.pairs()));
    EXPECT_EQ(std::count(ghost_seen.begin(), ghost_seen.end(), 1),
              static_cast<long>(ghost.pairs()));

    // The reference: each particle's partners from the lists, sorted by key.
    std::vector<std::vector<Key>> expected(n);
    for (std::size_t i = 0; i < n; ++i) {
      for (int e = local.offsets[i]; e < local.offsets[i + 1]; ++e) {
        expected[i].push_back(key_of_id.at(p.id[local.j[e]]));
        expected[local.j[e]].push_back(key_of_id.at(p.id[i]));
      }
      for (int e = ghost.offsets[i]; e < ghost.offsets[i + 1]; ++e)
        expected[i].push_back(key_of_id.at(g.id[ghost.j[e]]));
    }
    std::size_t with_images = 0, pairs = 0;
    for (std::size_t i = 0; i < n; ++i) {
      std::sort(expected[i].begin(), expected[i].end());
      EXPECT_EQ(met[i], expected[i]) << "particle " << p.id[i] << ", seed " << seed;
      with_images += ghost.offsets[i + 1] > ghost.offsets[i];
      pairs += expected[i].size();
    }
    EXPECT_GT(with_images, 50u);
    EXPECT_GT(pairs, 2000u);
  }
}

}  // namespace
}  // namespace grainflow
