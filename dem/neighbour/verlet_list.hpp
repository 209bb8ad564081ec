#pragma once
// Binned Verlet neighbour lists with skin.
//
// Build: local particles and ghosts are binned on a regular grid over the rank's box
// widened by the interaction range, with bins no smaller than that range
// (2 r_max + skin). The caller first re-sorts local particles by bin
// (sort_permutation) so that a bin's particles are contiguous in memory. build()
// then scans each local particle's 27 neighbouring bins and lists a pair when its
// surface gap is below the skin, |x_i - x_j| < r_i + r_j + skin:
//   - `local`: local-local pairs, each once (j > i), a half list;
//   - `ghost`: local-ghost pairs, each once per local particle (the rank that owns
//     the ghost lists the same pair from its side: forces are computed twice, once
//     per owner, bit-identically — see dem/parallel/ghosts.hpp).
// Periodicity is handled by ghosts (images), not here.
#include <array>
#include <cstddef>
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
  // Bins covering [lo, hi] with edges no smaller than bin_edge.
  BinGrid(const Vec3& lo, const Vec3& hi, double bin_edge);
  int bin_of(const Vec3& x) const;
  // Permutation that orders local particles by bin (counting sort, stable); also
  // sizes the grid for the current particle count.
  std::vector<std::size_t> sort_permutation(const Particles& p);
  // Requires local particles sorted by bin (after applying sort_permutation).
  void build(const Particles& p, const Ghosts& g, double skin, NeighbourList& local,
             NeighbourList& ghost) const;
  const std::array<int, 3>& bins() const { return n_; }

 private:
  void resize_for(std::size_t particles);

  Vec3 lo_, hi_;
  double min_edge_;
  std::array<int, 3> n_{};
  Vec3 inv_edge_;
  std::vector<int> bin_start_;  // size nbins+1, valid after sort_permutation
};

// Reference O(N^2) search with the same criterion (minimum image on periodic axes).
std::vector<std::pair<GlobalId, GlobalId>> brute_force_pairs(const Particles& p, const Box& box,
                                                              double skin);

}  // namespace grainflow
