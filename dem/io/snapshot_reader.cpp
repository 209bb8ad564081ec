#include "dem/io/snapshot_reader.hpp"

#include <hdf5.h>

#include <cmath>
#include <cstdint>
#include <vector>

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
  hid_t id;
  ~File() {
    if (id >= 0) H5Fclose(id);
  }
};

// Reads dataset `name` with `comps` components per particle; returns the count.
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
  out.resize(dims[0] * static_cast<std::size_t>(comps));
  const herr_t status =
      out.empty() ? 0 : H5Dread(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data());
  H5Dclose(d);
  if (status < 0) throw SnapshotReadError(path + ": error: cannot read dataset '" + name + "'");
  return dims[0];
}

}  // namespace

Snapshot read_snapshot(const std::string& path) {
  Quiet quiet;
  File f{H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT)};
  if (f.id < 0)
    throw SnapshotReadError(path + ": error: cannot open as an HDF5 file; check the path");
  std::vector<std::int64_t> id;
  std::vector<double> x, v, w, r, m;
  std::vector<int> mat;
  const std::size_t n = read(f.id, path, "/id", 1, H5T_NATIVE_INT64, id);
  const std::size_t counts[] = {read(f.id, path, "/position", 3, H5T_NATIVE_DOUBLE, x),
                                read(f.id, path, "/velocity", 3, H5T_NATIVE_DOUBLE, v),
                                read(f.id, path, "/angular_velocity", 3, H5T_NATIVE_DOUBLE, w),
                                read(f.id, path, "/radius", 1, H5T_NATIVE_DOUBLE, r),
                                read(f.id, path, "/mass", 1, H5T_NATIVE_DOUBLE, m),
                                read(f.id, path, "/material", 1, H5T_NATIVE_INT, mat)};
  for (std::size_t c : counts)
    if (c != n)
      throw SnapshotReadError(path + ": error: datasets have different particle counts (" +
                              std::to_string(n) + " ids, " + std::to_string(c) + " values)");
  Snapshot s;
  if (H5Aexists(f.id, "time") > 0) {
    const hid_t a = H5Aopen(f.id, "time", H5P_DEFAULT);
    H5Aread(a, H5T_NATIVE_DOUBLE, &s.time);
    H5Aclose(a);
  }
  s.particles.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 xi(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
    if (!xi.allFinite() || !(r[i] > 0) || !(m[i] > 0))
      throw SnapshotReadError(path + ": error: particle id " + std::to_string(id[i]) +
                              " has a non-finite position or a non-positive radius or mass");
    s.particles.add_raw(id[i], xi, Vec3(v[3 * i], v[3 * i + 1], v[3 * i + 2]),
                        Vec3(w[3 * i], w[3 * i + 1], w[3 * i + 2]), r[i], m[i],
                        0.4 * m[i] * r[i] * r[i], mat[i]);
  }
  return s;
}

}  // namespace grainflow
