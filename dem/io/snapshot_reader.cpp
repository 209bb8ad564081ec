#include "dem/io/snapshot_reader.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "dem/io/hdf5_attributes.hpp"
#include "dem/io/hdf5_checksum.hpp"

namespace grainflow {
namespace {

// Silences HDF5's own error printing while we turn failures into messages.
class Quiet {
 public:
  Quiet() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~Quiet() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }
  Quiet(const Quiet&) = delete;
  Quiet& operator=(const Quiet&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

struct File {
  explicit File(hid_t i) : id(i) {}
  File(const File&) = delete;
  File& operator=(const File&) = delete;
  ~File() {
    if (id >= 0) H5Fclose(id);
  }
  hid_t id;
};

// Reads dataset `name` with `comps` components per particle straight into `out` (a Vec3
// holds the 3 components of one particle, any other T one); returns the count.
template <class T>
std::size_t read(hid_t file, const std::string& path, const char* name, int comps, hid_t type,
                 std::vector<T>& out) {
  const hid_t d = H5Dopen2(file, name, H5P_DEFAULT);
  if (d < 0)
    throw SnapshotReadError(path + ": error: no dataset '" + name +
                            "'; is this a grainflow snapshot (particles_NNNNNN.h5)?");
  const hid_t space = H5Dget_space(d);
  hsize_t dims[2] = {0, 0};
  const int rank = H5Sget_simple_extent_dims(space, dims, nullptr);
  H5Sclose(space);
  const bool shape_ok = comps == 1 ? rank == 1 : rank == 2 && dims[1] == hsize_t(comps);
  if (!shape_ok) {
    H5Dclose(d);
    throw SnapshotReadError(path + ": error: dataset '" + name + "' should have " +
                            std::to_string(comps) + " component(s) per particle");
  }
  static_assert(sizeof(Vec3) == 3 * sizeof(double));
  constexpr int per_element = std::is_same_v<T, Vec3> ? 3 : 1;
  out.resize(dims[0] * static_cast<std::size_t>(comps / per_element));
  const herr_t status =
      out.empty() ? 0 : H5Dread(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data());
  std::string reason = status < 0 ? read_failure_reason() : std::string();
  // A damaged chunk record reads as zeros without an error (verify_stored).
  if (status >= 0 && !out.empty()) {
    const std::string unverified = verify_stored(d, type, out.data(), false);
    if (!unverified.empty()) {
      H5Dclose(d);
      throw SnapshotDamagedError(path + ": error: cannot read dataset '" + name +
                                 "': " + unverified +
                                 ": the file was changed or damaged after it was written");
    }
  }
  H5Dclose(d);
  if (status < 0)
    throw SnapshotDamagedError(path + ": error: cannot read dataset '" + name + "': " + reason);
  return dims[0];
}

// Opens a snapshot for reading (a prvalue: no copy, one close).
File open_snapshot(const std::string& path) {
  const hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (id < 0)
    throw SnapshotReadError(path + ": error: cannot open as an HDF5 file; check the path");
  return File(id);
}

}  // namespace

namespace {
// The root attribute material_names (a fixed-length string, the names joined by commas:
// snapshot_writer.hpp), split; empty when the file has none.
std::vector<std::string> read_material_names(hid_t file, const std::string& path) {
  std::vector<std::string> names;
  if (H5Aexists(file, "material_names") <= 0) return names;
  std::string joined;
  bool read_ok = false;
  const hid_t a = H5Aopen(file, "material_names", H5P_DEFAULT);
  if (a >= 0) {
    const hid_t type = H5Aget_type(a);
    if (type >= 0 && H5Tget_class(type) == H5T_STRING && H5Tis_variable_str(type) == 0) {
      std::vector<char> text(H5Tget_size(type) + 1, '\0');
      read_ok = H5Aread(a, type, text.data()) >= 0;
      joined = text.data();
    }
    if (type >= 0) H5Tclose(type);
    H5Aclose(a);
  }
  if (!read_ok)
    throw SnapshotDamagedError(path +
                               ": error: cannot read the root attribute 'material_names' "
                               "(a fixed-length string)");
  for (std::size_t start = 0; start <= joined.size();) {
    const std::size_t comma = std::min(joined.find(',', start), joined.size());
    names.push_back(joined.substr(start, comma - start));
    start = comma + 1;
  }
  return names;
}
}  // namespace

Snapshot read_snapshot(const std::string& path) {
  Quiet quiet;
  const File f = open_snapshot(path);
  // Read straight into the particle arrays: no second copy of the file's data.
  Snapshot s;
  Particles& p = s.particles;
  static_assert(std::is_same_v<GlobalId, std::int64_t>);
  const std::size_t n = read(f.id, path, "/id", 1, H5T_NATIVE_INT64, p.id);
  // Every grainflow snapshot has /id and /position; the other datasets are fields the
  // writing scene's output.fields may leave out.
  const auto has = [&](const char* name) { return H5Lexists(f.id, name, H5P_DEFAULT) > 0; };
  const auto left_out = [&](const std::string& what) {
    return SnapshotFieldsError(
        path + ": error: " + what +
        ": the scene that wrote this snapshot left it out of output.fields, and a snapshot "
        "insertion needs it; list it there (the default fields include it) and insert from a "
        "new snapshot, or continue that run from a checkpoint (grain run --restart)");
  };
  if (!has("/material")) throw left_out("no dataset '/material' (field material)");
  if (!has("/radius") && !has("/diameter"))
    throw left_out("neither dataset '/radius' nor '/diameter' (field radius or diameter)");
  std::vector<std::size_t> counts = {read(f.id, path, "/position", 3, H5T_NATIVE_DOUBLE, p.x),
                                     read(f.id, path, "/material", 1, H5T_NATIVE_INT, p.material)};
  if (has("/radius")) {
    counts.push_back(read(f.id, path, "/radius", 1, H5T_NATIVE_DOUBLE, p.radius));
  } else {  // d = 2 r exactly, so d / 2 is the radius the writer had
    counts.push_back(read(f.id, path, "/diameter", 1, H5T_NATIVE_DOUBLE, p.radius));
    for (double& r : p.radius) r *= 0.5;
  }
  s.has_velocity = has("/velocity");
  s.has_angular_velocity = has("/angular_velocity");
  s.has_mass = has("/mass");
  if (s.has_velocity)
    counts.push_back(read(f.id, path, "/velocity", 3, H5T_NATIVE_DOUBLE, p.v));
  else
    p.v.assign(n, Vec3::Zero());
  if (s.has_angular_velocity)
    counts.push_back(read(f.id, path, "/angular_velocity", 3, H5T_NATIVE_DOUBLE, p.omega));
  else
    p.omega.assign(n, Vec3::Zero());
  if (s.has_mass)
    counts.push_back(read(f.id, path, "/mass", 1, H5T_NATIVE_DOUBLE, p.mass));
  else
    p.mass.assign(n, 0.0);  // set by the reader's caller from the materials
  for (std::size_t c : counts)
    if (c != n)
      throw SnapshotReadError(path + ": error: datasets have different particle counts (" +
                              std::to_string(n) + " ids, " + std::to_string(c) + " values)");
  if (H5Aexists(f.id, "time") > 0) {
    const hid_t a = H5Aopen(f.id, "time", H5P_DEFAULT);
    H5Aread(a, H5T_NATIVE_DOUBLE, &s.time);
    H5Aclose(a);
  }
  s.material_names = read_material_names(f.id, path);
  p.inertia.resize(n);
  for (std::size_t i = 0; i < n; ++i) p.inertia[i] = 0.4 * p.mass[i] * p.radius[i] * p.radius[i];
  p.v_pred = p.v;
  p.omega_pred = p.omega;
  p.force.assign(n, Vec3::Zero());
  p.torque.assign(n, Vec3::Zero());
  // Optional (written when heat was on): the particles' temperatures.
  s.has_temperature = H5Lexists(f.id, "/temperature", H5P_DEFAULT) > 0;
  if (s.has_temperature) {
    if (read(f.id, path, "/temperature", 1, H5T_NATIVE_DOUBLE, p.temperature) != n)
      throw SnapshotReadError(path + ": error: dataset '/temperature' has a different particle "
                              "count than '/id'");
  } else {
    p.temperature.assign(n, 0.0);
  }
  if (H5Lexists(f.id, "/coarse_grain", H5P_DEFAULT) > 0 &&
      read(f.id, path, "/coarse_grain", 1, H5T_NATIVE_DOUBLE, s.coarse_grain) != n)
    throw SnapshotReadError(path +
                            ": error: dataset '/coarse_grain' has a different particle "
                            "count than '/id'");
  return s;
}

namespace {
// A one-dimensional numeric root attribute, empty when the file has none.
template <class T>
std::vector<T> array_attribute(hid_t file, const std::string& path, const char* name, hid_t type) {
  std::vector<T> out;
  if (!read_array_attribute(file, name, type, out))
    throw SnapshotDamagedError(path + ": error: cannot read the root attribute '" + name + "'");
  return out;
}
}  // namespace

SnapshotClasses read_snapshot_classes(const std::string& path) {
  Quiet quiet;
  const File f = open_snapshot(path);
  SnapshotClasses c;
  c.k = array_attribute<double>(f.id, path, "material_coarse_grain", H5T_NATIVE_DOUBLE);
  c.real = array_attribute<int>(f.id, path, "material_real", H5T_NATIVE_INT);
  c.names = read_material_names(f.id, path);
  if (c.k.size() != c.real.size())
    throw SnapshotReadError(path + ": error: the root attributes material_coarse_grain (" +
                            std::to_string(c.k.size()) + " values) and material_real (" +
                            std::to_string(c.real.size()) +
                            " values) should hold one value per material of the scene that "
                            "wrote the snapshot");
  if (c.k.empty() && H5Lexists(f.id, "/coarse_grain", H5P_DEFAULT) > 0) {
    std::vector<double> k;
    read(f.id, path, "/coarse_grain", 1, H5T_NATIVE_DOUBLE, k);
    for (double v : k) c.parcels_without_classes |= v != 1;
  }
  return c;
}

}  // namespace grainflow
