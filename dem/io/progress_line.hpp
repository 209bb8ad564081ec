#pragma once
// The terminal progress line of a run, printed by rank 0:
//   t = 0.1234 s / 0.5 s (24.7 %)  step 12345  1.2e5 particle-steps/s  ETA 0:03:12
// On a terminal the line is redrawn in place ('\r', at most twice a second); into a file or
// pipe (batch jobs) a full line is printed at every 10 % of progress or after 30 s of wall
// time, whichever comes first, so logs stay short but a stalled run is still visible.
#include <mpi.h>

#include <chrono>
#include <cstddef>
#include <ostream>
#include <string>

namespace grainflow {

class ProgressLine {
 public:
  enum class Style {
    Automatic,  // Redraw if `out` is std::cout/std::cerr/std::clog attached to a terminal
    Redraw,
    Lines
  };

  // `t_end`: simulated end time [s]. Disabled, or on ranks other than 0, every call is a no-op.
  ProgressLine(MPI_Comm comm, double t_end, bool enabled, std::ostream& out,
               Style style = Style::Automatic);
  // Ends a redrawn line with a newline if finish() was not called (run aborted by an error),
  // so that the error message starts on a line of its own.
  ~ProgressLine();
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  // Cheap when nothing is printed (one clock read); call it every step if convenient.
  // The rate and ETA are measured from the first call.
  void update(double t, long step, long particles);
  // Prints the final line with the total wall time since construction. Idempotent.
  void finish();

 private:
  using Clock = std::chrono::steady_clock;
  std::string status(Clock::time_point now) const;
  void print(const std::string& line, bool final);

  bool active_;
  bool redraw_ = false;
  double t_end_;
  std::ostream& out_;
  Clock::time_point constructed_;
  Clock::time_point first_update_;
  Clock::time_point last_print_;
  bool started_ = false;
  bool finished_ = false;
  bool line_open_ = false;      // a redrawn line without its newline yet
  std::size_t last_width_ = 0;  // of the redrawn line, to blank out a longer previous one
  double next_mark_ = 0.0;      // next progress fraction that prints a line (Lines style)
  double t_first_ = 0.0;
  double t_ = 0.0;
  long step_ = 0;
  double particle_steps_ = 0.0;  // sum of particles x steps since the first update
};

}  // namespace grainflow
