#pragma once
// The contact springs carried across a neighbour rebuild (Simulation::rebuild). Local indices
// change there (migration, removal, spatial re-sorting), so a spring travels by the global ids
// of its bodies, and only while it is stretched (a new contact starts from a zero spring):
//   - a particle pair's spring once per record, keyed by the two ids (lower first), holding
//     only the kinds the contact law keeps (tangential, EPSD rolling). Both partners of a
//     local pair find the same record; each owner of a pair across ranks carries its own copy
//     (the two are bit-identical, dem/parallel/ghosts.hpp);
//   - a particle-wall spring keyed by the particle's id and its wall history column
//     (WallSet), as a whole ContactHistory (a mesh slot's key column keeps a normal in it).
// The records form flat arrays that do not depend on the particles' order: re-sorting and
// removal leave them alone, and migration sends the records of the particles that leave with
// them (Exchange::migrate). A pair may then be held twice by the same rank (both owners' copies
// meet when a partner migrates); the copies are equal and either serves.
//
// For the lookups, index() builds a hash table of 4-byte record numbers (open addressing,
// linear probing, 1.5 slots per record): one probe sequence per list entry at the rebuild,
// no sort. Compared with a list of springs per particle (each spring held by both partners,
// 56 bytes per copy plus an allocation per particle), a touching pair costs 40 bytes here (16
// of ids, 24 of tangential spring) and 6 bytes of table.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "dem/contact/contact_geometry.hpp"
#include "dem/core/types.hpp"

namespace grainflow {

class CarriedSprings {
 public:
  struct PairKey {
    GlobalId lo, hi;  // lo < hi
  };
  struct WallKey {
    GlobalId particle;
    int column;  // WallSet history column
  };
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);

  CarriedSprings() = default;
  // Pair records hold the tangential and/or rolling spring as the contact law keeps them.
  CarriedSprings(bool tangential, bool rolling) : tangential_(tangential), rolling_(rolling) {}
  bool keeps_tangential() const { return tangential_; }
  bool keeps_rolling() const { return rolling_; }

  void reserve(std::size_t pairs, std::size_t walls);
  // The pair (a, b) in either order (a != b); the kinds not kept are ignored.
  void add_pair(GlobalId a, GlobalId b, const Vec3& tangential, const Vec3& rolling);
  void add_wall(GlobalId particle, int column, const ContactHistory& h);

  std::size_t pairs() const { return pair_key_.size(); }
  std::size_t walls() const { return wall_key_.size(); }
  const PairKey& pair_key(std::size_t r) const { return pair_key_[r]; }
  // Both springs of pair record r (zero where not kept).
  ContactHistory pair(std::size_t r) const {
    return {tangential_ ? tangential_values_[r] : Vec3::Zero(),
            rolling_ ? rolling_values_[r] : Vec3::Zero()};
  }
  const WallKey& wall_key(std::size_t r) const { return wall_key_[r]; }
  const ContactHistory& wall(std::size_t r) const { return wall_values_[r]; }

  // Removes the records whose flag is set (the others keep their order). Clears the index.
  void drop_pairs(const std::vector<char>& drop);
  void drop_walls(const std::vector<char>& drop);

  // Builds the hash tables for the lookups below; call after the last add (adding or
  // dropping records clears them). Costs 6 bytes per record.
  void index();
  // Lookups (after index()): a pair record of (a, b) in either order, a wall record of
  // (particle, column); npos when there is none.
  std::size_t find_pair(GlobalId a, GlobalId b) const;
  std::size_t find_wall(GlobalId particle, int column) const;

  void clear();  // every record and the index, memory released

 private:
  bool tangential_ = false, rolling_ = false;
  std::vector<PairKey> pair_key_;
  std::vector<Vec3> tangential_values_, rolling_values_;  // parallel to pair_key_, if kept
  std::vector<WallKey> wall_key_;
  std::vector<ContactHistory> wall_values_;
  // The hash tables: record number + 1 per slot, 0 for an empty slot (empty until index()).
  std::vector<std::uint32_t> pair_slots_, wall_slots_;
};

// Per-particle data that moves with its particle between ranks (and is permuted and
// compacted with it), and the springs, which travel by ids.
struct CarriedState {
  CarriedSprings springs;
  // The implicit drag (K, u) of the step's end, [particle]; carried only across the
  // rebuild after a checkpoint, where the next half kick still needs it. The flag is
  // the same on every rank (a rank may hold no particles).
  bool carries_drag = false;
  std::vector<std::array<double, 4>> drag;
};

}  // namespace grainflow
