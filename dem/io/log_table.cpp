#include "dem/io/log_table.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "dem/io/output_directory.hpp"
#include "dem/io/xdmf_index.hpp"

namespace grainflow {

namespace {
std::string full_header(const std::vector<std::string>& extra) {
  std::string h = LogTable::header;
  for (const std::string& name : extra) h += "," + name;
  return h;
}
}  // namespace

LogTable::LogTable(MPI_Comm comm, const std::string& path, const std::vector<std::string>& extra)
    : comm_(comm), path_(path), header_(full_header(extra)), extra_(extra.size()) {
  MPI_Comm_rank(comm_, &rank_);
  int err = 0;
  if (rank_ == 0) {
    errno = 0;
    file_ = std::fopen(path_.c_str(), "w");
    if (!file_)
      err = errno ? errno : EIO;
    else if (std::fprintf(file_, "%s\n", header_.c_str()) < 0 || std::fflush(file_) != 0)
      err = errno ? errno : EIO;
    if (err && file_) {
      std::fclose(file_);
      file_ = nullptr;
    }
  }
  agree(err, "cannot create the log table");
}

LogTable::LogTable(MPI_Comm comm, const std::string& path, long continue_after_step,
                   const std::vector<std::string>& extra)
    : comm_(comm), path_(path), header_(full_header(extra)), extra_(extra.size()) {
  MPI_Comm_rank(comm_, &rank_);
  int err = 0;
  if (rank_ == 0) {
    std::ifstream in(path_);
    std::string line;
    std::string kept;
    if (in && std::getline(in, line) && line == header_) {
      kept = line + "\n";
      while (std::getline(in, line)) {
        // A row without its newline was cut short (by a kill, or a full disk's short write);
        // even its step may be cut. It and anything after it are dropped.
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
  }
  agree(err, "cannot continue the log table");
}

LogTable::~LogTable() {
  if (file_) std::fclose(file_);
}

void LogTable::write(const LogRow& r) {
  int err = 0;
  if (rank_ == 0) {
    errno = 0;
    const int n =
        std::fprintf(file_, "%.17g,%ld,%ld,%.17g,%.17g,%.17g,%ld,%ld,%ld,%.17g", r.time, r.step,
                     r.particles, r.kinetic_translational, r.kinetic_rotational,
                     r.max_overlap_ratio, r.contacts, r.rebuilds, r.removed, r.wall_seconds);
    bool ok = n >= 0;
    for (std::size_t k = 0; k < extra_ && ok; ++k)
      ok = std::fprintf(file_, ",%.17g", k < r.extra.size() ? r.extra[k] : 0.0) >= 0;
    if (!ok || std::fputc('\n', file_) == EOF || std::fflush(file_) != 0) err = errno ? errno : EIO;
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
