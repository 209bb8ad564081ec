// The direct-write file driver (dem/io/direct_write_driver.hpp) against HDF5's own POSIX
// driver: the same HDF5 calls through each give byte-identical files, whose large writes went
// around the page cache where the file system takes O_DIRECT; the file reads back through
// HDF5's default driver with every checksum verified; failures carry the system's reason.
#include "dem/io/direct_write_driver.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "dem/io/hdf5_checksum.hpp"
#include "dem/io/hdf5_errors.hpp"

namespace grainflow {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("grainflow_direct_write_" + std::to_string(getpid()));
  fs::create_directories(dir);
  return dir / name;
}

std::vector<char> bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Whether the file system under `dir` takes an aligned O_DIRECT write (independently of the
// driver: the expectation on how many bytes went direct depends on it).
bool takes_direct_writes(const fs::path& dir) {
  const fs::path probe = dir / "probe";
  const int fd = open(probe.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_DIRECT, 0644);
  bool ok = false;
  if (fd >= 0) {
    void* block = std::aligned_alloc(4096, 4096);
    ok = block && pwrite(fd, block, 4096, 0) == 4096;
    std::free(block);
    close(fd);
  }
  fs::remove(probe);
  return ok;
}

// Random doubles of a dataset with `rows` rows of three.
std::vector<double> random_rows(std::size_t rows, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> v(3 * rows);
  for (double& x : v) x = u(rng);
  return v;
}

// Datasets as the snapshot writer makes them: checksummed chunks of up to 1 MiB written one by
// one (at unaligned addresses, with 4-byte checksums after each), a contiguous dataset written
// in one call (3 MB and 24 bytes), small ones below the direct threshold, and attributes.
// Object times off, so that two files written a second apart can be equal.
void write_file(const fs::path& path, hid_t fapl) {
  const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
  ASSERT_GE(file, 0) << hdf5_reason();
  const auto dataset = [&](const std::string& name, std::size_t rows, bool chunked) {
    const std::vector<double> data = random_rows(rows, static_cast<unsigned>(rows));
    const hsize_t dims[2] = {rows, 3};
    const hid_t space = H5Screate_simple(2, dims, nullptr);
    const hid_t dcpl =
        chunked ? checksummed_layout(2, dims, sizeof(double)) : H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_obj_track_times(dcpl, false);
    const hid_t set =
        H5Dcreate2(file, name.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    ASSERT_GE(set, 0) << hdf5_reason();
    ASSERT_TRUE(
        chunked ? write_checksummed(set, 2, dims, sizeof(double), data.data())
                : H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) >= 0)
        << hdf5_reason();
    H5Dclose(set);
    H5Pclose(dcpl);
    H5Sclose(space);
  };
  dataset("position", 101'111, true);  // three chunks of 33 704 rows
  dataset("velocity", 7, true);        // one tiny chunk
  dataset("plain", 125'001, false);    // one write of 3 000 024 bytes
  dataset("small", 10'000, false);     // 240 000 bytes: below the threshold
  dataset("radius", 43'690, true);     // 1 048 560 bytes and a checksum
  const hsize_t one = 1;
  const hid_t space = H5Screate_simple(1, &one, nullptr);
  const hid_t attribute = H5Acreate2(file, "time", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT);
  const double t = 0.125;
  H5Awrite(attribute, H5T_NATIVE_DOUBLE, &t);
  H5Aclose(attribute);
  H5Sclose(space);
  ASSERT_GE(H5Fclose(file), 0) << hdf5_reason();
}

TEST(DirectWriteDriver, WritesTheBytesOfHdf5sPosixDriver) {
  const fs::path posix = scratch("posix.h5"), direct = scratch("direct.h5");
  write_file(posix, H5P_DEFAULT);
  const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  ASSERT_TRUE(set_direct_write_driver(fapl));
  const long long before = direct_write_bytes();
  write_file(direct, fapl);
  const long long went_direct = direct_write_bytes() - before;
  H5Pclose(fapl);

  const std::vector<char> a = bytes_of(posix), b = bytes_of(direct);
  ASSERT_GT(a.size(), 6'700'000u);
  EXPECT_EQ(a.size(), b.size());
  EXPECT_TRUE(a == b) << "the files differ";
  if (takes_direct_writes(posix.parent_path())) {
    // The whole 4 KiB blocks of the five writes of at least 256 KiB: the three chunks of
    // 'position' (33 704 rows each, the last one part-filled but stored whole, and a 4-byte
    // checksum), 'plain' (3 000 024 bytes) and the chunk of 'radius' (1 048 560 + 4). Each
    // loses less than a block at either end.
    const long long large = 3 * (33'704 * 24 + 4) + 3'000'024 + 1'048'564;
    EXPECT_LE(went_direct, large);
    EXPECT_GT(went_direct, large - 5 * 2 * 4096);
    EXPECT_EQ(went_direct % 4096, 0);
  } else {
    EXPECT_EQ(went_direct, 0) << "the file system refuses O_DIRECT: all writes buffered";
  }
  fs::remove_all(posix.parent_path());
}

TEST(DirectWriteDriver, FileReadsBackThroughTheDefaultDriverWithItsChecksums) {
  const fs::path path = scratch("read_back.h5");
  const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  ASSERT_TRUE(set_direct_write_driver(fapl));
  write_file(path, fapl);
  H5Pclose(fapl);

  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0) << hdf5_reason();
  for (const auto& [name, rows] : std::vector<std::pair<std::string, std::size_t>>{
           {"position", 101'111}, {"velocity", 7}, {"plain", 125'001}, {"radius", 43'690}}) {
    std::vector<double> read(3 * rows);
    const hid_t set = H5Dopen2(file, name.c_str(), H5P_DEFAULT);
    ASSERT_GE(H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, read.data()), 0)
        << name << ": " << read_failure_reason();
    EXPECT_TRUE(read == random_rows(rows, static_cast<unsigned>(rows))) << name;
    H5Dclose(set);
  }
  H5Fclose(file);
  fs::remove_all(path.parent_path());
}

TEST(DirectWriteDriver, BufferedWritesAskedForKeepHdf5sPosixDriver) {
  const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  setenv("GRAINFLOW_BUFFERED_WRITES", "1", 1);
  EXPECT_TRUE(set_direct_write_driver(fapl));
  EXPECT_EQ(H5Pget_driver(fapl), H5FD_SEC2);
  setenv("GRAINFLOW_BUFFERED_WRITES", "0", 1);
  EXPECT_TRUE(set_direct_write_driver(fapl));
  EXPECT_NE(H5Pget_driver(fapl), H5FD_SEC2);
  unsetenv("GRAINFLOW_BUFFERED_WRITES");
  H5Pclose(fapl);
}

TEST(DirectWriteDriver, ANonsenseValueOfTheVariableIsRefusedWithTheAllowedValues) {
  QuietHdf5Errors quiet;
  const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  setenv("GRAINFLOW_BUFFERED_WRITES", "yes", 1);
  const bool set = set_direct_write_driver(fapl);
  const std::string reason = hdf5_reason();  // before any other HDF5 call clears the stack
  unsetenv("GRAINFLOW_BUFFERED_WRITES");
  H5Pclose(fapl);
  EXPECT_FALSE(set);
  EXPECT_NE(reason.find("GRAINFLOW_BUFFERED_WRITES is 'yes'"), std::string::npos) << reason;
  EXPECT_NE(reason.find("allowed values: 0"), std::string::npos) << reason;
}

TEST(DirectWriteDriver, AFileThatCannotBeCreatedFailsWithTheSystemsReason) {
  QuietHdf5Errors quiet;
  const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  ASSERT_TRUE(set_direct_write_driver(fapl));
  const hid_t file = H5Fcreate("/nonexistent_grainflow_dir/x.h5", H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
  EXPECT_LT(file, 0);
  const std::string reason = hdf5_reason();  // before any other HDF5 call clears the stack
  H5Pclose(fapl);
  EXPECT_NE(reason.find("No such file or directory"), std::string::npos) << reason;
}

}  // namespace
}  // namespace grainflow
