// Checksums of grainflow's files (dem/io/hdf5_checksum.hpp) against HDF5's own Fletcher32
// filter: the value it stores after a chunk, and a file written chunk by chunk with our
// checksums read back through HDF5's verifying read.
#include "dem/io/hdf5_checksum.hpp"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <cstdint>
#include <random>
#include <vector>

namespace grainflow {
namespace {

// An HDF5 file held in memory (core driver, nothing on disk).
hid_t memory_file() {
  const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  H5Pset_fapl_core(fapl, 1 << 20, false);
  static int count = 0;
  const std::string name = "checksum_test_" + std::to_string(count++) + ".h5";
  const hid_t file = H5Fcreate(name.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
  H5Pclose(fapl);
  return file;
}

// Writes `bytes` as one chunk through HDF5's Fletcher32 filter and returns the chunk as
// stored (data, then the 4-byte checksum).
std::vector<unsigned char> stored_by_hdf5(const std::vector<unsigned char>& bytes) {
  const hid_t file = memory_file();
  const hsize_t dims[1] = {bytes.size()};
  const hid_t space = H5Screate_simple(1, dims, nullptr);
  const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  H5Pset_chunk(dcpl, 1, dims);
  H5Pset_fletcher32(dcpl);
  const hid_t set = H5Dcreate2(file, "d", H5T_NATIVE_UCHAR, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  EXPECT_GE(H5Dwrite(set, H5T_NATIVE_UCHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, bytes.data()), 0);
  H5Dflush(set);
  hsize_t stored = 0;
  const hsize_t origin[1] = {0};
  EXPECT_GE(H5Dget_chunk_storage_size(set, origin, &stored), 0);
  std::vector<unsigned char> chunk(stored);
  std::uint32_t filters = 0;
  EXPECT_GE(H5Dread_chunk(set, H5P_DEFAULT, origin, &filters, chunk.data()), 0);
  EXPECT_EQ(filters, 0u);
  H5Dclose(set);
  H5Pclose(dcpl);
  H5Sclose(space);
  H5Fclose(file);
  return chunk;
}

std::uint32_t little_endian(const unsigned char* p) {
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 |
         std::uint32_t{p[3]} << 24;
}

TEST(Fletcher32, EqualsTheValueHdf5StoresForEveryLengthAndPattern) {
  std::mt19937 rng(7);
  // Lengths around the eight-word lanes and the 256-iteration blocks, odd ones, and a whole
  // 1 MiB chunk; patterns: random, all 0xff (the largest sums), all zero, one late non-zero
  // byte, and words summing to multiples of 65535.
  for (std::size_t n : {1u, 2u, 3u, 15u, 16u, 17u, 31u, 4095u, 4096u, 4097u, 4102u, 8191u,
                        100001u, 1u << 20}) {
    for (int pattern = 0; pattern < 5; ++pattern) {
      std::vector<unsigned char> bytes(n, 0);
      for (std::size_t i = 0; i < n; ++i) {
        if (pattern == 0) bytes[i] = static_cast<unsigned char>(rng());
        if (pattern == 1) bytes[i] = 0xff;
        if (pattern == 4) bytes[i] = (i % 4 < 2) ? 0xff : 0x00;  // 0xffff, 0x0000, ...
      }
      if (pattern == 3) bytes[n - 1] = 1;
      const std::vector<unsigned char> chunk = stored_by_hdf5(bytes);
      ASSERT_EQ(chunk.size(), n + 4) << n;
      EXPECT_EQ(fletcher32(bytes.data(), n), little_endian(chunk.data() + n))
          << n << " bytes, pattern " << pattern;
    }
  }
}

TEST(WriteChecksummed, GivesTheFilterPathsChunksAndHdf5VerifiesThemOnReading) {
  // 100 000 rows of three doubles: three chunks of 33 334 rows, the last one 2 rows short.
  const hsize_t dims[2] = {100000, 3};
  ASSERT_EQ(checksum_chunk_rows(2, dims, 8), 33334u);
  std::vector<double> values(dims[0] * dims[1]);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (double& v : values) v = u(rng);

  const hid_t file = memory_file();
  const hid_t space = H5Screate_simple(2, dims, nullptr);
  const hid_t dcpl = checksummed_layout(2, dims, 8);
  const hid_t direct =
      H5Dcreate2(file, "direct", H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  const hid_t filtered =
      H5Dcreate2(file, "filtered", H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  ASSERT_TRUE(write_checksummed(direct, 2, dims, 8, values.data()));
  ASSERT_GE(H5Dwrite(filtered, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0);
  H5Dflush(filtered);

  // Every whole chunk is stored byte for byte as the filter stores it, checksum included.
  const std::size_t chunk_bytes = 33334 * 24 + 4;
  for (hsize_t first : {hsize_t{0}, hsize_t{33334}}) {
    const hsize_t offset[2] = {first, 0};
    std::vector<unsigned char> a(chunk_bytes), b(chunk_bytes);
    std::uint32_t fa = 1, fb = 1;
    ASSERT_GE(H5Dread_chunk(direct, H5P_DEFAULT, offset, &fa, a.data()), 0);
    ASSERT_GE(H5Dread_chunk(filtered, H5P_DEFAULT, offset, &fb, b.data()), 0);
    EXPECT_EQ(fa, 0u);
    EXPECT_EQ(a, b) << "chunk at row " << first;
  }
  // HDF5's own read, which runs the filter and checks each chunk, returns the data.
  std::vector<double> back(values.size(), 0.0);
  ASSERT_GE(H5Dread(direct, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, back.data()), 0);
  EXPECT_EQ(back, values);

  // A chunk whose data no longer match its checksum fails that read.
  const hsize_t last[2] = {66668, 0};
  std::vector<unsigned char> chunk(chunk_bytes);
  std::uint32_t filters = 0;
  ASSERT_GE(H5Dread_chunk(direct, H5P_DEFAULT, last, &filters, chunk.data()), 0);
  chunk[100] ^= 0x10;
  ASSERT_GE(H5Dwrite_chunk(direct, H5P_DEFAULT, 0, last, chunk_bytes, chunk.data()), 0);
  H5E_BEGIN_TRY { EXPECT_LT(H5Dread(direct, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, back.data()), 0); }
  H5E_END_TRY

  H5Dclose(direct);
  H5Dclose(filtered);
  H5Pclose(dcpl);
  H5Sclose(space);
  H5Fclose(file);
}

}  // namespace
}  // namespace grainflow
