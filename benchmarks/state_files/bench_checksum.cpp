// The cost of the Fletcher32 checksums of checkpoints (docs/reliability.md): a checkpoint of
// 30 000 particles and 90 000 springs (a dense bed: ~3 contacts per particle, each listed under
// both partners), written and read back 20 times each with write_checkpoint / read_checkpoint
// (chunked, checksummed), and the same arrays written and read with the HDF5 C API in the
// contiguous layout without checksums and in the checksummed layout (through HDF5's filter
// and as grain writes it, chunk by chunk with write_checksummed), side by side. Files go
// to the given folder (default: the working directory); the page cache holds them, so the
// times are the CPU cost of HDF5 and the checksum, not of the disk.
//   bench_checksum [DIR]
#include <hdf5.h>
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "dem/io/checkpoint.hpp"
#include "dem/io/hdf5_checksum.hpp"

namespace {

using grainflow::Vec3;
using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct Array {
  std::string name;
  int cols;
  std::vector<double> data;
};

// Writes (or reads back) every array in one file, with or without checksums; returns seconds.
enum class Layout { contiguous, filter, direct };

// `filter`: chunked, HDF5's Fletcher32 filter in H5Dwrite; `direct`: the same layout, each
// chunk and its checksum written by grainflow::write_checksummed (what grain does).
double write_arrays(const std::string& path, const std::vector<Array>& arrays, Layout layout) {
  const bool checksum = layout != Layout::contiguous;
  const auto t0 = Clock::now();
  const hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  for (const Array& a : arrays) {
    const hsize_t dims[2] = {a.data.size() / static_cast<std::size_t>(a.cols),
                             static_cast<hsize_t>(a.cols)};
    const int rank = a.cols > 1 ? 2 : 1;
    const hid_t space = H5Screate_simple(rank, dims, nullptr);
    const hid_t dcpl =
        checksum ? grainflow::checksummed_layout(rank, dims, 8) : H5Pcreate(H5P_DATASET_CREATE);
    const hid_t d =
        H5Dcreate2(f, a.name.c_str(), H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    if (layout == Layout::direct)
      grainflow::write_checksummed(d, rank, dims, 8, a.data.data());
    else
      H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, a.data.data());
    H5Dclose(d);
    H5Pclose(dcpl);
    H5Sclose(space);
  }
  H5Fclose(f);
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double read_arrays(const std::string& path, std::vector<Array>& arrays) {
  const auto t0 = Clock::now();
  const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  for (Array& a : arrays) {
    const hid_t d = H5Dopen2(f, a.name.c_str(), H5P_DEFAULT);
    H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, a.data.data());
    H5Dclose(d);
  }
  H5Fclose(f);
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  const std::filesystem::path dir = argc > 1 ? argv[1] : ".";
  constexpr int kParticles = 30000, kSprings = 90000, kRepeats = 20;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  auto random_vec = [&] { return Vec3(u(rng), u(rng), u(rng)); };

  grainflow::CheckpointData d;
  d.time = 1;
  d.dt = 1e-6;
  d.step = 1000000;
  d.next_id = kParticles + 1;
  for (int i = 0; i < kParticles; ++i) {
    const double r = 5e-4 * (1 + 0.2 * u(rng));
    d.particles.add(i + 1, random_vec(), random_vec(), random_vec(), r, 0, 2500);
    d.particles.force.back() = random_vec();
    d.particles.torque.back() = random_vec();
  }
  for (int k = 0; k < kSprings; ++k)
    d.springs.push_back({k % kParticles + 1, (k * 7) % kParticles + 1, random_vec(), random_vec()});

  // The same numbers as plain arrays: 5 vectors, 4 scalars and the id per particle, 2 ids and
  // 2 vectors per spring (ids and materials as doubles: the sizes are what matter).
  std::vector<Array> arrays;
  for (const char* name : {"position", "velocity", "angular_velocity", "force", "torque"}) {
    Array a{name, 3, {}};
    for (int i = 0; i < 3 * kParticles; ++i) a.data.push_back(u(rng));
    arrays.push_back(a);
  }
  for (const char* name : {"id", "radius", "mass", "inertia", "material"})
    arrays.push_back({name, 1, std::vector<double>(kParticles, 1.0)});
  for (const char* name : {"spring_particle", "spring_partner"})
    arrays.push_back({name, 1, std::vector<double>(kSprings, 2.0)});
  for (const char* name : {"tangential", "rolling"})
    arrays.push_back({name, 3, std::vector<double>(3 * kSprings, 0.5)});

  const std::string plain = (dir / "bench_plain.h5").string();
  const std::string summed = (dir / "bench_checksummed.h5").string();
  const std::string direct = (dir / "bench_direct.h5").string();
  const std::string checkpoint = (dir / "bench_checkpoint.h5").string();
  std::vector<double> w_plain, w_summed, w_direct, r_plain, r_summed, r_direct, w_ckpt, r_ckpt;
  for (int k = 0; k < kRepeats; ++k) {
    w_plain.push_back(write_arrays(plain, arrays, Layout::contiguous));
    w_summed.push_back(write_arrays(summed, arrays, Layout::filter));
    w_direct.push_back(write_arrays(direct, arrays, Layout::direct));
    r_plain.push_back(read_arrays(plain, arrays));
    r_summed.push_back(read_arrays(summed, arrays));
    r_direct.push_back(read_arrays(direct, arrays));
    auto t0 = Clock::now();
    grainflow::write_checkpoint(MPI_COMM_SELF, checkpoint, d);
    w_ckpt.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
    t0 = Clock::now();
    const grainflow::CheckpointData back = grainflow::read_checkpoint(checkpoint);
    r_ckpt.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
    if (back.particles.size() != d.particles.size()) return 1;
  }
  std::printf("%d particles, %d springs; median of %d, ms\n", kParticles, kSprings, kRepeats);
  std::printf("arrays, contiguous, no checksum: write %.2f  read %.2f  (%ju bytes)\n",
              1e3 * median(w_plain), 1e3 * median(r_plain),
              static_cast<std::uintmax_t>(std::filesystem::file_size(plain)));
  std::printf("arrays, chunked + Fletcher32, HDF5's filter:  write %.2f  read %.2f  (%ju bytes)\n",
              1e3 * median(w_summed), 1e3 * median(r_summed),
              static_cast<std::uintmax_t>(std::filesystem::file_size(summed)));
  std::printf("arrays, chunked + Fletcher32, direct chunks: write %.2f  read %.2f  (%ju bytes)\n",
              1e3 * median(w_direct), 1e3 * median(r_direct),
              static_cast<std::uintmax_t>(std::filesystem::file_size(direct)));
  std::printf("write_checkpoint / read_checkpoint: write %.2f  read %.2f  (%ju bytes)\n",
              1e3 * median(w_ckpt), 1e3 * median(r_ckpt),
              static_cast<std::uintmax_t>(std::filesystem::file_size(checkpoint)));
  for (const std::string& p : {plain, summed, direct, checkpoint}) std::filesystem::remove(p);
  MPI_Finalize();
  return 0;
}
