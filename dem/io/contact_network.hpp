#pragma once
// The contact network of one snapshot (scene key `output.contacts`): every touching particle
// pair and every particle-wall contact of the force evaluation that produced the snapshot's
// forces, with the forces that evaluation applied.
//
// File layout, written by SnapshotWriter next to the particle datasets (M pairs, W wall
// contacts, over all ranks; each pair once):
//   /contacts/id (int64, M x 2)              the two global ids, the lower first ("a", "b")
//   /contacts/ends (double, 2M x 3)          rows 2k, 2k+1: the centres of a and b (b's
//                                            periodic image next to a), the line ParaView draws
//   /contacts/point (double, M x 3)          where the tangential force acts (a's torque arm)
//   /contacts/normal_force, /contacts/tangential_force (double, M x 3)
//                                            the force on a by b (b receives the opposite)
//   /contacts/normal_force_magnitude (double, M)
//   /contacts/overlap (double, M)
//   /wall_contacts/id (int64, W), /wall_contacts/wall (int32, W: index in the scene's walls)
//   /wall_contacts/ends (double, 2W x 3)     the particle's centre and the contact point
//   /wall_contacts/point, normal_force, tangential_force (double, W x 3): force on the particle
//   /wall_contacts/normal_force_magnitude, overlap (double, W)
// Each dataset is checksummed and has a "units" attribute like the particle datasets; each
// group has the attribute count (int64, M or W).
#include <array>
#include <vector>

#include "dem/core/types.hpp"
#include "dem/io/xdmf_index.hpp"

namespace grainflow {

// The datasets of one contact group: SnapshotField plus how many rows each contact has.
struct ContactField {
  SnapshotField field;
  int rows;  // rows per contact: 2 for the line's two ends, else 1
};

inline constexpr const char* pair_contact_group = "contacts";
inline constexpr const char* wall_contact_group = "wall_contacts";

inline constexpr std::array<ContactField, 7> pair_contact_fields{{
    {{"id", 2, SnapshotField::Type::Int64, "1"}, 1},
    {{"ends", 3, SnapshotField::Type::Float64, "m"}, 2},
    {{"point", 3, SnapshotField::Type::Float64, "m"}, 1},
    {{"normal_force", 3, SnapshotField::Type::Float64, "N"}, 1},
    {{"tangential_force", 3, SnapshotField::Type::Float64, "N"}, 1},
    {{"normal_force_magnitude", 1, SnapshotField::Type::Float64, "N"}, 1},
    {{"overlap", 1, SnapshotField::Type::Float64, "m"}, 1},
}};

inline constexpr std::array<ContactField, 8> wall_contact_fields{{
    {{"id", 1, SnapshotField::Type::Int64, "1"}, 1},
    {{"wall", 1, SnapshotField::Type::Int32, "1"}, 1},
    {{"ends", 3, SnapshotField::Type::Float64, "m"}, 2},
    {{"point", 3, SnapshotField::Type::Float64, "m"}, 1},
    {{"normal_force", 3, SnapshotField::Type::Float64, "N"}, 1},
    {{"tangential_force", 3, SnapshotField::Type::Float64, "N"}, 1},
    {{"normal_force_magnitude", 1, SnapshotField::Type::Float64, "N"}, 1},
    {{"overlap", 1, SnapshotField::Type::Float64, "m"}, 1},
}};

// One rank's share of the network, structure of arrays in the layout above.
struct PairContacts {
  std::vector<std::array<GlobalId, 2>> id;  // lower id first
  std::vector<Vec3> ends;                   // 2 per contact
  std::vector<Vec3> point, normal_force, tangential_force;
  std::vector<double> normal_force_magnitude, overlap;
  std::size_t size() const { return id.size(); }
};

struct WallContacts {
  std::vector<GlobalId> id;
  std::vector<int> wall;
  std::vector<Vec3> ends;  // 2 per contact
  std::vector<Vec3> point, normal_force, tangential_force;
  std::vector<double> normal_force_magnitude, overlap;
  std::size_t size() const { return id.size(); }
};

struct ContactNetwork {
  PairContacts pairs;
  WallContacts walls;
  void clear() {
    pairs = {};
    walls = {};
  }
};

}  // namespace grainflow
