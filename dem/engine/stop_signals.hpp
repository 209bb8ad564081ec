#pragma once
// SIGTERM and SIGINT while a run is in progress: the handler only records the signal, and
// the run loop asks, at a step boundary and on every rank at once, whether any rank got
// one — then finishes cleanly (checkpoint, message, exit code 0). The previous handlers
// come back when the object goes. A second signal more than a second after the first kills
// the run as the signal would; one sooner is the same request delivered twice (GNU timeout
// signals the process and its process group). Used by `grain run` and by grainFoam, so this
// header is C++17-clean.
#include <mpi.h>
#include <signal.h>

#include <string>
#include <vector>

namespace grainflow {

class StopSignals {
 public:
  explicit StopSignals(bool install);
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // The signal (SIGTERM or SIGINT) any rank of `comm` received since installation, else 0.
  // Collective: one MPI_Allreduce of an int, so that every rank stops at the same step.
  static int agreed(MPI_Comm comm);
  static const char* name(int signal) { return signal == SIGINT ? "SIGINT" : "SIGTERM"; }

 private:
  bool installed_;
  struct sigaction old_term_ = {};
  struct sigaction old_int_ = {};
};

// SIGTERM and SIGINT during a run's start-up (placing the particles of a large fill, reading a
// checkpoint), which has no step boundary to stop at: the handler prints `message` (a line
// per signal name, formatted here, since a handler may only call async-signal-safe functions),
// removes `files` and then the empty `folders` (the lock and the folders the start made), and
// ends the process with 128 + the signal, as the signal would. Used by `grain run` only.
class StartupSignals {
 public:
  StartupSignals(bool install, bool speak, const std::string& what, std::vector<std::string> files,
                 std::vector<std::string> folders);
  ~StartupSignals();
  StartupSignals(const StartupSignals&) = delete;
  StartupSignals& operator=(const StartupSignals&) = delete;

 private:
  bool installed_;
  struct sigaction old_term_ = {};
  struct sigaction old_int_ = {};
};

}  // namespace grainflow
