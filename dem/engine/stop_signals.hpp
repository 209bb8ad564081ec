#pragma once
// SIGTERM and SIGINT while a run is in progress: the handler only records the signal, and
// the run loop asks, at a step boundary and on every rank at once, whether any rank got
// one — then finishes cleanly (checkpoint, message, exit code 0). The previous handlers
// come back when the object goes. SA_RESETHAND: a second signal of the same kind kills the
// run as usual. Used by `grain run` and by grainFoam, so this header is C++17-clean.
#include <mpi.h>
#include <signal.h>

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

}  // namespace grainflow
