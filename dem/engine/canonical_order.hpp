#pragma once
// Reproducible summation (`parallel: {reproducible: true}`; docs/parallel.md).
//
// Floating-point addition is not associative, so a particle's total contact force depends
// on the order in which its contacts are added, and that order is the order of the
// neighbour lists: of the particles' storage order on the rank, of which rank holds which
// pair, of whether a partner is local or a ghost. One bit of difference in one step grows
// in a dense flow to a macroscopic difference within a few thousand steps.
//
// Here the pair sweep visits the pairs in an order that adds every particle's
// contributions by ascending key of the partner, with no buffer:
//   - every particle (local, ghost, periodic image) has a key fixed at each neighbour
//     rebuild: (the bin of an anchored lattice that holds its original's position, its
//     global id) (BinGrid::anchored; an image has its original's key);
//   - a pair belongs to the row of its particle with the lower key;
//   - rows are visited by ascending key (locals and ghosts merged), a row's pairs by
//     ascending key of the partner, and each pair's force is added to both its particles
//     (to the local ones) at once.
// A particle then receives first the pairs of the rows of its lower-key partners (visited
// before its own row, in ascending order) and then its own row (ascending): all its pairs
// by ascending partner key, whichever rank, list or storage slot holds them.
// The keys depend on positions and ids only, and rebuilds happen at the same steps on every
// rank count, so the order is the same on every decomposition.
//
// The local particles are stored by key (BinGrid::sort_permutation on the anchored
// lattice), and the half list's rows (j > i, bin by bin in key order, sorted within a bin)
// are then already rows of the lower key with partners ascending: without ghosts the order
// is the local list's own. The ghost list's entries are merged in: an entry goes to the row
// of its local particle when the ghost's key is higher, else to the ghost's row.
#include <cstdint>
#include <vector>

#include "dem/core/particles.hpp"
#include "dem/neighbour/verlet_list.hpp"
#include "dem/parallel/ghosts.hpp"

namespace grainflow {

struct CanonicalOrder {
  // The sweep's order: runs of local-list entries followed by runs of ghost-list entries.
  // Run r holds the local entries [runs[r-1].local_end, runs[r].local_end) in list order,
  // then the ghost entries ghost_entries[runs[r-1].ghost_end, runs[r].ghost_end).
  struct Run {
    int local_end;
    int ghost_end;
  };
  std::vector<Run> runs;
  std::vector<int> ghost_entries;  // ghost-list entries in sweep order
  // Where the sweep adds the ghosts' shares of their pairs (never read: a ghost's owner
  // computes its force).
  std::vector<Vec3> ghost_force, ghost_torque;

  // After a neighbour rebuild on the lattice `grid` (BinGrid::anchored), with the local
  // particles sorted by key (throws std::logic_error if they are not).
  void build(const Particles& p, const Ghosts& g, const NeighbourList& local,
             const NeighbourList& ghost, const BinGrid& grid);

 private:
  // Work arrays, kept between builds.
  std::vector<std::uint64_t> local_bin_, ghost_bin_;
  std::vector<int> before_, after_;  // ghost entries in a ghost's row / in a local's row
};

}  // namespace grainflow
