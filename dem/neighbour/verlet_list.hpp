#pragma once
// Binned Verlet neighbour list with skin (half list: each pair once, j > i).
//
// Build: particles are binned on a regular grid whose bin edge is at least the
// largest interaction range 2 r_max + skin; the caller first re-sorts particles by
// bin (sort_permutation) so that a bin's particles are contiguous in memory, then
// build() scans each particle's 27 neighbouring bins (fewer when an axis has fewer
// than 3 bins, so no bin is visited twice). A pair is listed when its surface gap
// is below the skin: |x_i - x_j| < r_i + r_j + skin, with the minimum-image
// distance along periodic axes.
#include <array>
#include <cstddef>
#include <vector>

#include "dem/core/particles.hpp"
#include "dem/scene/scene.hpp"

namespace grainflow {

// Minimum-image displacement helper: L per axis and 1/L (0 on bounded axes).
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
  std::vector<int> offsets;  // size N+1; neighbours of i are j[offsets[i] .. offsets[i+1])
  std::vector<int> j;
  std::size_t pairs() const { return j.size(); }
};

class BinGrid {
 public:
  // Throws std::invalid_argument if a periodic axis is shorter than two bin edges
  // (the minimum-image convention would then miss pairs).
  BinGrid(const Box& box, double bin_edge);
  int bin_of(const Vec3& x) const;
  // Permutation that orders particles by bin (counting sort, stable); also sizes
  // the grid for the current particle count.
  std::vector<std::size_t> sort_permutation(const Particles& p);
  // Requires particles sorted by bin (after applying sort_permutation).
  void build(const Particles& p, double skin, NeighbourList& out) const;
  const std::array<int, 3>& bins() const { return n_; }

 private:
  void resize_for(std::size_t particles);

  Box box_;
  double min_edge_;
  std::array<int, 3> n_{};
  Vec3 inv_edge_;
  std::vector<int> bin_start_;  // size nbins+1, valid after sort_permutation
};

// Reference O(N^2) search with the same criterion, for tests.
std::vector<std::pair<GlobalId, GlobalId>> brute_force_pairs(const Particles& p, const Box& box,
                                                              double skin);

}  // namespace grainflow
