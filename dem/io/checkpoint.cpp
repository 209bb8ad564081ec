#include "dem/io/checkpoint.hpp"

#include <hdf5.h>

#include <bit>
#include <cstdio>
#include <filesystem>

#include "dem/io/direct_write_driver.hpp"
#include "dem/io/hdf5_attributes.hpp"
#include "dem/io/hdf5_checksum.hpp"
#include "dem/io/hdf5_errors.hpp"

namespace grainflow {
namespace {

// Format 2 added the group 'streams', format 3 the group 'decomposition'; files of the
// earlier formats are read (without them).
constexpr const char* kFormat = "grainflow-checkpoint-3";
constexpr const char* kCutNames[3] = {"cuts_x", "cuts_y", "cuts_z"};

// Packs per-particle and per-spring records into doubles (ids bit-exact).
std::vector<double> pack(const CheckpointData& d) {
  std::vector<double> b;
  const bool drag = !d.drag_coefficient.empty();
  b.push_back(static_cast<double>(d.particles.size()));
  b.push_back((drag ? 1.0 : 0.0) + (d.has_temperature ? 2.0 : 0.0));  // flags
  for (std::size_t i = 0; i < d.particles.size(); ++i) {
    const Particles& p = d.particles;
    b.push_back(std::bit_cast<double>(p.id[i]));
    for (const Vec3* v : {&p.x[i], &p.v[i], &p.omega[i], &p.force[i], &p.torque[i]})
      b.insert(b.end(), v->data(), v->data() + 3);
    b.insert(b.end(), {p.radius[i], p.mass[i], p.inertia[i], static_cast<double>(p.material[i])});
    if (d.has_temperature) b.push_back(p.temperature[i]);
    if (drag) {
      b.push_back(d.drag_coefficient[i]);
      b.insert(b.end(), d.drag_fluid_velocity[i].data(), d.drag_fluid_velocity[i].data() + 3);
    }
  }
  for (const CheckpointSpring& s : d.springs) {
    b.push_back(std::bit_cast<double>(s.particle));
    b.push_back(std::bit_cast<double>(s.partner));
    b.insert(b.end(), s.tangential.data(), s.tangential.data() + 3);
    b.insert(b.end(), s.rolling.data(), s.rolling.data() + 3);
  }
  return b;
}

// The file's size: the data plus HDF5's metadata, about 3 kB per checksummed dataset
// (measured: 4000 particles without springs take 658 758 bytes, 624 000 of them data).
std::uintmax_t expected_bytes(const CheckpointData& d) {
  const std::uintmax_t n = d.particles.size(), per_particle = 8 + 5 * 24 + 3 * 8 + 4;
  const std::uintmax_t drag =
      (d.drag_coefficient.empty() ? 0 : 32) + (d.has_temperature ? 8 : 0);
  const std::uintmax_t streams = (d.streams ? d.streams->size() : 0) +
                                 (d.insertions ? d.insertions->size() : 0) +
                                 (d.log ? d.log->size() : 0) + (d.model ? d.model->size() : 0);
  std::uintmax_t grid = 0;
  if (d.grid)
    for (const auto& c : d.grid->cuts) grid += 8 * c.size();
  return n * (per_particle + drag) + d.springs.size() * (2 * 8 + 2 * 24) + streams + grid +
         23 * 3072 + 8192;
}

// Appends the records of one rank's buffer to `out`.
void unpack(const double* b, std::size_t n, CheckpointData& out) {
  std::size_t k = 0;
  const auto count = static_cast<std::size_t>(b[k++]);
  const int flags = static_cast<int>(b[k++]);
  const bool drag = (flags & 1) != 0, temperature = (flags & 2) != 0;
  if (temperature) out.has_temperature = true;
  auto vec = [&] {
    const Vec3 v(b[k], b[k + 1], b[k + 2]);
    k += 3;
    return v;
  };
  for (std::size_t i = 0; i < count; ++i) {
    const GlobalId id = std::bit_cast<GlobalId>(b[k++]);
    const Vec3 x = vec(), v = vec(), w = vec(), f = vec(), t = vec();
    const double r = b[k], m = b[k + 1], inertia = b[k + 2];
    const int mat = static_cast<int>(b[k + 3]);
    k += 4;
    out.particles.add_raw(id, x, v, w, r, m, inertia, mat);
    out.particles.force.back() = f;
    out.particles.torque.back() = t;
    if (temperature) out.particles.temperature.back() = b[k++];
    if (drag) {
      out.drag_coefficient.push_back(b[k++]);
      out.drag_fluid_velocity.push_back(vec());
    }
  }
  while (k < n) {
    CheckpointSpring s;
    s.particle = std::bit_cast<GlobalId>(b[k++]);
    s.partner = std::bit_cast<GlobalId>(b[k++]);
    s.tangential = vec();
    s.rolling = vec();
    out.springs.push_back(s);
  }
}

class File {
 public:
  explicit File(hid_t id) : id_(id) {}
  ~File() {
    if (id_ >= 0) H5Fclose(id_);
  }
  hid_t id() const { return id_; }
  bool close() {
    const bool ok = H5Fclose(id_) >= 0;
    id_ = -1;
    return ok;
  }

 private:
  hid_t id_;
};

// The first failure of a file write, with HDF5's reason. That reason must be read right after
// the failing call: every later HDF5 call (closing a dataset included) starts a new error stack.
class FirstFailure {
 public:
  // Right after a failed HDF5 call, before any other.
  void capture() {
    if (reason_.empty()) reason_ = hdf5_reason();
  }
  bool check(bool ok, const std::string& what) {
    if (!ok && error_.empty()) {
      capture();
      error_ = what + " failed: " + reason_;
    }
    return ok;
  }
  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }

 private:
  std::string reason_;
  std::string error_;
};

bool write_array(FirstFailure& fail, hid_t loc, const char* name, hid_t type, std::size_t rows,
                 std::size_t cols, const void* data) {
  const hsize_t dims[2] = {rows, cols};
  const int rank = cols > 1 ? 2 : 1;
  const hid_t space = H5Screate_simple(rank, dims, nullptr);
  const hid_t dcpl = checksummed_layout(rank, dims, H5Tget_size(type));
  const hid_t set =
      dcpl < 0 ? -1 : H5Dcreate2(loc, name, type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  // The dataset's type is the memory's: each chunk goes out with its checksum directly
  // (hdf5_checksum.hpp), the same file as through HDF5's filter.
  bool ok = set >= 0 && (rows == 0 || write_checksummed(set, rank, dims, H5Tget_size(type), data));
  if (!ok) fail.capture();
  if (set >= 0) H5Dclose(set);
  if (dcpl >= 0) H5Pclose(dcpl);
  H5Sclose(space);
  return ok;
}

template <class T>
bool write_attribute(FirstFailure& fail, hid_t loc, const char* name, hid_t type, const T& value) {
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t attr = H5Acreate2(loc, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  const bool ok = attr >= 0 && H5Awrite(attr, type, &value) >= 0;
  if (!ok) fail.capture();
  if (attr >= 0) H5Aclose(attr);
  H5Sclose(space);
  return ok;
}

std::string write_file(const std::string& path, const CheckpointData& d) {
  const Particles& p = d.particles;
  const std::size_t n = p.size(), m = d.springs.size();
  FirstFailure fail;
  if (!d.drag_coefficient.empty() &&
      (d.drag_coefficient.size() != n || d.drag_fluid_velocity.size() != n))
    return "the ranks disagree on whether particles have an implicit drag (" +
           std::to_string(d.drag_coefficient.size()) + " drag entries for " + std::to_string(n) +
           " particles)";
  // Large writes around the page cache (direct_write_driver.hpp): the same file, faster on
  // machines where fresh page-cache pages are slow to come by.
  const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  if (!fail.check(fapl >= 0 && set_direct_write_driver(fapl),
                  "choosing how '" + path + "' is written")) {
    if (fapl >= 0) H5Pclose(fapl);
    return fail.error();
  }
  File f(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl));
  const bool created = fail.check(f.id() >= 0, "creating '" + path + "'");
  if (fapl >= 0) H5Pclose(fapl);  // after the check: any HDF5 call clears the error stack
  if (!created) return fail.error();
  const hid_t str = H5Tcopy(H5T_C_S1);
  H5Tset_size(str, std::char_traits<char>::length(kFormat));
  {
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t attr = H5Acreate2(f.id(), "format", str, space, H5P_DEFAULT, H5P_DEFAULT);
    const bool written = attr >= 0 && H5Awrite(attr, str, kFormat) >= 0;
    if (!written) fail.capture();
    if (attr >= 0) H5Aclose(attr);
    fail.check(written, "writing the attribute 'format'");
    H5Sclose(space);
  }
  H5Tclose(str);
  const long long step = d.step, next = d.next_id, rebuilds = d.rebuilds;
  fail.check(fail.ok() && write_attribute(fail, f.id(), "time", H5T_NATIVE_DOUBLE, d.time) &&
                 write_attribute(fail, f.id(), "dt", H5T_NATIVE_DOUBLE, d.dt) &&
                 write_attribute(fail, f.id(), "step", H5T_NATIVE_LLONG, step) &&
                 write_attribute(fail, f.id(), "next_id", H5T_NATIVE_LLONG, next) &&
                 write_attribute(fail, f.id(), "rebuilds", H5T_NATIVE_LLONG, rebuilds),
             "writing the attributes time, dt, step, next_id, rebuilds");
  if (fail.ok() && !d.material_coarse_grain.empty()) {
    const std::vector<long long> real(d.material_real.begin(), d.material_real.end());
    const std::size_t materials = d.material_coarse_grain.size();
    const bool written =
        write_array_attribute(f.id(), "material_coarse_grain", H5T_NATIVE_DOUBLE, H5T_NATIVE_DOUBLE,
                              materials, d.material_coarse_grain.data()) &&
        write_array_attribute(f.id(), "material_real", H5T_NATIVE_LLONG, H5T_NATIVE_LLONG,
                              materials, real.data());
    if (!written) fail.capture();
    fail.check(written, "writing the attributes material_coarse_grain, material_real");
  }
  if (fail.ok() && !d.wall_impulse.empty()) {
    const bool written =
        write_array_attribute(f.id(), "wall_impulse", H5T_NATIVE_DOUBLE, H5T_NATIVE_DOUBLE,
                              d.wall_impulse.size(), d.wall_impulse.data());
    if (!written) fail.capture();
    fail.check(written, "writing the attribute wall_impulse");
  }
  if (fail.ok() && d.largest_radius) {
    const long long removed = d.removed;
    fail.check(
        write_attribute(fail, f.id(), "largest_radius", H5T_NATIVE_DOUBLE, *d.largest_radius) &&
            write_attribute(fail, f.id(), "removed", H5T_NATIVE_LLONG, removed),
        "writing the attributes largest_radius, removed");
  }
  if (fail.ok() && d.skin)
    fail.check(write_attribute(fail, f.id(), "skin", H5T_NATIVE_DOUBLE, *d.skin),
               "writing the attribute skin");
  if (fail.ok() && d.rayleigh_fraction)
    fail.check(
        write_attribute(fail, f.id(), "rayleigh_fraction", H5T_NATIVE_DOUBLE, *d.rayleigh_fraction),
        "writing the attribute rayleigh_fraction");
  if (fail.ok()) {
    const std::uint32_t sum = attributes_checksum(d);
    fail.check(write_attribute(fail, f.id(), "attributes_checksum", H5T_NATIVE_UINT32, sum),
               "writing the attribute attributes_checksum");
  }
  std::vector<long long> ids(p.id.begin(), p.id.end());
  std::vector<int> mats(p.material.begin(), p.material.end());
  auto flat = [](const std::vector<Vec3>& v) {
    std::vector<double> out;
    out.reserve(3 * v.size());
    for (const Vec3& x : v) out.insert(out.end(), {x[0], x[1], x[2]});
    return out;
  };
  if (fail.ok()) {
    const hid_t g = H5Gcreate2(f.id(), "particles", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    fail.check(g >= 0 && write_array(fail, g, "id", H5T_NATIVE_LLONG, n, 1, ids.data()) &&
                   write_array(fail, g, "position", H5T_NATIVE_DOUBLE, n, 3, flat(p.x).data()) &&
                   write_array(fail, g, "velocity", H5T_NATIVE_DOUBLE, n, 3, flat(p.v).data()) &&
                   write_array(fail, g, "angular_velocity", H5T_NATIVE_DOUBLE, n, 3,
                               flat(p.omega).data()) &&
                   write_array(fail, g, "force", H5T_NATIVE_DOUBLE, n, 3, flat(p.force).data()) &&
                   write_array(fail, g, "torque", H5T_NATIVE_DOUBLE, n, 3, flat(p.torque).data()) &&
                   write_array(fail, g, "radius", H5T_NATIVE_DOUBLE, n, 1, p.radius.data()) &&
                   write_array(fail, g, "mass", H5T_NATIVE_DOUBLE, n, 1, p.mass.data()) &&
                   write_array(fail, g, "inertia", H5T_NATIVE_DOUBLE, n, 1, p.inertia.data()) &&
                   write_array(fail, g, "material", H5T_NATIVE_INT, n, 1, mats.data()),
               "writing the group 'particles'");
    if (d.has_temperature)
      fail.check(g >= 0 && write_array(fail, g, "temperature", H5T_NATIVE_DOUBLE, n, 1,
                                       p.temperature.data()),
                 "writing the temperatures in group 'particles'");
    if (!d.drag_coefficient.empty())
      fail.check(g >= 0 &&
                     write_array(fail, g, "drag_coefficient", H5T_NATIVE_DOUBLE, n, 1,
                                 d.drag_coefficient.data()) &&
                     write_array(fail, g, "drag_fluid_velocity", H5T_NATIVE_DOUBLE, n, 3,
                                 flat(d.drag_fluid_velocity).data()),
                 "writing the implicit drag in group 'particles'");
    if (g >= 0) H5Gclose(g);
  }
  std::vector<long long> a(m), b(m);
  std::vector<Vec3> t(m), r(m);
  for (std::size_t k = 0; k < m; ++k) {
    a[k] = d.springs[k].particle;
    b[k] = d.springs[k].partner;
    t[k] = d.springs[k].tangential;
    r[k] = d.springs[k].rolling;
  }
  if (fail.ok()) {
    const hid_t s = H5Gcreate2(f.id(), "springs", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    fail.check(s >= 0 && write_array(fail, s, "particle", H5T_NATIVE_LLONG, m, 1, a.data()) &&
                   write_array(fail, s, "partner", H5T_NATIVE_LLONG, m, 1, b.data()) &&
                   write_array(fail, s, "tangential", H5T_NATIVE_DOUBLE, m, 3, flat(t).data()) &&
                   write_array(fail, s, "rolling", H5T_NATIVE_DOUBLE, m, 3, flat(r).data()),
               "writing the group 'springs'");
    if (s >= 0) H5Gclose(s);
  }
  if (fail.ok() && d.streams) {
    const hid_t s = H5Gcreate2(f.id(), "streams", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    fail.check(s >= 0 && write_array(fail, s, "state", H5T_NATIVE_UCHAR, d.streams->size(), 1,
                                     d.streams->data()),
               "writing the group 'streams'");
    if (fail.ok() && d.insertions)
      fail.check(write_array(fail, s, "insertions", H5T_NATIVE_UCHAR, d.insertions->size(), 1,
                             d.insertions->data()),
                 "writing the dataset '/streams/insertions'");
    if (s >= 0) H5Gclose(s);
  }
  if (fail.ok() && d.model) {
    const hid_t s = H5Gcreate2(f.id(), "scene", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    fail.check(s >= 0 && write_array(fail, s, "model", H5T_NATIVE_UCHAR, d.model->size(), 1,
                                     d.model->data()),
               "writing the dataset '/scene/model'");
    if (s >= 0) H5Gclose(s);
  }
  if (fail.ok() && d.log) {
    const hid_t s = H5Gcreate2(f.id(), "log", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    fail.check(
        s >= 0 && write_array(fail, s, "table", H5T_NATIVE_UCHAR, d.log->size(), 1, d.log->data()),
        "writing the dataset '/log/table'");
    if (s >= 0) H5Gclose(s);
  }
  if (fail.ok() && d.grid) {
    const CheckpointGrid& grid = *d.grid;
    const hid_t s = H5Gcreate2(f.id(), "decomposition", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    bool ok = s >= 0 && write_array(fail, s, "ranks", H5T_NATIVE_INT, 1, 1, &grid.ranks) &&
              write_array(fail, s, "dims", H5T_NATIVE_INT, 3, 1, grid.dims.data());
    for (int axis = 0; axis < 3 && ok; ++axis)
      ok = write_array(fail, s, kCutNames[axis], H5T_NATIVE_DOUBLE, grid.cuts[axis].size(), 1,
                       grid.cuts[axis].data());
    fail.check(ok, "writing the group 'decomposition'");
    if (s >= 0) H5Gclose(s);
  }
  // Closing flushes HDF5's metadata cache: on a full disk this is often where it fails.
  fail.check(f.close(), "closing (flushing) the file");
  return fail.error();
}

// `name` is the dataset's full path (/particles/velocity), for messages.
template <class T>
std::vector<T> read_array(hid_t file, const char* name, hid_t type, std::size_t cols,
                          std::size_t& rows, std::string& error, bool sealed) {
  std::vector<T> out;
  if (!error.empty()) return out;
  const hid_t set = H5Dopen2(file, name, H5P_DEFAULT);
  if (set < 0) {
    error = std::string("dataset '") + name + "' is missing";
    return out;
  }
  const hid_t space = H5Dget_space(set);
  hsize_t dims[2] = {0, 0};
  const int rank = H5Sget_simple_extent_dims(space, dims, nullptr);
  if (rank < 1 || (cols > 1 && (rank != 2 || dims[1] != cols)) || (cols == 1 && rank != 1)) {
    error = std::string("dataset '") + name + "' has the wrong shape";
  } else if (rows != static_cast<std::size_t>(-1) && dims[0] != rows) {
    error = std::string("dataset '") + name + "' has " + std::to_string(dims[0]) +
            " rows, expected " + std::to_string(rows);
  } else {
    rows = dims[0];
    out.resize(rows * cols);
    if (rows > 0 && H5Dread(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0) {
      error = std::string("dataset '") + name + "' cannot be read: " + read_failure_reason();
    } else if (rows > 0) {
      const std::string unverified = verify_stored(set, type, out.data(), sealed);
      if (!unverified.empty())
        error = std::string("dataset '") + name + "' cannot be read: " + unverified +
                ": the file was changed or damaged after it was written";
    }
  }
  H5Sclose(space);
  H5Dclose(set);
  return out;
}

}  // namespace

void write_checkpoint(MPI_Comm comm, const std::string& path, const CheckpointData& local) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const std::vector<double> mine = pack(local);
  int count = static_cast<int>(mine.size());
  std::vector<int> counts(size), displs(size);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  std::vector<double> all;
  if (rank == 0) {
    long total = 0;
    for (int r = 0; r < size; ++r) {
      displs[r] = static_cast<int>(total);
      total += counts[r];
    }
    all.resize(total);
  }
  MPI_Gatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), displs.data(),
              MPI_DOUBLE, 0, comm);
  std::string error;
  if (rank == 0) {
    CheckpointData d;
    d.time = local.time;
    d.dt = local.dt;
    d.step = local.step;
    d.next_id = local.next_id;
    d.rebuilds = local.rebuilds;
    d.largest_radius = local.largest_radius;
    d.skin = local.skin;
    d.rayleigh_fraction = local.rayleigh_fraction;
    d.removed = local.removed;
    d.streams = local.streams;
    d.insertions = local.insertions;
    d.log = local.log;
    d.model = local.model;
    d.grid = local.grid;
    d.material_coarse_grain = local.material_coarse_grain;
    d.material_real = local.material_real;
    d.wall_impulse = local.wall_impulse;
    for (int r = 0; r < size; ++r) unpack(all.data() + displs[r], counts[r], d);
    const std::string part = path + ".part";
    // A foreseeable full disk is refused before HDF5 starts: a checksummed (chunked) file
    // whose final flush fails leaves HDF5 unable to close it, and the library's clean-up at
    // exit then crashed (measured: exit 139 after the message).
    const std::string parent = std::filesystem::path(path).parent_path().string();
    error = no_space_note(parent.empty() ? "." : parent, expected_bytes(d));
    if (error.empty()) {
      const QuietHdf5Errors quiet;
      error = write_file(part, d);
    }
    std::error_code ec;
    if (error.empty()) std::filesystem::rename(part, path, ec);
    if (error.empty() && ec) error = "cannot rename " + part + ": " + ec.message();
    if (!error.empty()) std::filesystem::remove(part, ec);
  }
  int length = static_cast<int>(error.size());
  MPI_Bcast(&length, 1, MPI_INT, 0, comm);
  error.resize(length);
  MPI_Bcast(error.data(), length, MPI_CHAR, 0, comm);
  if (!error.empty())
    throw OutputError("cannot write checkpoint '" + path + "': " + error +
                      "; its partial file was deleted and no earlier checkpoint was touched");
}

namespace {

// The text dataset `name` ("/group/set") of the checkpoint at `path`; empty when the file
// cannot be read or holds no such dataset.
std::optional<std::string> read_checkpoint_text(const std::string& path, const char* group,
                                                const char* name) {
  const QuietHdf5Errors quiet;
  const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return std::nullopt;
  std::optional<std::string> out;
  if (H5Lexists(f, group, H5P_DEFAULT) > 0 && H5Lexists(f, name, H5P_DEFAULT) > 0) {
    const hid_t set = H5Dopen2(f, name, H5P_DEFAULT);
    const hid_t space = set >= 0 ? H5Dget_space(set) : -1;
    const hssize_t n = space >= 0 ? H5Sget_simple_extent_npoints(space) : -1;
    if (n >= 0) {
      std::string text(static_cast<std::size_t>(n), '\0');
      if (n == 0 || H5Dread(set, H5T_NATIVE_UCHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, text.data()) >= 0)
        out = std::move(text);
    }
    if (space >= 0) H5Sclose(space);
    if (set >= 0) H5Dclose(set);
  }
  H5Fclose(f);
  return out;
}

}  // namespace

bool is_particle_snapshot(const std::string& path) {
  const QuietHdf5Errors quiet;
  const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return false;
  const bool snapshot = H5Aexists(f, "format") <= 0 && H5Lexists(f, "position", H5P_DEFAULT) > 0;
  H5Fclose(f);
  return snapshot;
}

std::optional<std::string> read_checkpoint_insertions(const std::string& path) {
  return read_checkpoint_text(path, "streams", "/streams/insertions");
}

std::optional<std::string> read_checkpoint_model(const std::string& path) {
  return read_checkpoint_text(path, "scene", "/scene/model");
}

std::uint32_t attributes_checksum(const CheckpointData& d) {
  std::vector<unsigned char> bytes;
  const auto put = [&bytes](auto value) {  // a double or a 64-bit integer, little-endian
    const auto raw = std::bit_cast<std::uint64_t>(value);
    for (int b = 0; b < 8; ++b) bytes.push_back(static_cast<unsigned char>(raw >> (8 * b)));
  };
  put(d.time);
  put(d.dt);
  put(static_cast<std::int64_t>(d.step));
  put(static_cast<std::int64_t>(d.next_id));
  put(static_cast<std::int64_t>(d.rebuilds));
  put(static_cast<std::int64_t>(d.material_coarse_grain.size()));
  for (double k : d.material_coarse_grain) put(k);
  for (int real : d.material_real) put(static_cast<std::int64_t>(real));
  put(static_cast<std::int64_t>(d.wall_impulse.size()));
  for (double j : d.wall_impulse) put(j);
  if (d.largest_radius) {
    put(*d.largest_radius);
    put(static_cast<std::int64_t>(d.removed));
  }
  if (d.skin) put(*d.skin);
  if (d.rayleigh_fraction) put(*d.rayleigh_fraction);
  return fletcher32(bytes.data(), bytes.size());
}

CheckpointData read_checkpoint(const std::string& path) {
  H5E_auto2_t old_func;
  void* old_data;
  H5Eget_auto2(H5E_DEFAULT, &old_func, &old_data);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  CheckpointData d;
  std::string error;
  const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) {
    error = "cannot open it as an HDF5 file";
  } else {
    auto attr = [&](const char* name, hid_t type, void* out) {
      if (!error.empty()) return;
      const hid_t a = H5Aopen(f, name, H5P_DEFAULT);
      if (a < 0 || H5Aread(a, type, out) < 0) error = std::string("attribute '") + name + "' is missing";
      if (a >= 0) H5Aclose(a);
    };
    long long step = 0, next = 1;
    if (H5Aexists(f, "format") <= 0 && H5Lexists(f, "position", H5P_DEFAULT) > 0)
      error =
          "it is a particle snapshot, not a checkpoint; a restart needs a "
          "checkpoint_<step>.h5 (output.checkpoint_interval), and a new run starts from a "
          "snapshot with the insertion `type: snapshot`";
    attr("time", H5T_NATIVE_DOUBLE, &d.time);
    attr("dt", H5T_NATIVE_DOUBLE, &d.dt);
    attr("step", H5T_NATIVE_LLONG, &step);
    attr("next_id", H5T_NATIVE_LLONG, &next);
    d.step = step;
    d.next_id = next;
    if (error.empty() && H5Aexists(f, "format") <= 0) error = "it is not a grainflow checkpoint";
    // Optional (written since restarts continue parallel.balance's pacing).
    if (error.empty() && H5Aexists(f, "rebuilds") > 0) {
      long long rebuilds = 0;
      attr("rebuilds", H5T_NATIVE_LLONG, &rebuilds);
      if (error.empty() && rebuilds < 0)
        error = "attribute 'rebuilds' is negative (" + std::to_string(rebuilds) + ")";
      d.rebuilds = static_cast<long>(rebuilds);
    }
    // Optional (written since restarts keep the interaction range and the removed count);
    // the values are checked by check_checkpoint.
    if (error.empty() && H5Aexists(f, "largest_radius") > 0) {
      double r = 0;
      long long removed = 0;
      attr("largest_radius", H5T_NATIVE_DOUBLE, &r);
      attr("removed", H5T_NATIVE_LLONG, &removed);
      d.largest_radius = r;
      d.removed = static_cast<long>(removed);
    }
    if (error.empty() && H5Aexists(f, "skin") > 0) {  // optional: files written before it
      double skin = 0;
      attr("skin", H5T_NATIVE_DOUBLE, &skin);
      d.skin = skin;
    }
    if (error.empty() && H5Aexists(f, "rayleigh_fraction") > 0) {  // optional, as skin
      double fraction = 0;
      attr("rayleigh_fraction", H5T_NATIVE_DOUBLE, &fraction);
      d.rayleigh_fraction = fraction;
    }
    // Optional (written since the parcel classes are checked on restart).
    if (error.empty() && !read_array_attribute(f, "material_coarse_grain", H5T_NATIVE_DOUBLE,
                                               d.material_coarse_grain))
      error = "attribute 'material_coarse_grain' cannot be read";
    if (error.empty() && !read_array_attribute(f, "material_real", H5T_NATIVE_INT, d.material_real))
      error = "attribute 'material_real' cannot be read";
    if (error.empty() && d.material_coarse_grain.size() != d.material_real.size())
      error = "attributes 'material_coarse_grain' and 'material_real' differ in length";
    if (error.empty() &&
        !read_array_attribute(f, "wall_impulse", H5T_NATIVE_DOUBLE, d.wall_impulse))
      error = "attribute 'wall_impulse' cannot be read";
    // Optional (written since the attributes carry a checksum); compared by Simulation::restore
    // after every rule, so that a value a rule refuses is named by that rule.
    if (error.empty() && H5Aexists(f, "attributes_checksum") > 0) {
      std::uint32_t stored = 0;
      attr("attributes_checksum", H5T_NATIVE_UINT32, &stored);
      d.attributes_checksum_stored = stored;
      d.attributes_checksum_read = attributes_checksum(d);
    }
    // A file written with the attributes' checksum has a Fletcher32 checksum on every
    // dataset: one without it was damaged.
    const bool sealed = d.attributes_checksum_stored.has_value();
    std::size_t n = static_cast<std::size_t>(-1), m = static_cast<std::size_t>(-1);
    if (error.empty() && H5Lexists(f, "particles", H5P_DEFAULT) <= 0)
      error = "group 'particles' is missing";
    const auto ids =
        read_array<long long>(f, "/particles/id", H5T_NATIVE_LLONG, 1, n, error, sealed);
    const auto x =
        read_array<double>(f, "/particles/position", H5T_NATIVE_DOUBLE, 3, n, error, sealed);
    const auto v =
        read_array<double>(f, "/particles/velocity", H5T_NATIVE_DOUBLE, 3, n, error, sealed);
    const auto w = read_array<double>(f, "/particles/angular_velocity", H5T_NATIVE_DOUBLE, 3, n,
                                      error, sealed);
    const auto force =
        read_array<double>(f, "/particles/force", H5T_NATIVE_DOUBLE, 3, n, error, sealed);
    const auto torque =
        read_array<double>(f, "/particles/torque", H5T_NATIVE_DOUBLE, 3, n, error, sealed);
    const auto r =
        read_array<double>(f, "/particles/radius", H5T_NATIVE_DOUBLE, 1, n, error, sealed);
    const auto mass =
        read_array<double>(f, "/particles/mass", H5T_NATIVE_DOUBLE, 1, n, error, sealed);
    const auto inertia =
        read_array<double>(f, "/particles/inertia", H5T_NATIVE_DOUBLE, 1, n, error, sealed);
    const auto mat = read_array<int>(f, "/particles/material", H5T_NATIVE_INT, 1, n, error, sealed);
    // Optional: present when the run had fluid forces.
    const bool has_drag =
        error.empty() && H5Lexists(f, "/particles/drag_coefficient", H5P_DEFAULT) > 0;
    // Optional: present when the run had heat transfer.
    d.has_temperature =
        error.empty() && H5Lexists(f, "/particles/temperature", H5P_DEFAULT) > 0;
    std::vector<double> temperature;
    if (d.has_temperature)
      temperature =
          read_array<double>(f, "/particles/temperature", H5T_NATIVE_DOUBLE, 1, n, error, sealed);
    std::vector<double> drag_k, drag_u;
    if (has_drag) {
      drag_k = read_array<double>(f, "/particles/drag_coefficient", H5T_NATIVE_DOUBLE, 1, n, error,
                                  sealed);
      drag_u = read_array<double>(f, "/particles/drag_fluid_velocity", H5T_NATIVE_DOUBLE, 3, n,
                                  error, sealed);
    }
    if (error.empty() && H5Lexists(f, "springs", H5P_DEFAULT) <= 0)
      error = "group 'springs' is missing";
    const auto a =
        read_array<long long>(f, "/springs/particle", H5T_NATIVE_LLONG, 1, m, error, sealed);
    const auto b =
        read_array<long long>(f, "/springs/partner", H5T_NATIVE_LLONG, 1, m, error, sealed);
    const auto t =
        read_array<double>(f, "/springs/tangential", H5T_NATIVE_DOUBLE, 3, m, error, sealed);
    const auto ro =
        read_array<double>(f, "/springs/rolling", H5T_NATIVE_DOUBLE, 3, m, error, sealed);
    if (error.empty() && H5Lexists(f, "streams", H5P_DEFAULT) > 0) {
      std::size_t length = static_cast<std::size_t>(-1);
      const auto text = read_array<unsigned char>(f, "/streams/state", H5T_NATIVE_UCHAR, 1, length,
                                                  error, sealed);
      if (error.empty()) d.streams = std::string(text.begin(), text.end());
      // Optional (written since restarts compare the scene's insertions with the run's).
      if (error.empty() && H5Lexists(f, "/streams/insertions", H5P_DEFAULT) > 0) {
        std::size_t chars = static_cast<std::size_t>(-1);
        const auto record = read_array<unsigned char>(f, "/streams/insertions", H5T_NATIVE_UCHAR, 1,
                                                      chars, error, sealed);
        if (error.empty()) d.insertions = std::string(record.begin(), record.end());
      }
    }
    // Optional (written since restarts compare the scene's model with the run's).
    if (error.empty() && H5Lexists(f, "scene", H5P_DEFAULT) > 0) {
      std::size_t chars = static_cast<std::size_t>(-1);
      const auto model =
          read_array<unsigned char>(f, "/scene/model", H5T_NATIVE_UCHAR, 1, chars, error, sealed);
      if (error.empty()) d.model = std::string(model.begin(), model.end());
    }
    // Optional (written since the checkpoint keeps the run's log).
    if (error.empty() && H5Lexists(f, "log", H5P_DEFAULT) > 0) {
      std::size_t chars = static_cast<std::size_t>(-1);
      const auto table =
          read_array<unsigned char>(f, "/log/table", H5T_NATIVE_UCHAR, 1, chars, error, sealed);
      if (error.empty()) d.log = std::string(table.begin(), table.end());
    }
    // Optional (format 3): the shapes here, the values in check_checkpoint.
    if (error.empty() && H5Lexists(f, "decomposition", H5P_DEFAULT) > 0) {
      CheckpointGrid grid;
      std::size_t one = 1, three = 3;
      const auto ranks =
          read_array<int>(f, "/decomposition/ranks", H5T_NATIVE_INT, 1, one, error, sealed);
      const auto dims =
          read_array<int>(f, "/decomposition/dims", H5T_NATIVE_INT, 1, three, error, sealed);
      for (int axis = 0; axis < 3; ++axis) {
        std::size_t planes = static_cast<std::size_t>(-1);
        const std::string name = std::string("/decomposition/") + kCutNames[axis];
        grid.cuts[axis] =
            read_array<double>(f, name.c_str(), H5T_NATIVE_DOUBLE, 1, planes, error, sealed);
      }
      if (error.empty()) {
        grid.ranks = ranks[0];
        for (int axis = 0; axis < 3; ++axis) grid.dims[axis] = dims[axis];
        d.grid = std::move(grid);
      }
    }
    H5Fclose(f);
    if (error.empty()) {
      for (std::size_t i = 0; i < n; ++i) {
        d.particles.add_raw(ids[i], Vec3(x[3 * i], x[3 * i + 1], x[3 * i + 2]),
                            Vec3(v[3 * i], v[3 * i + 1], v[3 * i + 2]),
                            Vec3(w[3 * i], w[3 * i + 1], w[3 * i + 2]), r[i], mass[i], inertia[i],
                            mat[i]);
        d.particles.force.back() = Vec3(force[3 * i], force[3 * i + 1], force[3 * i + 2]);
        d.particles.torque.back() = Vec3(torque[3 * i], torque[3 * i + 1], torque[3 * i + 2]);
        if (d.has_temperature) d.particles.temperature.back() = temperature[i];
        if (has_drag) {
          d.drag_coefficient.push_back(drag_k[i]);
          d.drag_fluid_velocity.emplace_back(drag_u[3 * i], drag_u[3 * i + 1], drag_u[3 * i + 2]);
        }
      }
      for (std::size_t k = 0; k < m; ++k)
        d.springs.push_back({a[k], b[k], Vec3(t[3 * k], t[3 * k + 1], t[3 * k + 2]),
                             Vec3(ro[3 * k], ro[3 * k + 1], ro[3 * k + 2])});
    }
  }
  H5Eset_auto2(H5E_DEFAULT, old_func, old_data);
  if (!error.empty()) throw OutputError("cannot read checkpoint '" + path + "': " + error);
  d.file = path;
  return d;
}

}  // namespace grainflow
