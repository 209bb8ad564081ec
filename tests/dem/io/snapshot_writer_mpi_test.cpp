// SnapshotWriter under MPI (CTest runs it with 2 ranks; it also passes with 1 or more).
// Reference: the particle values each rank wrote, regenerated bit for bit on rank 0 by the same
// deterministic function and compared EXACTLY (tolerance 0): the writer copies doubles and
// integers without arithmetic, except diameter = 2 * radius, which is exact in binary floating
// point. The file is read back serially on rank 0 with the plain HDF5 C API. The XDMF index is
// parsed by Python's xml.etree (a strict XML parser), which prints its structure for checking.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <mpi.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "dem/core/particles.hpp"
#include "dem/io/output_directory.hpp"
#include "dem/io/snapshot_writer.hpp"

namespace grainflow {
namespace {

namespace fs = std::filesystem;

int world_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

int world_size() {
  int s = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &s);
  return s;
}

// A fresh, empty directory per test, the same path on every rank. CTest runs this executable
// twice, the second time with GRAINFLOW_SNAPSHOT_MPIIO=1 (snapshot_writer_mpiio_mpi_test,
// tests/CMakeLists.txt), and may run the two at once: each route has a folder of its own.
std::string test_directory() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const char* mpiio = std::getenv("GRAINFLOW_SNAPSHOT_MPIIO");
  const std::string route = mpiio && std::string(mpiio) == "1" ? "snapshot_writer_mpiio_mpi_test"
                                                               : "snapshot_writer_mpi_test";
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / route /
                       (std::string(info->test_suite_name()) + "." + info->name());
  if (world_rank() == 0) fs::remove_all(dir);
  MPI_Barrier(MPI_COMM_WORLD);
  prepare_output_directory(dir.string());  // every rank at once, as a run does
  MPI_Barrier(MPI_COMM_WORLD);
  return dir.string();
}

// Deterministic, rank-dependent particles whose values are not round numbers, so that a slice
// written at the wrong offset or a lossy conversion cannot go unnoticed.
Particles make_particles(int rank, int count) {
  Particles p;
  for (int i = 0; i < count; ++i) {
    const double k = 100.0 * rank + i;
    const GlobalId id = 1'000'000'007LL * (rank + 1) + 13 * i;  // beyond 32 bits
    const Vec3 x(0.1 * k + 1.0 / 3.0, -0.25 * k - std::numbers::pi, 1e-3 * k + 1e-17);
    const Vec3 v(std::sqrt(2.0) * k, -1.0 / (k + 7.0), 1e300 / (k + 1.0));
    const Vec3 w(-k / 3.0, 5e-310, std::exp(-k));  // 5e-310: a subnormal
    const double r = 1e-3 * (1.0 + 0.1 * i) + 1e-5 * rank;
    p.add(id, x, v, w, r, rank + i % 3, 2500.0 + rank);
  }
  return p;
}

struct Expected {
  std::vector<std::int64_t> id;
  std::vector<double> position, velocity, angular_velocity, radius, diameter, mass;
  std::vector<std::int32_t> material;
};

void append3(std::vector<double>& out, const Vec3& a) {
  for (int k = 0; k < 3; ++k) out.push_back(a[k]);
}

// The global arrays: rank 0's slice, then rank 1's, ...
Expected expected_arrays(const std::vector<int>& counts) {
  Expected e;
  for (int r = 0; r < static_cast<int>(counts.size()); ++r) {
    const Particles p = make_particles(r, counts[static_cast<std::size_t>(r)]);
    for (std::size_t i = 0; i < p.size(); ++i) {
      e.id.push_back(p.id[i]);
      append3(e.position, p.x[i]);
      append3(e.velocity, p.v[i]);
      append3(e.angular_velocity, p.omega[i]);
      e.radius.push_back(p.radius[i]);
      e.diameter.push_back(2.0 * p.radius[i]);
      e.mass.push_back(p.mass[i]);
      e.material.push_back(p.material[i]);
    }
  }
  return e;
}

template <class T>
void read_dataset(hid_t file, const char* name, hid_t file_type, hid_t mem_type,
                  std::vector<hsize_t> dims, std::vector<T>& out) {
  SCOPED_TRACE(name);
  const hid_t dset = H5Dopen2(file, name, H5P_DEFAULT);
  ASSERT_GE(dset, 0);
  const hid_t type = H5Dget_type(dset);
  EXPECT_GT(H5Tequal(type, file_type), 0) << "stored type";
  H5Tclose(type);
  const hid_t space = H5Dget_space(dset);
  const int rank = H5Sget_simple_extent_ndims(space);
  std::vector<hsize_t> got(static_cast<std::size_t>(std::max(rank, 0)));
  H5Sget_simple_extent_dims(space, got.data(), nullptr);
  H5Sclose(space);
  EXPECT_EQ(got, dims);
  hsize_t n = 1;
  for (hsize_t d : dims) n *= d;
  out.assign(n, T{});
  T dummy{};
  EXPECT_GE(H5Dread(dset, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, n ? out.data() : &dummy), 0);
  // The units attribute is part of the format other tools rely on.
  EXPECT_GT(H5Aexists(dset, "units"), 0);
  H5Dclose(dset);
}

template <class T>
void read_root_attribute(hid_t file, const char* name, hid_t mem_type, T& out) {
  const hid_t attr = H5Aopen(file, name, H5P_DEFAULT);
  ASSERT_GE(attr, 0) << name;
  EXPECT_GE(H5Aread(attr, mem_type, &out), 0) << name;
  H5Aclose(attr);
}

// Serial read-back on rank 0 (no collective calls in here, so a failed ASSERT cannot leave the
// other ranks waiting).
void check_snapshot(const std::string& path, const std::vector<int>& counts, double time,
                    long step) {
  SCOPED_TRACE(path);
  const Expected e = expected_arrays(counts);
  const hsize_t n = e.id.size();
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);

  double t = -1;
  std::int64_t s = -1, count = -1;
  read_root_attribute(file, "time", H5T_NATIVE_DOUBLE, t);
  read_root_attribute(file, "step", H5T_NATIVE_INT64, s);
  read_root_attribute(file, "count", H5T_NATIVE_INT64, count);
  EXPECT_EQ(t, time);
  EXPECT_EQ(s, step);
  EXPECT_EQ(count, static_cast<std::int64_t>(n));

  std::vector<std::int64_t> id;
  std::vector<double> position, velocity, angular_velocity, radius, diameter, mass;
  std::vector<std::int32_t> material;
  read_dataset(file, "/id", H5T_STD_I64LE, H5T_NATIVE_INT64, {n}, id);
  read_dataset(file, "/position", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n, 3}, position);
  read_dataset(file, "/velocity", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n, 3}, velocity);
  read_dataset(file, "/angular_velocity", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n, 3},
               angular_velocity);
  read_dataset(file, "/radius", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n}, radius);
  read_dataset(file, "/diameter", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n}, diameter);
  read_dataset(file, "/mass", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n}, mass);
  read_dataset(file, "/material", H5T_STD_I32LE, H5T_NATIVE_INT32, {n}, material);
  EXPECT_GE(H5Fclose(file), 0);

  // Exact comparisons, element by element and in order (see the header comment).
  EXPECT_EQ(id, e.id);
  EXPECT_EQ(position, e.position);
  EXPECT_EQ(velocity, e.velocity);
  EXPECT_EQ(angular_velocity, e.angular_velocity);
  EXPECT_EQ(radius, e.radius);
  EXPECT_EQ(diameter, e.diameter);
  EXPECT_EQ(mass, e.mass);
  EXPECT_EQ(material, e.material);
}

// Particle counts per rank; ranks beyond the list (runs with more than 2 ranks) own r + 1.
std::vector<int> counts_for_world(std::vector<int> pattern) {
  pattern.resize(static_cast<std::size_t>(world_size()), 0);
  for (std::size_t r = 2; r < pattern.size(); ++r) pattern[r] = static_cast<int>(r) + 1;
  return pattern;
}

void write_and_check(const std::vector<int>& pattern) {
  const std::vector<int> counts = counts_for_world(pattern);
  const std::string dir = test_directory();
  const int rank = world_rank();
  SnapshotWriter writer(MPI_COMM_WORLD, dir);
  const Particles p = make_particles(rank, counts[static_cast<std::size_t>(rank)]);
  const double time = 0.1 + 1e-12;
  const long step = 12345678901L;
  const std::string path = writer.write(p, time, step);
  EXPECT_EQ(path, (fs::path(dir) / "particles_000000.h5").string());
  if (rank == 0) {
    check_snapshot(path, counts, time, step);
    EXPECT_FALSE(fs::exists(path + ".part")) << "temporary file left behind";
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(SnapshotWriter, DifferentCountsPerRankLandInRankOrder) { write_and_check({3, 5}); }

TEST(SnapshotWriter, RankOneOwnsNoParticles) { write_and_check({4, 0}); }

TEST(SnapshotWriter, RankZeroOwnsNoParticles) { write_and_check({0, 3}); }

TEST(SnapshotWriter, NoParticlesAnywhereGivesEmptyDatasets) { write_and_check({0, 0}); }

// Extra fields (output.fields) land in rank order like the state, with their stored types;
// fields not asked for are absent. Reference: the same deterministic values (exact).
void write_and_check_extras(const std::vector<int>& pattern) {
  const std::vector<int> counts = counts_for_world(pattern);
  const std::string dir = test_directory();
  const int rank = world_rank();
  const SnapshotFieldSet fields = snapshot_required_fields | snapshot_field_bit("force") |
                                  snapshot_field_bit("coordination") |
                                  snapshot_field_bit("overlap_max");
  SnapshotWriter writer(MPI_COMM_WORLD, dir, "particles", fields);
  const auto extras_of = [](int r, int n) {
    SnapshotExtras e;
    for (int i = 0; i < n; ++i) {
      e.force.emplace_back(1.0 / (3 + i + 10 * r), -1e-300 * i, 7.0 * r);
      e.coordination.push_back(i + 100 * r);
      e.overlap_max.push_back(0.1 * i + r / 3.0);
    }
    return e;
  };
  const Particles p = make_particles(rank, counts[static_cast<std::size_t>(rank)]);
  const std::string path =
      writer.write(p, 0.25, 3, extras_of(rank, counts[static_cast<std::size_t>(rank)]));
  if (rank == 0) {
    SCOPED_TRACE(path);
    std::vector<double> force, overlap;
    std::vector<std::int32_t> coordination;
    for (int r = 0; r < static_cast<int>(counts.size()); ++r) {
      const SnapshotExtras e = extras_of(r, counts[static_cast<std::size_t>(r)]);
      for (std::size_t i = 0; i < e.force.size(); ++i) {
        append3(force, e.force[i]);
        coordination.push_back(e.coordination[i]);
        overlap.push_back(e.overlap_max[i]);
      }
    }
    const hsize_t n = coordination.size();
    const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(file, 0);
    std::vector<double> got_force, got_overlap;
    std::vector<std::int32_t> got_coordination;
    read_dataset(file, "/force", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n, 3}, got_force);
    read_dataset(file, "/coordination", H5T_STD_I32LE, H5T_NATIVE_INT32, {n}, got_coordination);
    read_dataset(file, "/overlap_max", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n}, got_overlap);
    for (const char* absent : {"velocity", "torque", "fluid_force", "material"})
      EXPECT_EQ(H5Lexists(file, absent, H5P_DEFAULT), 0) << absent;
    EXPECT_GE(H5Fclose(file), 0);
    EXPECT_EQ(got_force, force);
    EXPECT_EQ(got_coordination, coordination);
    EXPECT_EQ(got_overlap, overlap);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(SnapshotWriter, ExtraFieldsLandInRankOrder) { write_and_check_extras({3, 5}); }

TEST(SnapshotWriter, ExtraFieldsWhenRankOneOwnsNoParticles) { write_and_check_extras({4, 0}); }

// A field of the writer's set without its values is a programming error, found before any
// collective call (on every rank alike, as every rank lacks it).
TEST(SnapshotWriter, MissingExtraFieldIsALogicError) {
  const std::string dir = test_directory();
  SnapshotWriter writer(MPI_COMM_WORLD, dir, "particles",
                        snapshot_default_fields | snapshot_field_bit("torque"));
  EXPECT_THROW(writer.write(make_particles(world_rank(), 2), 0.0, 0), std::logic_error);
  MPI_Barrier(MPI_COMM_WORLD);
}

// Runs python's strict XML parser on the index and prints one line per time step (a Spatial
// collection holding one grid, "particles"):
//   <step name> <time> <topology type> <elements> then "<tag>:<name> <dims> <type> <prec> <ref>"
// for the geometry and every attribute.
const char* xdmf_dump_script = R"PY(
import sys, xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
assert root.tag == "Xdmf", root.tag
(domain,) = root.findall("Domain")
(series,) = domain.findall("Grid")
print("series", series.get("Name"), series.get("GridType"), series.get("CollectionType"))
for step in series.findall("Grid"):
    assert (step.get("GridType"), step.get("CollectionType")) == ("Collection", "Spatial")
    (g,) = step.findall("Grid")
    assert g.get("Name") == "particles", g.get("Name")
    topo = g.find("Topology")
    print("grid", step.get("Name"), repr(float(step.find("Time").get("Value"))),
          topo.get("TopologyType"), topo.get("NumberOfElements"), topo.get("NodesPerElement"))
    items = [("Geometry:" + g.find("Geometry").get("GeometryType"), g.find("Geometry/DataItem"))]
    items += [("Attribute:" + a.get("Name") + ":" + a.get("AttributeType") + ":" + a.get("Center"),
               a.find("DataItem")) for a in g.findall("Attribute")]
    for label, d in items:
        print(" ", label, d.get("Dimensions").replace(" ", "x"), d.get("NumberType"),
              d.get("Precision"), d.get("Format"), d.text.strip())
)PY";

// The Python that has what each script imports (scripts/python.sh; it names the missing
// modules and the fix when none has them).
std::string python() { return GRAINFLOW_SOURCE_DIR "/scripts/python.sh"; }

// Runs `command`, returns its standard output; exit status in `status`.
std::string run(const std::string& command, int& status) {
  std::string out;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) {
    status = -1;
    return out;
  }
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) out.append(buf, n);
  status = ::pclose(pipe);
  return out;
}

std::string expected_grid(const std::string& stem, double time, long count) {
  std::ostringstream s;
  s.precision(17);
  const std::string n = std::to_string(count);
  const std::string f = stem + ".h5:/";
  s << "grid " << stem << ' ' << time << " Polyvertex " << n << " 1\n"
    << "  Geometry:XYZ " << n << "x3 Float 8 HDF " << f << "position\n"
    << "  Attribute:id:Scalar:Node " << n << " Int 8 HDF " << f << "id\n"
    << "  Attribute:velocity:Vector:Node " << n << "x3 Float 8 HDF " << f << "velocity\n"
    << "  Attribute:angular_velocity:Vector:Node " << n << "x3 Float 8 HDF " << f
    << "angular_velocity\n"
    << "  Attribute:radius:Scalar:Node " << n << " Float 8 HDF " << f << "radius\n"
    << "  Attribute:diameter:Scalar:Node " << n << " Float 8 HDF " << f << "diameter\n"
    << "  Attribute:mass:Scalar:Node " << n << " Float 8 HDF " << f << "mass\n"
    << "  Attribute:material:Scalar:Node " << n << " Int 4 HDF " << f << "material\n";
  return s.str();
}

void check_xdmf(const std::string& dir, const std::string& index,
                const std::vector<std::string>& stems, const std::vector<double>& times,
                const std::vector<long>& counts) {
  const std::string script = (fs::path(dir) / "dump_xdmf.py").string();
  std::ofstream(script) << xdmf_dump_script;
  int status = 0;
  const std::string got = run(python() + " " + script + " " + index + " 2>&1", status);
  ASSERT_EQ(status, 0) << got;
  std::ostringstream want;
  want << "series particles Collection Temporal\n";
  for (std::size_t i = 0; i < stems.size(); ++i)
    want << expected_grid(stems[i], times[i], counts[i]);

  // The times: python printed repr(float), which reads back to the identical double.
  std::istringstream lines(got);
  std::string line;
  std::size_t grid = 0;
  std::string normalised;
  while (std::getline(lines, line)) {
    if (line.rfind("grid ", 0) == 0) {
      std::istringstream fields(line);
      std::string tag, name, time_text, rest;
      fields >> tag >> name >> time_text;
      std::getline(fields, rest);
      ASSERT_LT(grid, times.size()) << got;
      EXPECT_EQ(std::strtod(time_text.c_str(), nullptr), times[grid]) << line;
      std::ostringstream t;
      t.precision(17);
      t << times[grid];
      line = tag + " " + name + " " + t.str() + rest;
      ++grid;
    }
    normalised += line + "\n";
  }
  EXPECT_EQ(grid, stems.size());
  EXPECT_EQ(normalised, want.str());
}

TEST(SnapshotWriter, XdmfIndexListsEverySnapshotInTimeOrder) {
  const std::vector<int> counts = counts_for_world({2, 3});
  const std::string dir = test_directory();
  const int rank = world_rank();
  SnapshotWriter writer(MPI_COMM_WORLD, dir);
  const std::vector<double> times = {0.0, 1e-3, 1.0 / 3.0};
  const std::vector<long> steps = {0, 10, 3333};
  std::vector<long> totals;
  for (std::size_t i = 0; i < times.size(); ++i) {
    // The particle count changes between snapshots, as when particles are inserted.
    const Particles p =
        make_particles(rank, counts[static_cast<std::size_t>(rank)] + static_cast<int>(i));
    writer.write(p, times[i], steps[i]);
    long total = 0;
    for (int c : counts) total += c + static_cast<long>(i);
    totals.push_back(total);
  }
  EXPECT_EQ(writer.snapshots_written(), 3u);
  EXPECT_EQ(writer.index_path(), (fs::path(dir) / "particles.xdmf").string());
  if (rank == 0) {
    for (const char* f :
         {"particles_000000.h5", "particles_000001.h5", "particles_000002.h5", "particles.xdmf"})
      EXPECT_TRUE(fs::exists(fs::path(dir) / f)) << f;
    EXPECT_FALSE(fs::exists(writer.index_path() + ".tmp")) << "temporary index left behind";
    check_xdmf(dir, writer.index_path(),
               {"particles_000000", "particles_000001", "particles_000002"}, times, totals);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(SnapshotWriter, CustomBasenameNamesFilesAndIndex) {
  const std::string dir = test_directory();
  SnapshotWriter writer(MPI_COMM_WORLD, dir, "tracer");
  const std::string path = writer.write(make_particles(world_rank(), 1), 0.5, 7);
  EXPECT_EQ(path, (fs::path(dir) / "tracer_000000.h5").string());
  EXPECT_EQ(writer.index_path(), (fs::path(dir) / "tracer.xdmf").string());
  if (world_rank() == 0) {
    EXPECT_TRUE(fs::exists(writer.index_path()));
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

// A missing directory must give the same OutputError on every rank (no rank left hanging in a
// collective call), naming the file; the writer must stay usable afterwards.
TEST(SnapshotWriter, MissingDirectoryThrowsOnEveryRank) {
  const std::string dir = test_directory();
  const std::string missing = (fs::path(dir) / "not" / "there").string();
  SnapshotWriter bad(MPI_COMM_WORLD, missing);
  std::string message;
  try {
    bad.write(make_particles(world_rank(), 2), 0.0, 0);
    ADD_FAILURE() << "no OutputError";
  } catch (const OutputError& e) {
    message = e.what();
  }
  EXPECT_NE(message.find(missing + "/particles_000000.h5"), std::string::npos) << message;
  EXPECT_EQ(bad.snapshots_written(), 0u);

  // All ranks must have thrown the same message.
  int length = static_cast<int>(message.size());
  int min_length = length;
  MPI_Allreduce(&length, &min_length, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  EXPECT_EQ(min_length, length);

  SnapshotWriter good(MPI_COMM_WORLD, dir);
  EXPECT_NO_THROW(good.write(make_particles(world_rank(), 2), 0.0, 0));
  MPI_Barrier(MPI_COMM_WORLD);
}

// The tutorial helper reads our files (h5py) and reports count and bounds.
TEST(SnapshotWriter, H5SummaryScriptReadsSnapshot) {
  const std::vector<int> counts = counts_for_world({3, 5});
  const std::string dir = test_directory();
  SnapshotWriter writer(MPI_COMM_WORLD, dir);
  const std::string path = writer.write(
      make_particles(world_rank(), counts[static_cast<std::size_t>(world_rank())]), 0.25, 250);
  if (world_rank() == 0) {
    [&] {
      int status = 0;
      const std::string out = run(
          python() + " " GRAINFLOW_SOURCE_DIR "/scripts/h5_summary.py " + path + " 2>&1", status);
      ASSERT_EQ(status, 0) << out;
      long total = 0;
      for (int c : counts) total += c;
      EXPECT_NE(out.find("particles " + std::to_string(total)), std::string::npos) << out;
      EXPECT_NE(out.find("step 250"), std::string::npos) << out;
    }();
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

// Failures on ranks other than 0 are printed with their rank (their normal output is muted).
class RankFailurePrinter : public ::testing::EmptyTestEventListener {
 public:
  explicit RankFailurePrinter(int rank) : rank_(rank) {}
  void OnTestPartResult(const ::testing::TestPartResult& r) override {
    if (r.failed())
      std::fprintf(stderr, "[rank %d] %s:%d: %s\n", rank_, r.file_name() ? r.file_name() : "?",
                   r.line_number(), r.summary());
  }

 private:
  int rank_;
};

}  // namespace
}  // namespace grainflow

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  const int rank = grainflow::world_rank();
  if (rank != 0) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
    listeners.Append(new grainflow::RankFailurePrinter(rank));
  }
  int result = RUN_ALL_TESTS();
  MPI_Allreduce(MPI_IN_PLACE, &result, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Finalize();
  return result;
}
