#include "dem/engine/canonical_order.hpp"

#include <algorithm>
#include <stdexcept>
#include <tuple>

namespace grainflow {

void CanonicalOrder::build(const Particles& p, const Ghosts& g, const NeighbourList& local,
                           const NeighbourList& ghost, const BinGrid& grid) {
  const int n = static_cast<int>(p.size());
  const int ng = static_cast<int>(g.size());
  local_bin_.resize(n);
  for (int i = 0; i < n; ++i) local_bin_[i] = grid.key_of(p.x[i]);
  // A ghost's key is its original's: the bin of its unshifted position.
  ghost_bin_.resize(ng);
  for (int q = 0; q < ng; ++q) ghost_bin_[q] = grid.key_of(g.x[q]);
  const auto local_key = [&](int i) { return std::tie(local_bin_[i], p.id[i]); };
  const auto ghost_key = [&](int q) { return std::tie(ghost_bin_[q], g.id[q]); };

  // The order below relies on the storage order and the half list's rows; a violation is a
  // programming error, not a user's.
  for (int i = 1; i < n; ++i)
    if (!(local_key(i - 1) < local_key(i)))
      throw std::logic_error("CanonicalOrder: local particles are not sorted by key");
  for (int i = 0; i < n; ++i)
    for (int k = local.offsets[i]; k < local.offsets[i + 1]; ++k)
      if (local.j[k] <= (k > local.offsets[i] ? local.j[k - 1] : i))
        throw std::logic_error("CanonicalOrder: a half-list row is not in ascending key order");

  // Each ghost entry (i, q) goes to the row of the lower key: the ghost's row, or i's row.
  before_.clear();
  after_.clear();
  for (int e = 0; e < static_cast<int>(ghost.pairs()); ++e)
    (ghost_key(ghost.j[e]) < local_key(ghost.owner[e]) ? before_ : after_).push_back(e);
  // Ghost rows by the ghost's key (two images of one particle, rows of their own, by index),
  // and within a row by the local partner's key, which is its index.
  std::sort(before_.begin(), before_.end(), [&](int e, int f) {
    const int q = ghost.j[e], r = ghost.j[f];
    return std::tuple(ghost_bin_[q], g.id[q], q, ghost.owner[e]) <
           std::tuple(ghost_bin_[r], g.id[r], r, ghost.owner[f]);
  });
  // Local rows' ghost partners by row, then by the ghost's key.
  std::sort(after_.begin(), after_.end(), [&](int e, int f) {
    const int q = ghost.j[e], r = ghost.j[f];
    return std::tuple(ghost.owner[e], ghost_bin_[q], g.id[q], e) <
           std::tuple(ghost.owner[f], ghost_bin_[r], g.id[r], f);
  });

  runs.clear();
  ghost_entries.clear();
  int locals_done = 0;  // local entries placed so far (they are placed in list order)
  const auto place_ghost = [&](int e) {
    if (runs.empty() || runs.back().local_end != locals_done)
      runs.push_back({locals_done, static_cast<int>(ghost_entries.size())});
    ghost_entries.push_back(e);
    ++runs.back().ghost_end;
  };
  std::size_t b = 0, a = 0;
  for (int i = 0; i < n; ++i) {
    // The rows of the ghosts whose keys lie below i's.
    for (; b < before_.size() && ghost_key(ghost.j[before_[b]]) < local_key(i); ++b)
      place_ghost(before_[b]);
    // Row i: its local partners and its higher-key ghost partners, merged by key.
    int k = local.offsets[i];
    const int end = local.offsets[i + 1];
    for (; a < after_.size() && ghost.owner[after_[a]] == i; ++a) {
      const int q = ghost.j[after_[a]];
      while (k < end && local_key(local.j[k]) < ghost_key(q)) ++k;
      locals_done = k;
      place_ghost(after_[a]);
    }
    locals_done = end;
  }
  for (; b < before_.size(); ++b) place_ghost(before_[b]);
  if (runs.empty() || runs.back().local_end != locals_done)
    runs.push_back({locals_done, static_cast<int>(ghost_entries.size())});
}

}  // namespace grainflow
