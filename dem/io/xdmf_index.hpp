#pragma once
// XDMF index of a snapshot series: a small XML file that ParaView's "XDMF Reader" opens as a
// time series of particle point clouds, while the per-particle arrays stay in the HDF5 files.
// Format: XDMF 2 (https://www.xdmf.org/index.php/Xdmf2_Model_and_Format_Archive). A
// Polyvertex topology without a connectivity DataItem gets the default connectivity 0..N-1
// (Xdmf2 XdmfTopology::Update), i.e. one vertex cell per particle. Each time step is a
// Spatial collection of that grid named "particles" (absent when the snapshot holds no
// particle) and, with a contact network (output.contacts), the network's Polyline grids
// (render_contact_grids).
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
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

// The first eight are the default set (and temperature when heat is on); the others are
// written when the scene's `output.fields` asks for them (docs/scene-reference.md).
inline constexpr std::array<SnapshotField, 16> snapshot_fields{{
    {"id", 1, SnapshotField::Type::Int64, "1"},
    {"position", 3, SnapshotField::Type::Float64, "m"},
    {"velocity", 3, SnapshotField::Type::Float64, "m/s"},
    {"angular_velocity", 3, SnapshotField::Type::Float64, "rad/s"},
    {"radius", 1, SnapshotField::Type::Float64, "m"},
    {"diameter", 1, SnapshotField::Type::Float64, "m"},
    {"mass", 1, SnapshotField::Type::Float64, "kg"},
    {"material", 1, SnapshotField::Type::Int32, "1"},
    {"force", 3, SnapshotField::Type::Float64, "N"},
    {"torque", 3, SnapshotField::Type::Float64, "N m"},
    {"coordination", 1, SnapshotField::Type::Int32, "1"},
    {"fluid_force", 3, SnapshotField::Type::Float64, "N"},
    {"overlap_max", 1, SnapshotField::Type::Float64, "1"},
    {"temperature", 1, SnapshotField::Type::Float64, "K"},  // heat on (written by default then)
    // Coarse graining (docs/models/coarse-graining.md; written by default when a scene has
    // parcels): the factor k and the real particles k^3 a particle stands for.
    {"coarse_grain", 1, SnapshotField::Type::Float64, "1"},
    {"real_count", 1, SnapshotField::Type::Float64, "1"},
}};

// A set of snapshot fields: bit k stands for snapshot_fields[k].
using SnapshotFieldSet = std::uint32_t;

// The bit of the field called `name`, or 0 when no field has that name.
constexpr SnapshotFieldSet snapshot_field_bit(std::string_view name) {
  for (std::size_t k = 0; k < snapshot_fields.size(); ++k)
    if (name == snapshot_fields[k].name) return SnapshotFieldSet{1} << k;
  return 0;
}

// What every snapshot holds: id and position (the XDMF geometry needs them).
inline constexpr SnapshotFieldSet snapshot_required_fields =
    snapshot_field_bit("id") | snapshot_field_bit("position");
// The set written when the scene does not give `output.fields`.
inline constexpr SnapshotFieldSet snapshot_default_fields = (SnapshotFieldSet{1} << 8) - 1;

// The field XDMF uses as the points' coordinates; every other field becomes an Attribute.
inline constexpr const char* snapshot_geometry_field = "position";

struct XdmfEntry {
  std::string file;  // HDF5 file name relative to the index's directory
  double time;       // [s]
  long step;
  long count;  // global number of particles in the file
  SnapshotFieldSet fields = snapshot_default_fields;  // the datasets the file holds
  // The contact network's global counts (contact_network.hpp): particle pairs and wall
  // contacts; -1 when the file holds no network.
  long contacts = -1;
  long wall_contacts = -1;
};

// The contact network of one entry as XDMF grids, for a Spatial collection of the entry's
// time: one Uniform Polyline grid per group (/contacts, /wall_contacts), one line of 2 nodes
// per contact (its `ends`), every other dataset a Cell attribute (the pairs' ids as `id_a`
// and `id_b`, HyperSlabs of the M x 2 dataset); a group without contacts
// has no grid. Each line of the result starts with `indent`; empty when the entry holds no
// network.
std::string render_contact_grids(const XdmfEntry& entry, const std::string& indent);

// The complete index for `entries` (in the order given), as one Temporal Collection named
// `series_name` of Spatial collections, one per time step (render_xdmf_entry); each
// particles grid lists the fields its file holds.
// It is render_xdmf_head + render_xdmf_entry of each entry + render_xdmf_tail; the index file
// (xdmf_index_file.hpp) appends one rendered entry at a time between the grids and the tail.
std::string render_xdmf(const std::vector<XdmfEntry>& entries, const std::string& series_name);

// Up to and including the opening tag of the Temporal Collection.
std::string render_xdmf_head(const std::string& series_name);
// Everything the index says about one snapshot: the elements of one time step, complete (they
// contain no "?>", which the append relies on: xdmf_index_file.cpp).
std::string render_xdmf_entry(const XdmfEntry& entry);
// The closing tags of the collection, the domain and the document.
std::string render_xdmf_tail();

// Replaces `path` by `content` atomically: writes `path`.tmp in the same directory, flushes it
// to disk, then renames it over `path`, so neither a reader nor a killed run ever sees a
// half-written file. Throws OutputError naming the path and the OS reason.
void write_file_atomically(const std::string& path, const std::string& content);

}  // namespace grainflow
