#include "dem/io/log_table.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <utility>

#include "dem/io/output_directory.hpp"
#include "dem/io/xdmf_index.hpp"

namespace grainflow {

namespace {
std::string full_header(const std::vector<std::string>& extra) {
  std::string h = LogTable::header;
  for (const std::string& name : extra) h += "," + name;
  return h;
}

// The rows of a table's text (lines after the header), and the step of its last row (-1: none).
std::pair<long, long> rows_and_last_step(const std::string& text) {
  long rows = -1, last = -1;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line); ++rows) {
    const auto comma = line.find(',');
    if (rows >= 0 && comma != std::string::npos)
      last = std::strtol(line.c_str() + comma + 1, nullptr, 10);
  }
  return {std::max(rows, 0L), last};
}

// One row as the file holds it, newline included: doubles with 17 significant digits.
std::string format_row(const LogRow& r, std::size_t extra) {
  char buffer[400];
  const int n =
      std::snprintf(buffer, sizeof buffer, "%.17g,%ld,%ld,%.17g,%.17g,%.17g,%ld,%ld,%ld,%.17g",
                    r.time, r.step, r.particles, r.kinetic_translational, r.kinetic_rotational,
                    r.max_overlap_ratio, r.contacts, r.rebuilds, r.removed, r.wall_seconds);
  std::string line(buffer, static_cast<std::size_t>(std::max(n, 0)));
  for (std::size_t k = 0; k < extra; ++k) {
    const int m =
        std::snprintf(buffer, sizeof buffer, ",%.17g", k < r.extra.size() ? r.extra[k] : 0.0);
    line.append(buffer, static_cast<std::size_t>(std::max(m, 0)));
  }
  line += '\n';
  return line;
}
}  // namespace

LogTable::LogTable(MPI_Comm comm, const std::string& path, const std::vector<std::string>& extra)
    : comm_(comm), path_(path), header_(full_header(extra)), extra_(extra.size()) {
  MPI_Comm_rank(comm_, &rank_);
  int err = 0;
  if (rank_ == 0) {
    // A new file, not the old one truncated: a hard link to it elsewhere (a `cp -al` backup
    // of the folder) keeps the earlier run's log.
    std::remove(path_.c_str());
    errno = 0;
    file_ = std::fopen(path_.c_str(), "w");
    if (!file_)
      err = errno ? errno : EIO;
    else if (std::fprintf(file_, "%s\n", header_.c_str()) < 0 || std::fflush(file_) != 0)
      err = errno ? errno : EIO;
    record_ = header_ + "\n";
    if (err && file_) {
      std::fclose(file_);
      file_ = nullptr;
    }
  }
  agree(err, "cannot create the log table");
}

LogTable::LogTable(MPI_Comm comm, const std::string& path, long continue_after_step,
                   const std::vector<std::string>& extra, const std::optional<std::string>& record)
    : comm_(comm), path_(path), header_(full_header(extra)), extra_(extra.size()) {
  MPI_Comm_rank(comm_, &rank_);
  int err = 0;
  if (rank_ == 0) {
    std::ifstream in(path_, std::ios::binary);
    std::string kept;
    if (record) {
      const std::string existing{std::istreambuf_iterator<char>(in), {}};
      const bool same_columns = record->starts_with(header_ + "\n");
      kept = same_columns ? *record : header_ + "\n";
      const auto [rows, last] = rows_and_last_step(kept);
      std::ostringstream note;
      if (!same_columns)
        note << path_ << " starts afresh: the checkpoint's copy of the log has other columns "
             << "than this run's (output.wall_loads differs), so its rows are not continued";
      else if (!in.is_open())
        note << path_ << " was missing: restored from the checkpoint's copy (" << rows
             << " row(s), up to step " << last << ")";
      else if (!existing.starts_with(kept))
        note << path_ << " held rows that the checkpoint's run did not write (another run's "
             << "log, or changed since): replaced by the checkpoint's copy (" << rows
             << " row(s), up to step " << last << ")";
      note_ = note.str();
    } else {
      std::string line;
      if (in && std::getline(in, line) && line == header_) {
        kept = line + "\n";
        while (std::getline(in, line)) {
          // A row without its newline was cut short (by a kill, or a full disk's short
          // write); even its step may be cut. It and anything after it are dropped.
          if (in.eof()) break;
          const auto comma = line.find(',');
          if (comma == std::string::npos) break;
          const long step = std::strtol(line.c_str() + comma + 1, nullptr, 10);
          if (step > continue_after_step) break;
          kept += line + "\n";
        }
      } else {
        kept = header_ + "\n";
      }
    }
    in.close();
    try {
      write_file_atomically(path_, kept);
    } catch (const OutputError&) {
      err = EIO;
    }
    if (!err) {
      errno = 0;
      file_ = std::fopen(path_.c_str(), "a");
      if (!file_) err = errno ? errno : EIO;
    }
    record_ = std::move(kept);
  }
  agree(err, "cannot continue the log table");
}

LogTable::~LogTable() {
  if (file_) std::fclose(file_);
}

void LogTable::write(const LogRow& r, bool recorded) {
  int err = 0;
  if (rank_ == 0) {
    const std::string line = format_row(r, extra_);
    errno = 0;
    if (std::fputs(line.c_str(), file_) == EOF || std::fflush(file_) != 0)
      err = errno ? errno : EIO;
    if (recorded && !record_dropped_) {
      if (record_.size() + line.size() > record_limit_) {
        record_dropped_ = true;
        std::string().swap(record_);
      } else {
        record_ += line;
      }
    }
  }
  agree(err, "cannot append to the log table");
}

void LogTable::agree(int error_number, const char* what) {
  MPI_Bcast(&error_number, 1, MPI_INT, 0, comm_);
  if (error_number != 0)
    throw OutputError(std::string(what) + " '" + path_ + "': " + std::strerror(error_number) +
                      ". Check free space and permissions of the output directory.");
}

}  // namespace grainflow
