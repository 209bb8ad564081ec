#include "dem/io/snapshot_writer.hpp"

#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <utility>
#include <vector>

#include "dem/io/direct_write_driver.hpp"
#include "dem/io/hdf5_attributes.hpp"
#include "dem/io/hdf5_checksum.hpp"
#include "dem/io/hdf5_errors.hpp"
#include "grainflow_version.hpp"

namespace grainflow {

namespace {

// Owns one HDF5 identifier and closes it on scope exit.
class Hid {
 public:
  using Closer = herr_t (*)(hid_t);
  Hid(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  ~Hid() {
    if (id_ >= 0) closer_(id_);
  }
  Hid(const Hid&) = delete;
  Hid& operator=(const Hid&) = delete;
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  // Closes now; closing a file flushes it, so its result matters.
  bool close() {
    const hid_t id = std::exchange(id_, -1);
    return id < 0 || closer_(id) >= 0;
  }

 private:
  hid_t id_;
  Closer closer_;
};

// Keeps all ranks in the same sequence of collective calls: after each stage every rank learns
// whether any rank failed, and if so all throw the lowest failing rank's message. A rank that
// gave up alone would leave the others waiting forever inside the next collective call.
class Agreement {
 public:
  // `bytes`: the file's expected size, to recognise a full disk (no_space_note).
  Agreement(MPI_Comm comm, int rank, int size, std::string path, std::uintmax_t bytes = 0)
      : comm_(comm), rank_(rank), size_(size), path_(std::move(path)), bytes_(bytes) {}

  // For HDF5 calls: the reason is read from the HDF5 error stack.
  void check(bool ok, const std::string& what) {
    agree(ok ? std::string() : message(what, hdf5_reason()));
  }
  // For a failure whose reason was read before later HDF5 calls cleared the error stack.
  void check(const std::pair<std::string, std::string>& what_and_reason) {
    const auto& [what, reason] = what_and_reason;
    agree(what.empty() ? std::string() : message(what, reason));
  }
  // For operating-system calls: the reason is errno's text.
  void check_os(bool ok, const std::string& what, int err) {
    agree(ok ? std::string() : message(what, std::strerror(err)));
  }
  // Before the file is created: the file system must have room for it (no_space_note). HDF5
  // allocates a checksummed (chunked) dataset at creation inside a collective call with a
  // barrier; a rank that fails there alone leaves the others waiting in it for ever, so a
  // foreseeable full disk is refused here, by all ranks together.
  void check_space() {
    const std::string note =
        rank_ == 0 ? no_space_note(std::filesystem::path(path_).parent_path().string(), bytes_)
                   : std::string();
    agree(note.empty() ? note
                       : "cannot write snapshot '" + path_ + "': " + note +
                             ". Check free space, quota and permissions of the output directory.");
  }
  // For failures already phrased as a full message.
  void agree(const std::string& local_message) {
    int first = local_message.empty() ? size_ : rank_;
    MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, comm_);
    if (first == size_) return;
    std::string text = local_message;
    int length = static_cast<int>(text.size());
    MPI_Bcast(&length, 1, MPI_INT, first, comm_);
    text.resize(static_cast<std::size_t>(length));
    MPI_Bcast(text.data(), length, MPI_CHAR, first, comm_);
    throw OutputError(text);
  }

 private:
  std::string message(const std::string& what, const std::string& reason) const {
    std::string where = size_ > 1 ? " on rank " + std::to_string(rank_) : "";
    const std::string full =
        no_space_note(std::filesystem::path(path_).parent_path().string(), bytes_);
    return "cannot write snapshot '" + path_ + "': " + what + " failed" + where + ": " + reason +
           (full.empty() ? "" : "; " + full) +
           ". Check free space, quota and permissions of the output directory.";
  }

  MPI_Comm comm_;
  int rank_;
  int size_;
  std::string path_;
  std::uintmax_t bytes_;
};

struct HdfTypes {
  hid_t file;
  hid_t memory;
};

HdfTypes hdf_types(SnapshotField::Type t) {
  switch (t) {
    case SnapshotField::Type::Int64:
      return {H5T_STD_I64LE, H5T_NATIVE_INT64};
    case SnapshotField::Type::Int32:
      return {H5T_STD_I32LE, H5T_NATIVE_INT};
    case SnapshotField::Type::Float64:
      break;
  }
  return {H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE};
}

constexpr const SnapshotField& field(std::string_view name) {
  for (const SnapshotField& f : snapshot_fields)
    if (name == f.name) return f;
  throw std::logic_error("unknown snapshot field");
}

// A fixed-length ASCII string attribute (h5py reads it as bytes, h5dump prints it plainly).
bool write_string_attribute(hid_t loc, const char* name, const std::string& value) {
  Hid type(H5Tcopy(H5T_C_S1), H5Tclose);
  Hid space(H5Screate(H5S_SCALAR), H5Sclose);
  if (!type.valid() || !space.valid()) return false;
  if (H5Tset_size(type.get(), value.size() + 1) < 0) return false;
  if (H5Tset_strpad(type.get(), H5T_STR_NULLTERM) < 0) return false;
  Hid attr(H5Acreate2(loc, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!attr.valid()) return false;
  if (H5Awrite(attr.get(), type.get(), value.c_str()) < 0) return false;
  return attr.close();
}

bool write_scalar_attribute(hid_t loc, const char* name, HdfTypes types, const void* value) {
  Hid space(H5Screate(H5S_SCALAR), H5Sclose);
  if (!space.valid()) return false;
  Hid attr(H5Acreate2(loc, name, types.file, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!attr.valid()) return false;
  if (H5Awrite(attr.get(), types.memory, value) < 0) return false;
  return attr.close();
}

// This rank's slice of the global arrays: elements [offset, offset + count) of N = total.
struct Slice {
  hsize_t offset;
  hsize_t count;
  hsize_t total;
};

struct OpenFile {
  hid_t file;   // -1 on the ranks that hand their data to rank 0 (gather)
  hid_t dcpl;  // dataset creation: no fill values (every element is written)
  hid_t dxpl;  // transfer: collective MPI-IO
  bool serial;  // one process writes the file through HDF5's POSIX driver (write_whole)
  // Several ranks on one node: each dataset's slices are gathered on rank 0, which writes the
  // file alone (serial is true there); the others make no HDF5 call.
  bool gather;
  MPI_Comm comm;
  bool writes() const { return file >= 0 || !gather; }
};

// A dataset of `rows` rows from `data`, written by one process: chunk by chunk with the
// checksums computed here when the memory's bytes are the file's, else through HDF5's filter.
// Returns what failed and HDF5's reason, read before the handles close (empty: nothing).
std::pair<std::string, std::string> write_whole(const OpenFile& out, const SnapshotField& f,
                                                const std::string& dset_path, hsize_t rows,
                                                const void* data) {
  const auto failed = [](std::string what) { return std::pair{what, hdf5_reason()}; };
  const int rank = f.components == 1 ? 1 : 2;
  const hsize_t dims[2] = {rows, static_cast<hsize_t>(f.components)};
  const HdfTypes types = hdf_types(f.type);
  Hid space(H5Screate_simple(rank, dims, nullptr), H5Sclose);
  Hid dcpl(H5Pcopy(out.dcpl), H5Pclose);
  if (!space.valid() || !dcpl.valid() ||
      !add_checksum(dcpl.get(), rank, dims, H5Tget_size(types.file)))
    return failed("setting the checksum of " + dset_path);
  Hid dset(H5Dcreate2(out.file, dset_path.c_str(), types.file, space.get(), H5P_DEFAULT,
                      dcpl.get(), H5P_DEFAULT),
           H5Dclose);
  if (!dset.valid()) return failed("creating dataset " + dset_path);
  if (!write_string_attribute(dset.get(), "units", f.units))
    return failed("writing the units attribute of " + dset_path);
  const bool direct = H5Tequal(types.memory, types.file) > 0;
  if (rows > 0 &&
      !(direct ? write_checksummed(dset.get(), rank, dims, H5Tget_size(types.file), data)
               : H5Dwrite(dset.get(), types.memory, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0))
    return failed("writing dataset " + dset_path);
  if (!dset.close()) return failed("closing dataset " + dset_path);
  return {};
}

// OpenFile::gather: the ranks' slices (in rank order, as their offsets are) travel to rank 0,
// which writes the whole dataset. Collective.
void write_gathered(const OpenFile& out, Agreement& agreement, const SnapshotField& f,
                    const Slice& slice, const void* data, const std::string& dset_path) {
  int ranks = 1;
  MPI_Comm_size(out.comm, &ranks);
  const std::size_t row_bytes =
      static_cast<std::size_t>(f.components) * H5Tget_size(hdf_types(f.type).memory);
  if (slice.total > static_cast<hsize_t>(std::numeric_limits<int>::max()))
    throw std::logic_error("SnapshotWriter: more than 2^31 rows gathered in one dataset");
  const int local_rows = static_cast<int>(slice.count);
  std::vector<int> counts(out.writes() ? ranks : 0), displacements(counts.size(), 0);
  MPI_Gather(&local_rows, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, out.comm);
  for (std::size_t r = 1; r < counts.size(); ++r)
    displacements[r] = displacements[r - 1] + counts[r - 1];
  std::vector<unsigned char> all(out.writes() ? slice.total * row_bytes : 0);
  MPI_Datatype row;
  MPI_Type_contiguous(static_cast<int>(row_bytes), MPI_BYTE, &row);
  MPI_Type_commit(&row);
  MPI_Gatherv(data, local_rows, row, all.data(), counts.data(), displacements.data(), row, 0,
              out.comm);
  MPI_Type_free(&row);
  agreement.check(out.writes() ? write_whole(out, f, dset_path, slice.total, all.data())
                                : std::pair<std::string, std::string>{});
}

// `group`: the group below the root holding the dataset (nullptr: the root).
void write_dataset(const OpenFile& out, Agreement& agreement, const SnapshotField& f,
                   const Slice& slice, const void* data, const char* group = nullptr) {
  const std::string dset_path = (group ? std::string("/") + group : std::string()) + "/" + f.name;
  if (out.gather) return write_gathered(out, agreement, f, slice, data, dset_path);
  // One rank: its slice is the whole dataset.
  if (out.serial) return agreement.check(write_whole(out, f, dset_path, slice.total, data));
  const int rank = f.components == 1 ? 1 : 2;
  const hsize_t comps = static_cast<hsize_t>(f.components);
  const hsize_t file_dims[2] = {slice.total, comps};
  const hsize_t local_dims[2] = {slice.count, comps};
  const hsize_t start[2] = {slice.offset, 0};

  Hid file_space(H5Screate_simple(rank, file_dims, nullptr), H5Sclose);
  Hid mem_space(H5Screate_simple(rank, local_dims, nullptr), H5Sclose);
  bool ok = file_space.valid() && mem_space.valid();
  // A rank without particles still takes part in the collective write, selecting nothing.
  if (ok && slice.count == 0)
    ok = H5Sselect_none(file_space.get()) >= 0 && H5Sselect_none(mem_space.get()) >= 0;
  else if (ok)
    ok = H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, local_dims,
                             nullptr) >= 0;
  agreement.check(ok, "selecting this rank's slice of " + dset_path);

  const HdfTypes types = hdf_types(f.type);
  // Chunked with a Fletcher32 checksum per chunk (hdf5_checksum.hpp), verified on every read.
  // A chunk may span two ranks' slices: parallel HDF5 then writes it collectively (the
  // transfer list is collective), as a filtered dataset requires.
  Hid dcpl(H5Pcopy(out.dcpl), H5Pclose);
  agreement.check(
      dcpl.valid() && add_checksum(dcpl.get(), rank, file_dims, H5Tget_size(types.file)),
      "setting the checksum of " + dset_path);
  Hid dset(H5Dcreate2(out.file, dset_path.c_str(), types.file, file_space.get(), H5P_DEFAULT,
                      dcpl.get(), H5P_DEFAULT),
           H5Dclose);
  agreement.check(dset.valid(), "creating dataset " + dset_path);
  agreement.check(write_string_attribute(dset.get(), "units", f.units),
                  "writing the units attribute of " + dset_path);
  // HDF5 allocates no storage for a dataset of zero elements, and a collective write into it
  // fails even with empty selections (1.10.8: "addr overflow"), so an empty snapshot skips
  // the write; total is global, so all ranks skip together. HDF5 also rejects a null buffer
  // when nothing is selected, and an empty vector may give one.
  static const std::int64_t nothing = 0;
  if (slice.total > 0)
    agreement.check(H5Dwrite(dset.get(), types.memory, mem_space.get(), file_space.get(), out.dxpl,
                             slice.count ? data : &nothing) >= 0,
                    "writing dataset " + dset_path);
  agreement.check(dset.close(), "closing dataset " + dset_path);
}

// One group of the contact network (contact_network.hpp): `n_local` contacts of this rank,
// `data[k]` the array of fields[k]. Collective; returns the global count.
template <std::size_t N>
std::int64_t write_contact_group(const OpenFile& out, Agreement& agreement, MPI_Comm comm, int rank,
                                 const char* group, const std::array<ContactField, N>& fields,
                                 std::size_t n_local, const std::array<const void*, N>& data) {
  const std::int64_t n = static_cast<std::int64_t>(n_local);
  std::int64_t offset = 0, total = 0;
  MPI_Exscan(&n, &offset, 1, MPI_INT64_T, MPI_SUM, comm);
  if (rank == 0) offset = 0;  // MPI_Exscan leaves rank 0's result undefined
  MPI_Allreduce(&n, &total, 1, MPI_INT64_T, MPI_SUM, comm);
  const std::string path = std::string("/") + group;
  const bool writes = out.writes();
  Hid g(writes ? H5Gcreate2(out.file, path.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT) : -1,
        H5Gclose);
  agreement.check(!writes || g.valid(), "creating group " + path);
  const HdfTypes i64 = hdf_types(SnapshotField::Type::Int64);
  agreement.check(!writes || write_scalar_attribute(g.get(), "count", i64, &total),
                  "writing the count attribute of " + path);
  agreement.check(!writes || g.close(), "closing group " + path);
  for (std::size_t k = 0; k < N; ++k) {
    const hsize_t rows = static_cast<hsize_t>(fields[k].rows);
    const Slice slice{rows * static_cast<hsize_t>(offset), rows * static_cast<hsize_t>(n),
                      rows * static_cast<hsize_t>(total)};
    write_dataset(out, agreement, fields[k].field, slice, data[k], group);
  }
  return total;
}

std::string six_digits(std::size_t index) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%06zu", index);
  return buf;
}

}  // namespace

SnapshotWriter::SnapshotWriter(MPI_Comm comm, std::string directory, std::string basename,
                               SnapshotFieldSet fields)
    : comm_(comm),
      directory_(std::move(directory)),
      basename_(std::move(basename)),
      fields_(fields | snapshot_required_fields) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  // Ranks that share one node's memory hand their slices to rank 0, which writes each
  // snapshot alone with direct chunks (hdf5_checksum.hpp): on one node the file system is one
  // stream anyway, and parallel HDF5's collective filtered writes copy and sum every chunk in
  // HDF5's slow path and need every rank running at once. Across nodes: collective MPI-IO.
  // GRAINFLOW_SNAPSHOT_MPIIO=1 takes the MPI-IO route on one node too (its tests).
  if (size_ > 1) {
    MPI_Comm node;
    MPI_Comm_split_type(comm_, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
    int node_size = 0;
    MPI_Comm_size(node, &node_size);
    MPI_Comm_free(&node);
    const char* forced = std::getenv("GRAINFLOW_SNAPSHOT_MPIIO");
    const bool mpiio = forced && std::string(forced) == "1";
    int one_node = node_size == size_ && !mpiio ? 1 : 0;
    MPI_Allreduce(MPI_IN_PLACE, &one_node, 1, MPI_INT, MPI_MIN, comm_);
    gather_ = one_node == 1;
  }
}

std::size_t SnapshotWriter::continue_series(long up_to_step, double up_to_time) {
  QuietHdf5Errors quiet;
  entries_.clear();
  foreign_file_.clear();
  missing_.clear();
  reused_.clear();
  next_number_ = 0;
  index_.reset();  // the next write() rewrites the index with the entries taken over
  // The highest number in the folder: a file missing or unreadable below it is a gap (deleted,
  // damaged), not the end of the series; the files after it are taken over too.
  const std::vector<std::pair<long, std::string>> numbered = numbered_files();
  const long highest = numbered.empty() ? -1 : numbered.back().first;
  std::vector<std::string> skipped;  // numbers without a readable snapshot of this run
  for (long number = 0; number <= highest; ++number) {
    const std::string file_name = basename_ + "_" + six_digits(number) + ".h5";
    const std::string path = (std::filesystem::path(directory_) / file_name).string();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
      skipped.push_back(file_name + " (missing)");
      continue;
    }
    Hid file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
    double t = 0;
    std::int64_t s = 0, n = 0;
    auto read = [&](const char* name, hid_t type, void* out) {
      Hid attr(H5Aopen(file.get(), name, H5P_DEFAULT), H5Aclose);
      return attr.valid() && H5Aread(attr.get(), type, out) >= 0;
    };
    if (!file.valid() || !read("time", H5T_NATIVE_DOUBLE, &t) ||
        !read("step", H5T_NATIVE_INT64, &s) || !read("count", H5T_NATIVE_INT64, &n)) {
      skipped.push_back(file_name + " (unreadable)");
      continue;
    }
    if (s > up_to_step) break;  // the stopped run's, after its checkpoint: written again
    // Another scene's run (a file without the attribute predates it and is taken over).
    std::int64_t fingerprint = 0;
    if (fingerprint_ != 0 && H5Aexists(file.get(), "scene_fingerprint") > 0 &&
        read("scene_fingerprint", H5T_NATIVE_INT64, &fingerprint) &&
        static_cast<std::uint64_t>(fingerprint) != fingerprint_) {
      foreign_file_ = file_name;
      break;
    }
    SnapshotFieldSet held = 0;
    for (std::size_t k = 0; k < snapshot_fields.size(); ++k)
      if (H5Lexists(file.get(), snapshot_fields[k].name, H5P_DEFAULT) > 0)
        held |= SnapshotFieldSet{1} << k;
    // The contact network's counts (group attribute "count"), -1 when the file has none.
    std::int64_t counts[2] = {-1, -1};
    const char* groups[2] = {pair_contact_group, wall_contact_group};
    for (int k = 0; k < 2; ++k) {
      if (H5Lexists(file.get(), groups[k], H5P_DEFAULT) <= 0) continue;
      Hid attr(H5Aopen_by_name(file.get(), groups[k], "count", H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
      if (!attr.valid() || H5Aread(attr.get(), H5T_NATIVE_INT64, &counts[k]) < 0) counts[k] = -1;
    }
    entries_.push_back({file_name, t, static_cast<long>(s), static_cast<long>(n), held,
                        static_cast<long>(counts[0]), static_cast<long>(counts[1])});
    next_number_ = number + 1;
    // The gaps before this file are the series' own.
    missing_.insert(missing_.end(), skipped.begin(), skipped.end());
    skipped.clear();
  }
  H5Eclear2(H5E_DEFAULT);
  // Files missing or unreadable after the last one taken: the index the run wrote dates them.
  // One dated at or before the checkpoint is a gap of the series (and so is every one before
  // it); one dated after it is the stopped run's, written again; an undated one is written
  // again and said.
  const std::map<std::string, double> listed =
      foreign_file_.empty() ? index_times() : std::map<std::string, double>{};
  // The index's snapshots after the highest file in the folder (all missing: the ones at
  // the checkpoint and after it deleted) are looked at as the skipped ones are.
  for (const auto& [name, t] : listed)
    if (name.size() == basename_.size() + 7 &&
        name.find_first_not_of("0123456789", basename_.size() + 1) == std::string::npos &&
        std::stol(name.substr(basename_.size() + 1)) > highest)
      skipped.push_back(name + ".h5 (missing)");
  if (foreign_file_.empty() && !skipped.empty()) {
    const auto number_of = [&](const std::string& gap) {
      return std::stol(gap.substr(basename_.size() + 1, 6));
    };
    for (const std::string& gap : skipped) {
      const auto it = listed.find(gap.substr(0, basename_.size() + 7));  // particles_NNNNNN
      if (it != listed.end() && it->second <= up_to_time) next_number_ = number_of(gap) + 1;
    }
    for (const std::string& gap : skipped) {
      if (number_of(gap) < next_number_)
        missing_.push_back(gap);
      else if (listed.find(gap.substr(0, basename_.size() + 7)) == listed.end())
        reused_.push_back(gap);
    }
  }
  return entries_.size();
}

std::map<std::string, double> SnapshotWriter::index_times() const {
  // particles.xdmf: each time step is <Grid Name="particles_000003" ...> then <Time Value="t"/>.
  std::map<std::string, double> out;
  std::ifstream in(index_path(), std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  const std::string grid = "<Grid Name=\"" + basename_ + "_", time = "<Time Value=\"";
  for (std::size_t at = text.find(grid); at != std::string::npos; at = text.find(grid, at + 1)) {
    const std::size_t name_at = at + 12;  // after <Grid Name="
    const std::size_t name_end = text.find('"', name_at);
    const std::size_t t = text.find(time, at);
    if (name_end == std::string::npos || t == std::string::npos) break;
    const std::string name = text.substr(name_at, name_end - name_at);
    char* end = nullptr;
    const double value = std::strtod(text.c_str() + t + time.size(), &end);
    if (end != text.c_str() + t + time.size()) out.emplace(name, value);
  }
  return out;
}

std::vector<std::pair<long, std::string>> SnapshotWriter::numbered_files() const {
  std::vector<std::pair<long, std::string>> found;
  std::error_code ec;
  const std::string prefix = basename_ + "_";
  for (const auto& e : std::filesystem::directory_iterator(directory_, ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() != prefix.size() + 9 || !name.starts_with(prefix) || !name.ends_with(".h5"))
      continue;
    const std::string digits = name.substr(prefix.size(), 6);
    if (digits.find_first_not_of("0123456789") == std::string::npos)
      found.emplace_back(std::stol(digits), name);
  }
  std::sort(found.begin(), found.end());
  return found;
}

std::vector<std::string> SnapshotWriter::files_after_series() const {
  std::vector<std::string> out;
  for (const auto& [number, name] : numbered_files())
    if (number >= next_number_) out.push_back(name);
  return out;
}

std::string SnapshotWriter::index_path() const {
  return (std::filesystem::path(directory_) / (basename_ + ".xdmf")).string();
}

std::string SnapshotWriter::write(const Particles& p, double time, long step,
                                  const SnapshotExtras& extras, const ContactNetwork* contacts) {
  const auto wants = [&](const char* name) { return (fields_ & snapshot_field_bit(name)) != 0; };
  const auto check_size = [&](const char* name, std::size_t n) {
    if (wants(name) && n != p.size())
      throw std::logic_error(std::string("SnapshotWriter::write: the extra field '") + name +
                             "' has " + std::to_string(n) + " values for " +
                             std::to_string(p.size()) + " particles");
  };
  check_size("force", extras.force.size());
  check_size("torque", extras.torque.size());
  check_size("coordination", extras.coordination.size());
  check_size("fluid_force", extras.fluid_force.size());
  check_size("overlap_max", extras.overlap_max.size());
  const std::string file_name = basename_ + "_" + six_digits(next_number_) + ".h5";
  const std::string path = (std::filesystem::path(directory_) / file_name).string();
  // Written under a temporary name and renamed once closed: a run killed mid-write never
  // leaves a truncated file under a name the index lists.
  const std::string partial = path + ".part";

  // Attributes must be identical on all ranks; rank 0's values are the reference.
  double t = time;
  std::int64_t s = step;
  MPI_Bcast(&t, 1, MPI_DOUBLE, 0, comm_);
  MPI_Bcast(&s, 1, MPI_INT64_T, 0, comm_);

  const std::int64_t n_local = static_cast<std::int64_t>(p.size());
  std::int64_t offset = 0;
  std::int64_t total = 0;
  MPI_Exscan(&n_local, &offset, 1, MPI_INT64_T, MPI_SUM, comm_);
  if (rank_ == 0) offset = 0;  // MPI_Exscan leaves rank 0's result undefined
  MPI_Allreduce(&n_local, &total, 1, MPI_INT64_T, MPI_SUM, comm_);
  const Slice slice{static_cast<hsize_t>(offset), static_cast<hsize_t>(n_local),
                    static_cast<hsize_t>(total)};

  // The contact network's sizes over all ranks (-1: not written).
  std::int64_t pair_contacts = -1, wall_contacts = -1;
  QuietHdf5Errors quiet;
  // Data plus HDF5's metadata, about 3 kB per checksummed dataset (measured: 4000 particles
  // take 454 040 bytes, 432 000 of them data).
  std::uintmax_t bytes_per_particle = 0;
  for (std::size_t k = 0; k < snapshot_fields.size(); ++k) {
    const SnapshotField& f = snapshot_fields[k];
    if (!(fields_ & (SnapshotFieldSet{1} << k))) continue;
    bytes_per_particle +=
        static_cast<std::uintmax_t>(f.components) * (f.type == SnapshotField::Type::Int32 ? 4 : 8);
  }
  std::uintmax_t bytes = bytes_per_particle * static_cast<std::uintmax_t>(total) + 32768;
  if (contacts) {
    // 152 bytes per pair (ids, line ends, point, two forces, magnitude, overlap), 140 per
    // wall contact, and the metadata of 15 more datasets.
    std::int64_t n[2] = {static_cast<std::int64_t>(contacts->pairs.size()),
                         static_cast<std::int64_t>(contacts->walls.size())};
    MPI_Allreduce(MPI_IN_PLACE, n, 2, MPI_INT64_T, MPI_SUM, comm_);
    bytes += 152 * static_cast<std::uintmax_t>(n[0]) + 140 * static_cast<std::uintmax_t>(n[1]) +
             15 * 3072;
  }
  Agreement agreement(comm_, rank_, size_, path, bytes);
  try {
    agreement.check_space();
    Hid fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
    Hid dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    Hid dxpl(H5Pcreate(H5P_DATASET_XFER), H5Pclose);
    bool ok = fapl.valid() && dcpl.valid() && dxpl.valid();
    if (size_ > 1 && !gather_) {
      ok = ok && H5Pset_fapl_mpio(fapl.get(), comm_, MPI_INFO_NULL) >= 0;
      // Metadata written collectively instead of by rank 0 alone plus broadcasts (scales
      // better).
      ok = ok && H5Pset_coll_metadata_write(fapl.get(), true) >= 0;
      ok = ok && H5Pset_all_coll_metadata_ops(fapl.get(), true) >= 0;
      ok = ok && H5Pset_dxpl_mpio(dxpl.get(), H5FD_MPIO_COLLECTIVE) >= 0;
    }
    // One rank writes through HDF5's default (POSIX) driver: the same file, without the
    // collective filtered-chunk path of MPI-IO, which copies every chunk once more. Its
    // large writes bypass the page cache (direct_write_driver.hpp); the bytes are the same.
    // Parallel HDF5 allocates datasets at creation; without this it would also write fill
    // values there first, doubling the I/O.
    ok = ok && H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_NEVER) >= 0;
    agreement.check(ok, "setting up the MPI-IO property lists");
    if (size_ == 1 || gather_) {
      const std::string setting = buffered_writes_error();
      agreement.agree(setting.empty() ? setting
                                      : "cannot write snapshot '" + path + "': " + setting);
      agreement.check(set_direct_write_driver(fapl.get()), "choosing how the file is written");
    }

    // Gathering on rank 0 (several ranks on one node, gather_): rank 0 alone opens the file.
    const bool opens = !gather_ || rank_ == 0;
    Hid file(opens ? H5Fcreate(partial.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()) : -1,
             H5Fclose);
    agreement.check(!opens || file.valid(), "creating the temporary file '" + partial + "'");
    const OpenFile out{file.get(), dcpl.get(), dxpl.get(), size_ == 1 || gather_, gather_, comm_};

    write_dataset(out, agreement, field("id"), slice, p.id.data());
    // A Vec3 is three contiguous doubles: its array is the (n, 3) dataset as it stands.
    static_assert(sizeof(Vec3) == 3 * sizeof(double));
    const auto vectors = [](const std::vector<Vec3>& a) {
      return a.empty() ? nullptr : a.front().data();
    };
    write_dataset(out, agreement, field("position"), slice, vectors(p.x));
    // Every rank holds the same set, so all take part in the same collective writes.
    const auto optional = [&](const char* name, const void* data) {
      if (wants(name)) write_dataset(out, agreement, field(name), slice, data);
    };
    optional("velocity", vectors(p.v));
    optional("angular_velocity", vectors(p.omega));
    optional("radius", p.radius.data());
    if (wants("diameter")) {
      // Not kept between snapshots: it would add 8 bytes per particle to the run's peak.
      std::vector<double> diameter(p.size());
      for (std::size_t i = 0; i < p.size(); ++i) diameter[i] = 2.0 * p.radius[i];
      write_dataset(out, agreement, field("diameter"), slice, diameter.data());
    }
    optional("mass", p.mass.data());
    optional("material", p.material.data());
    optional("force", vectors(extras.force));
    optional("torque", vectors(extras.torque));
    static_assert(sizeof(int) == 4, "coordination is written as int32");
    optional("coordination", extras.coordination.data());
    optional("fluid_force", vectors(extras.fluid_force));
    optional("overlap_max", extras.overlap_max.data());
    optional("temperature", p.temperature.data());
    if (wants("coarse_grain") || wants("real_count")) {
      // From the material's factor (set_coarse_grain); not kept between snapshots.
      std::vector<double> k(p.size(), 1.0), count(p.size(), 1.0);
      if (!coarse_grain_.empty())
        for (std::size_t i = 0; i < p.size(); ++i) {
          k[i] = coarse_grain_[static_cast<std::size_t>(p.material[i])];
          count[i] = k[i] * k[i] * k[i];
        }
      optional("coarse_grain", k.data());
      optional("real_count", count.data());
    }
    static_assert(snapshot_fields.size() == 16, "a new snapshot field needs its write above");

    if (contacts) {
      static_assert(sizeof(std::array<GlobalId, 2>) == 2 * sizeof(std::int64_t));
      const PairContacts& c = contacts->pairs;
      const auto ids = [](const auto& a) { return a.empty() ? nullptr : a.data(); };
      static_assert(pair_contact_fields.size() == 7, "a new contact field needs its array here");
      pair_contacts = write_contact_group(
          out, agreement, comm_, rank_, pair_contact_group, pair_contact_fields, c.size(),
          {ids(c.id), vectors(c.ends), vectors(c.point), vectors(c.normal_force),
           vectors(c.tangential_force), ids(c.normal_force_magnitude), ids(c.overlap)});
      const WallContacts& w = contacts->walls;
      static_assert(wall_contact_fields.size() == 8, "a new contact field needs its array here");
      wall_contacts = write_contact_group(
          out, agreement, comm_, rank_, wall_contact_group, wall_contact_fields, w.size(),
          {ids(w.id), ids(w.wall), vectors(w.ends), vectors(w.point), vectors(w.normal_force),
           vectors(w.tangential_force), ids(w.normal_force_magnitude), ids(w.overlap)});
    }

    const HdfTypes f64 = hdf_types(SnapshotField::Type::Float64);
    const HdfTypes i64 = hdf_types(SnapshotField::Type::Int64);
    ok = !opens || (write_scalar_attribute(file.get(), "time", f64, &t) &&
                    write_scalar_attribute(file.get(), "step", i64, &s) &&
                    write_scalar_attribute(file.get(), "count", i64, &total) &&
                    write_string_attribute(file.get(), "grainflow_version", GRAINFLOW_VERSION));
    agreement.check(ok, "writing the root attributes (time, step, count)");
    if (fingerprint_ != 0) {
      const auto fingerprint = static_cast<std::int64_t>(fingerprint_);
      ok = !opens || write_scalar_attribute(file.get(), "scene_fingerprint", i64, &fingerprint);
      agreement.check(ok, "writing the root attribute scene_fingerprint");
    }
    if (!material_names_.empty()) {
      ok = !opens || write_string_attribute(file.get(), "material_names", material_names_);
      agreement.check(ok, "writing the root attribute material_names");
    }
    if (!coarse_grain_.empty()) {
      const std::vector<std::int64_t> real(real_material_.begin(), real_material_.end());
      ok = !opens ||
           (write_array_attribute(file.get(), "material_coarse_grain", f64.file, f64.memory,
                                  coarse_grain_.size(), coarse_grain_.data()) &&
            write_array_attribute(file.get(), "material_real", i64.file, i64.memory, real.size(),
                                  real.data()));
      agreement.check(ok, "writing the root attributes material_coarse_grain, material_real");
    }
    agreement.check(!opens || file.close(), "closing (flushing) the file");

    const bool renamed = rank_ != 0 || std::rename(partial.c_str(), path.c_str()) == 0;
    const int rename_errno = errno;
    agreement.check_os(renamed, "renaming '" + partial + "' to its final name", rename_errno);
  } catch (const OutputError&) {
    // Every rank arrives here together, with all HDF5 handles closed by now.
    if (rank_ == 0) std::remove(partial.c_str());
    throw;
  }

  entries_.push_back({file_name, t, static_cast<long>(s), static_cast<long>(total), fields_,
                      static_cast<long>(pair_contacts), static_cast<long>(wall_contacts)});
  ++next_number_;
  std::string index_error;
  if (rank_ == 0) {
    try {
      // The first snapshot of this writer (or the first after continue_series) writes the
      // whole index; later ones append one time step (xdmf_index_file.hpp).
      if (index_)
        index_->append(entries_.back());
      else
        index_ = std::make_unique<XdmfIndexFile>(index_path(), basename_, entries_);
    } catch (const OutputError& e) {
      index_.reset();  // the next snapshot, if any, rewrites the index whole
      index_error = e.what();
    }
  }
  agreement.agree(index_error);
  return path;
}

}  // namespace grainflow
