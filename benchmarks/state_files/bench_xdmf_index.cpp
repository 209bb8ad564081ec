// The cost of keeping the XDMF index of a snapshot series current (docs/reliability.md): 1000
// snapshots of 2 particles (default fields), the index updated after each, side by side:
//   rewrite  the whole index rendered and replaced atomically (write_file_atomically: a
//            temporary file, fsync, rename) at every snapshot, as before the append existed;
//   append   XdmfIndexFile: written whole once, then five pwrite calls per snapshot, no fsync.
// Each scheme runs `rounds` times, alternating, in the given folder (default: the working
// directory); the table gives the median seconds for the series and the bytes written.
//   bench_xdmf_index [DIR] [SNAPSHOTS] [ROUNDS]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "dem/io/xdmf_index.hpp"
#include "dem/io/xdmf_index_file.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

std::vector<grainflow::XdmfEntry> series(int n) {
  std::vector<grainflow::XdmfEntry> entries;
  for (int k = 0; k < n; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "particles_%06d.h5", k);
    entries.push_back({name, 1e-3 * k, 100L * k, 2});
  }
  return entries;
}

double rewrite(const std::string& path, const std::vector<grainflow::XdmfEntry>& all,
               double& bytes) {
  const auto t0 = Clock::now();
  std::vector<grainflow::XdmfEntry> listed;
  bytes = 0;
  for (const grainflow::XdmfEntry& e : all) {
    listed.push_back(e);
    const std::string text = grainflow::render_xdmf(listed, "particles");
    grainflow::write_file_atomically(path, text);
    bytes += static_cast<double>(text.size());
  }
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double append(const std::string& path, const std::vector<grainflow::XdmfEntry>& all,
              double& bytes) {
  // The bytes of the plan (the same writes XdmfIndexFile makes), counted before the clock runs.
  grainflow::XdmfIndexLayout layout;
  bytes = static_cast<double>(
      grainflow::render_xdmf_appendable({all.front()}, "particles", layout).size());
  for (std::size_t k = 1; k < all.size(); ++k) {
    grainflow::XdmfIndexLayout next;
    for (const auto& w :
         grainflow::plan_xdmf_append(layout, grainflow::render_xdmf_entry(all[k]), next))
      bytes += static_cast<double>(w.bytes.size());
    layout = next;
  }
  const auto t0 = Clock::now();
  grainflow::XdmfIndexFile index(path, "particles", {all.front()});
  for (std::size_t k = 1; k < all.size(); ++k) index.append(all[k]);
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path dir = argc > 1 ? argv[1] : ".";
  const int snapshots = argc > 2 ? std::atoi(argv[2]) : 1000;
  const int rounds = argc > 3 ? std::atoi(argv[3]) : 3;
  std::filesystem::create_directories(dir);
  const auto all = series(snapshots);
  std::vector<double> t_rewrite, t_append;
  double b_rewrite = 0, b_append = 0;
  for (int r = 0; r < rounds; ++r) {
    t_rewrite.push_back(rewrite((dir / "rewrite.xdmf").string(), all, b_rewrite));
    t_append.push_back(append((dir / "append.xdmf").string(), all, b_append));
  }
  std::printf(
      "| index update (%d snapshots of 2 particles) | median s (%d rounds) | bytes written |\n",
      snapshots, rounds);
  std::printf("|---|---|---|\n");
  std::printf("| rewrite + fsync + rename each time | %.3f | %.0f |\n", median(t_rewrite),
              b_rewrite);
  std::printf("| append (XdmfIndexFile) | %.4f | %.0f |\n", median(t_append), b_append);
  std::printf("ratio rewrite / append: %.0f x in time, %.0f x in bytes\n",
              median(t_rewrite) / median(t_append), b_rewrite / b_append);
  return 0;
}
