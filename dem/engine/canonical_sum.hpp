#pragma once
// Reproducible summation (`parallel: {reproducible: true}`; docs/parallel.md).
//
// Floating-point addition is not associative, so a particle's total contact force depends
// on the order in which its contacts are added, and that order is the order of the
// neighbour lists: of the particles' storage order on the rank, of which rank holds which
// pair, of whether a partner is local or a ghost. One bit of difference in one step grows
// in a dense flow to a macroscopic difference within a few thousand steps.
//
// Here each particle's pair contributions are added in one canonical order instead:
// by the partner's global id (then by the partner image's periodic shift), which is a
// property of the pair, not of the decomposition. The pair sweeps write every touching
// contact's two shares (force and torque on its first and on its second particle, first =
// lower global id) into a buffer instead of adding them; add_to() then adds each
// particle's shares to its force and torque in the order fixed at the neighbour rebuild.
// The walls follow in wall order, then the force terms in their order (Simulation).
#include <vector>

#include "dem/core/particles.hpp"
#include "dem/neighbour/verlet_list.hpp"
#include "dem/parallel/ghosts.hpp"

namespace grainflow {

struct CanonicalSum {
  // One contact's force on its first particle (the second gets -force) and its torques on
  // both.
  struct Share {
    Vec3 force;
    Vec3 torque[2];
  };

  // Sets the order of every local particle's list entries, after a neighbour rebuild:
  // entries are numbered over the local list, then the ghost list, and each particle's
  // references `2 e + side` (side 0: the particle is the pair's first, 1: its second) are
  // sorted by the partner's global id, then by the partner image's shift.
  void build(const Particles& p, const Ghosts& g, const NeighbourList& local,
             const NeighbourList& ghost);

  // Adds the shares of the local particles [a, b) of this sweep, in canonical order, to
  // their force (and torque when `spin`).
  void add_to(Particles& p, bool spin, int a, int b) const;

  // The sweep runs over the owners kChunk at a time, and adds the chunk's sums right after
  // it (contact_sweep.cpp). The shares then live in a ring of records that holds every
  // touching contact between the first owner of a pair's chunk and the end of its partner's
  // chunk (its size is set in build()), small enough to stay in cache.
  static constexpr int kChunk = 256;
  // Filled by the pair sweeps: the record of entry e, slot[e], or `none` (zeros) when the
  // entry does not touch.
  std::vector<int> slot;
  std::vector<Share> shares;
  int mask = 0;        // ring size - 1 (a power of two minus 1)
  int none = 0;        // the record of zeros: the ring size
  int ghost_base = 0;  // number of the first ghost-list entry (the local list's length)

 private:
  std::vector<int> offsets_;  // refs_ of local particle i: [offsets_[i], offsets_[i + 1])
  std::vector<int> refs_;     // 2 e + side
};

}  // namespace grainflow
