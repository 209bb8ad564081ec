#pragma once
// The run's log table: one CSV row per log interval, readable by any spreadsheet, by
// numpy.genfromtxt(names=True) and by scripts/plot_log.py. Column names carry their units.
#include <mpi.h>

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace grainflow {

// One row; every value is already global (reduced over ranks) when passed in.
struct LogRow {
  double time;                   // simulated time [s]
  long step;                     // time-step count
  long particles;                // particles in the domain
  double kinetic_translational;  // sum of m v^2 / 2 [J]
  double kinetic_rotational;     // sum of I omega^2 / 2 [J]
  double max_overlap_ratio;      // largest contact overlap / radius of the smaller particle [-]
  long contacts;                 // active particle-particle and particle-wall contacts
  long rebuilds;                 // neighbour-list rebuilds since the previous row
  long removed;                  // particles removed (left the domain) since the previous row
  double wall_seconds;           // wall-clock time since the start of the run [s]
  std::vector<double> extra = {};  // one value per extra column (LogTable's constructors)
};

class LogTable {
 public:
  static constexpr const char* header =
      "time_s,step,particles,ke_trans_J,ke_rot_J,max_overlap_ratio,contacts,rebuilds,removed,"
      "wall_s";

  // Collective: rank 0 creates (truncates) `path` and writes the header, `header` followed
  // by the `extra` column names (each row then carries as many LogRow::extra values); every
  // rank throws OutputError naming the path if that fails.
  LogTable(MPI_Comm comm, const std::string& path, const std::vector<std::string>& extra = {});
  // Collective: continues the table of a restarted run, then appends.
  // With `record` (the checkpoint's copy of the table up to its step, record() of the run that
  // wrote it): the table becomes that copy, whatever the file holds — rows a stopped run wrote
  // after its checkpoint, another run's log, an edited or a missing file (note() says which);
  // a copy with other columns than this run's (output.wall_loads changed) starts a new table.
  // Without it (a checkpoint written before it had the copy): rank 0 keeps the file's header and
  // rows with step <= `continue_after_step`; a missing file, or one with another header, is
  // replaced by a new table.
  LogTable(MPI_Comm comm, const std::string& path, long continue_after_step,
           const std::vector<std::string>& extra = {},
           const std::optional<std::string>& record = std::nullopt);
  ~LogTable();
  LogTable(const LogTable&) = delete;
  LogTable& operator=(const LogTable&) = delete;

  // Collective: rank 0 appends the row (doubles with 17 significant digits, so they read back
  // exactly) and flushes it, so a killed run keeps its log up to the last row. Every rank
  // throws OutputError if the write fails (disk full), so no rank runs on without a log.
  // `recorded` false: the row is written to the file but left out of record(), so that a
  // restart from the checkpoint written next drops it (the row a stop signal adds at the stop
  // step, which the uninterrupted run does not write).
  void write(const LogRow& row, bool recorded = true);

  const std::string& path() const { return path_; }
  // Rank 0: the table's text (header and recorded rows) as a checkpoint stores it; other ranks,
  // and a table whose text grew beyond record_limit() bytes: empty (its checkpoints then keep no
  // copy, and a restart keeps the file's rows up to its step).
  const std::string& record() const { return record_; }
  // 64 MiB by default (about 300 000 rows): a log written every step of a long run is not
  // copied into memory and into every checkpoint.
  std::size_t record_limit() const { return record_limit_; }
  void set_record_limit(std::size_t bytes) { record_limit_ = bytes; }
  // Rank 0, after the continuing constructor: what the restart replaced, as a sentence, or "".
  const std::string& note() const { return note_; }

 private:
  void agree(int error_number, const char* what);

  MPI_Comm comm_;
  int rank_ = 0;
  std::string path_;
  std::string header_;  // header and the extra columns
  std::size_t extra_ = 0;
  std::FILE* file_ = nullptr;  // open on rank 0 only
  std::string record_;         // rank 0
  std::size_t record_limit_ = std::size_t{64} << 20;
  bool record_dropped_ = false;  // record_ grew beyond the limit
  std::string note_;           // rank 0
};

}  // namespace grainflow
