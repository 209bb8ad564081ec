#pragma once
// XDMF index of a snapshot series: a small XML file that ParaView's "XDMF Reader" opens as a
// time series of particle point clouds, while the per-particle arrays stay in the HDF5 files.
// Format: XDMF 2 (https://www.xdmf.org/index.php/Xdmf2_Model_and_Format_Archive). A
// Polyvertex topology without a connectivity DataItem gets the default connectivity 0..N-1
// (Xdmf2 XdmfTopology::Update), i.e. one vertex cell per particle.
#include <array>
#include <string>
#include <vector>

namespace grainflow {

// One dataset of a snapshot file. This table is the single description of the file layout,
// shared by SnapshotWriter (what it writes) and the index (what it announces).
struct SnapshotField {
  enum class Type { Float64, Int64, Int32 };
  const char* name;  // dataset path below the root group
  int components;    // 1: shape (N), 3: shape (N, 3)
  Type type;
  const char* units;  // stored as the dataset's "units" attribute
};

inline constexpr std::array<SnapshotField, 8> snapshot_fields{{
    {"id", 1, SnapshotField::Type::Int64, "1"},
    {"position", 3, SnapshotField::Type::Float64, "m"},
    {"velocity", 3, SnapshotField::Type::Float64, "m/s"},
    {"angular_velocity", 3, SnapshotField::Type::Float64, "rad/s"},
    {"radius", 1, SnapshotField::Type::Float64, "m"},
    {"diameter", 1, SnapshotField::Type::Float64, "m"},
    {"mass", 1, SnapshotField::Type::Float64, "kg"},
    {"material", 1, SnapshotField::Type::Int32, "1"},
}};

// The field XDMF uses as the points' coordinates; every other field becomes an Attribute.
inline constexpr const char* snapshot_geometry_field = "position";

struct XdmfEntry {
  std::string file;  // HDF5 file name relative to the index's directory
  double time;       // [s]
  long step;
  long count;  // global number of particles in the file
};

// The complete index for `entries` (in the order given), as one Temporal Collection named
// `series_name` of Uniform Polyvertex grids.
std::string render_xdmf(const std::vector<XdmfEntry>& entries, const std::string& series_name);

// Replaces `path` by `content` atomically: writes `path`.tmp in the same directory, flushes it
// to disk, then renames it over `path`, so neither a reader nor a killed run ever sees a
// half-written file. Throws OutputError naming the path and the OS reason.
void write_file_atomically(const std::string& path, const std::string& content);

}  // namespace grainflow
