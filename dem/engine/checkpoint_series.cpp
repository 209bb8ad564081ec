#include "dem/engine/checkpoint_series.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <system_error>
#include <vector>

#include "dem/engine/simulation.hpp"

namespace grainflow {

namespace fs = std::filesystem;

std::string CheckpointSeries::file_name(long step) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "checkpoint_%09ld.h5", step);
  return buf;
}

CheckpointSeries::CheckpointSeries(MPI_Comm comm, std::string directory, int keep,
                                   long adopt_up_to_step)
    : comm_(comm), directory_(std::move(directory)), keep_(std::max(1, keep)) {
  MPI_Comm_rank(comm_, &rank_);
  if (rank_ != 0 || adopt_up_to_step < 0) return;
  std::vector<std::string> found;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(directory_, ec)) {
    const std::string name = e.path().filename().string();
    long step = -1;
    int used = 0;
    if (name.size() == file_name(0).size() &&
        std::sscanf(name.c_str(), "checkpoint_%9ld.h5%n", &step, &used) == 1 &&
        used == static_cast<int>(name.size()) && step <= adopt_up_to_step)
      found.push_back(e.path().string());
  }
  std::sort(found.begin(), found.end());  // 9-digit steps: name order is step order
  files_.assign(found.begin(), found.end());
}

std::string CheckpointSeries::write(Simulation& sim) {
  const std::string path = (fs::path(directory_) / file_name(sim.counters().steps)).string();
  sim.write_checkpoint(path);  // <path>.part, then renamed: complete before anything is deleted
  warning_.clear();
  if (rank_ == 0) {
    if (files_.empty() || files_.back() != path) files_.push_back(path);
    while (static_cast<int>(files_.size()) > keep_) {
      std::error_code ec;
      fs::remove(files_.front(), ec);
      if (ec)
        warning_ = "warning: could not delete the old checkpoint '" + files_.front() +
                   "': " + ec.message();
      files_.pop_front();
    }
  }
  return path;
}

}  // namespace grainflow
