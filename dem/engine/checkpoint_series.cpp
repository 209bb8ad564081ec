#include "dem/engine/checkpoint_series.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <system_error>
#include <vector>

#include "dem/engine/simulation.hpp"
#include "dem/io/checkpoint.hpp"

namespace grainflow {

namespace fs = std::filesystem;

std::string CheckpointSeries::file_name(long step) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "checkpoint_%09ld.h5", step);
  return buf;
}

namespace {

// The step of `name` if it is `checkpoint_<9 digits>.h5` followed by `suffix`, else -1.
long step_of(const std::string& name, const std::string& suffix) {
  const std::string plain = CheckpointSeries::file_name(0);
  if (name.size() != plain.size() + suffix.size() ||
      name.compare(plain.size(), suffix.size(), suffix) != 0)
    return -1;
  long step = -1;
  int used = 0;
  const std::string stem = name.substr(0, plain.size());
  if (std::sscanf(stem.c_str(), "checkpoint_%9ld.h5%n", &step, &used) != 1 ||
      used != static_cast<int>(stem.size()))
    return -1;
  return step;
}

// The lines of a model record, sorted: the same model in another order compares equal.
std::vector<std::string> sorted_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    lines.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  std::sort(lines.begin(), lines.end());
  return lines;
}

}  // namespace

bool CheckpointSeries::is_foreign(const std::string& path) const {
  if (!record_.empty()) {
    const std::optional<std::string> theirs = read_checkpoint_insertions(path);
    if (theirs && *theirs != record_) return true;
  }
  if (!model_.empty()) {
    const std::optional<std::string> theirs = read_checkpoint_model(path);
    if (theirs && sorted_lines(*theirs) != sorted_lines(model_)) return true;
  }
  return false;
}

CheckpointSeries::CheckpointSeries(MPI_Comm comm, std::string directory, int keep,
                                   long adopt_up_to_step, const std::string& record,
                                   const std::string& model)
    : comm_(comm),
      directory_(std::move(directory)),
      keep_(std::max(1, keep)),
      record_(record),
      model_(model) {
  MPI_Comm_rank(comm_, &rank_);
  std::vector<std::string> found;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(directory_, ec)) {
    const std::string name = e.path().filename().string();
    const long step = step_of(name, "");
    if (adopt_up_to_step >= 0 && step >= 0 && step <= adopt_up_to_step) {
      if (is_foreign(e.path().string()))
        foreign_.push_back(e.path().string());
      else
        found.push_back(e.path().string());
    }
    // A killed run's partial file: a later write of the same step would replace it, but
    // it must never be mistaken for a checkpoint nor pile up.
    if (rank_ == 0 && step_of(name, ".part") >= 0) {
      std::error_code rm;
      fs::remove(e.path(), rm);
      removed_partial_.push_back(e.path().string());
      if (rm)
        warning_ = "warning: could not delete the partial checkpoint '" + e.path().string() +
                   "' of an earlier run: " + rm.message();
    }
  }
  std::sort(found.begin(), found.end());  // 9-digit steps: name order is step order
  std::sort(foreign_.begin(), foreign_.end());
  if (!found.empty()) newest_ = found.back();
  if (rank_ == 0) files_.assign(found.begin(), found.end());
}

std::string CheckpointSeries::write(Simulation& sim) {
  const std::string path = (fs::path(directory_) / file_name(sim.counters().steps)).string();
  // Another scene's checkpoint under this name (beyond the adopted step): written over, said.
  std::string over;
  if (rank_ == 0 && std::find(files_.begin(), files_.end(), path) == files_.end()) {
    std::error_code ec;
    if (fs::exists(path, ec) && is_foreign(path)) over = path;
  }
  sim.write_checkpoint(path);  // <path>.part, then renamed: complete before anything is deleted
  newest_ = path;
  warning_.clear();
  if (!over.empty())
    warning_ = "note: wrote this run's checkpoint over " + over +
               ", which another scene's run had written (its record of insertions or model "
               "differs): give each run its own --output";
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

std::string CheckpointSeries::resume_hint(const std::string& command) const {
  if (newest_.empty()) return "No complete checkpoint of this run exists yet.";
  return "The newest complete checkpoint is '" + newest_ + "' (untouched); free space and " +
         "continue with: " + command;
}

}  // namespace grainflow
