#pragma once
// Binned Verlet neighbour lists with skin.
//
// Bins: a regular lattice over the rank's box widened by the interaction range, with bins
// no smaller than that range (2 r_max + skin). Only the bins that hold particles exist:
// each local particle and ghost carries the integer key of its bin, and the particles are
// sorted by key, so memory and time are O(N) whatever the size of the domain — a heap of
// particles in a 20 m domain costs what it costs in an 8 cm one (docs/performance.md,
// benchmarks/neighbour_search/).
//
// Build: the caller first re-sorts local particles by bin (sort_permutation, ordered by
// bin, then by global id within a bin) so that a bin's particles are contiguous in
// memory. build() then scans each local particle's 27 neighbouring bins — nine rows of
// three bins along x, each row a contiguous range of keys and so of sorted particles —
// and lists a pair when its surface gap is below the skin, |x_i - x_j| < r_i + r_j + skin:
//   - `local`: local-local pairs, each once (j > i), a half list;
//   - `ghost`: local-ghost pairs, each once per local particle (the rank that owns
//     the ghost lists the same pair from its side: forces are computed twice, once
//     per owner, bit-identically — see dem/parallel/ghosts.hpp).
// A particle's partners are listed bin by bin in key order, within a bin in sorted order
// (locals) or exchange order (ghosts). The key orders bins by z, then y, then x, unless x
// or y has more than twice z's bins: then that axis comes first (choose_axes()).
// Periodicity is handled by ghosts (images), not here.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "dem/core/particles.hpp"
#include "dem/parallel/ghosts.hpp"
#include "dem/scene/scene.hpp"

namespace grainflow {

// Minimum-image displacement helper (for reference searches in tests).
struct Box {
  Vec3 lo, hi, length, inv_length_periodic;
  std::array<bool, 3> periodic;
  bool any_periodic;
  explicit Box(const Domain& d);
  Vec3 min_image(Vec3 d) const {
    if (any_periodic)
      for (int a = 0; a < 3; ++a)
        if (periodic[a]) d[a] -= length[a] * std::nearbyint(d[a] * inv_length_periodic[a]);
    return d;
  }
};

struct NeighbourList {
  std::vector<int> offsets;  // size N+1; partners of i are j[offsets[i] .. offsets[i+1])
  std::vector<int> j;        // local index (half list) or ghost index (ghost list)
  // The particle i of each entry (parallel to j): the contact sweeps run over all entries
  // in one loop with it. A loop per particle ends after a varying count of entries, which
  // the processor mispredicts about once per particle (8 % of the settled bed's run time).
  std::vector<int> owner;
  std::size_t pairs() const { return j.size(); }
};

class BinGrid {
 public:
  // The lattice of bins covering [lo, hi] with edges no smaller than bin_edge (at most
  // 2^20 bins per axis, so that a key fits in 60 bits; larger bins are still correct).
  BinGrid(const Vec3& lo, const Vec3& hi, double bin_edge);
  // The lattice anchored at the domain [lo, hi] (parallel.reproducible): floor(L / bin_edge)
  // bins across each axis of length L, plus one on either side for ghosts and periodic
  // images (they lie within the interaction range <= one bin of the domain). Every rank of
  // every decomposition has the same lattice, so a particle's bin (its key for
  // CanonicalOrder) depends on its position only.
  static BinGrid anchored(const Vec3& lo, const Vec3& hi, double bin_edge);
  // Key of the bin holding x: (k_s n_m + k_m) n_f + k_f, each k clamped to the lattice,
  // over the axes slow, middle, fast (axes(); (z, y, x) unless x or y has more than twice
  // z's bins).
  std::uint64_t key_of(const Vec3& x) const;
  // Permutation that orders local particles by bin key, then by global id.
  std::vector<std::size_t> sort_permutation(const Particles& p);
  // Requires local particles sorted by bin (after applying sort_permutation).
  void build(const Particles& p, const Ghosts& g, double skin, NeighbourList& local,
             NeighbourList& ghost);
  const std::array<int, 3>& bins() const { return n_; }  // the lattice, per axis
  const std::array<int, 3>& axes() const { return axis_; }  // the key's axes, fastest first
  // Bytes held by the grid between builds (its work arrays): O(particles + ghosts).
  std::size_t memory_bytes() const;

 private:
  Vec3 lo_, hi_;
  std::array<int, 3> n_{};
  std::array<int, 3> axis_{0, 1, 2};  // the key's axes, fastest first
  Vec3 inv_edge_;
  void choose_axes();
  // Work arrays, kept between builds so that a rebuild does not allocate.
  std::vector<std::uint64_t> key_, key_tmp_;
  std::vector<int> order_, order_tmp_;
  std::vector<std::uint64_t> ghost_key_;  // sorted
  std::vector<int> ghost_order_;          // ghost indices by key, exchange order within a key
};

// Reference O(N^2) search with the same criterion (minimum image on periodic axes).
std::vector<std::pair<GlobalId, GlobalId>> brute_force_pairs(const Particles& p, const Box& box,
                                                              double skin);

}  // namespace grainflow
