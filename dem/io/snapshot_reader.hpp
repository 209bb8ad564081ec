#pragma once
// Reading one grainflow HDF5 snapshot (the layout of snapshot_writer.hpp) back into
// particles, e.g. to continue a packed bed in a new scene. Serial read: every rank
// that calls it reads the whole file.
#include <stdexcept>
#include <string>
#include <vector>

#include "dem/core/particles.hpp"

namespace grainflow {

// A snapshot that cannot be read; the message names the file and the dataset.
class SnapshotReadError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};
// A grainflow snapshot whose data cannot be read back as written (a Fletcher32 checksum
// that does not match, a damaged chunk).
class SnapshotDamagedError : public SnapshotReadError {
  using SnapshotReadError::SnapshotReadError;
};

// A grainflow snapshot without a dataset a snapshot insertion needs (material, radius or
// diameter): the writing scene's output.fields left it out.
class SnapshotFieldsError : public SnapshotReadError {
  using SnapshotReadError::SnapshotReadError;
};

// The values are not checked here: insert_particles checks them (restored_state.hpp).
struct Snapshot {
  Particles particles;  // id, x, v, omega, radius, mass, material; inertia = 2/5 m r^2
  double time = 0;
  // Fields the writing scene may have left out (output.fields): absent velocities read as
  // zero, an absent mass as 0 (and the inertia with it) for the caller to set.
  bool has_velocity = true;
  bool has_angular_velocity = true;
  bool has_mass = true;
  bool has_temperature = false;  // the file holds temperatures (else particles' are 0)
  std::vector<double> coarse_grain;  // each particle's k, when the file has the dataset
  // The writing scene's material names by index (root attribute material_names); empty for
  // a file written before snapshots carried them.
  std::vector<std::string> material_names;
};

Snapshot read_snapshot(const std::string& path);

// The parcel classes of the scene that wrote a snapshot (docs/models/coarse-graining.md): for
// each material index of that scene its factor k and its listed material, from the root
// attributes material_coarse_grain and material_real. Both empty for a snapshot of real
// particles, and for one written before snapshots carried the classes: then
// `parcels_without_classes` tells whether its coarse_grain dataset holds a k != 1. Throws
// SnapshotReadError when the file cannot be opened or the attributes disagree in length.
struct SnapshotClasses {
  std::vector<double> k;
  std::vector<int> real;
  // Every material's name by index (root attribute material_names; empty for a file written
  // before snapshots carried them).
  std::vector<std::string> names;
  bool parcels_without_classes = false;
};
SnapshotClasses read_snapshot_classes(const std::string& path);

}  // namespace grainflow
