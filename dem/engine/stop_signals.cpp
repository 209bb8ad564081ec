#include "dem/engine/stop_signals.hpp"

#include <csignal>

namespace grainflow {
namespace {

// The signal that asked the run to stop (0: none). A signal handler can reach nothing but a
// global, and may only store to a volatile sig_atomic_t (C++20 [support.signal]).
volatile std::sig_atomic_t stop_signal = 0;

extern "C" void on_stop_signal(int signal) { stop_signal = signal; }

}  // namespace

StopSignals::StopSignals(bool install) : installed_(install) {
  stop_signal = 0;
  if (!installed_) return;
  struct sigaction action = {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;
  sigaction(SIGTERM, &action, &old_term_);
  sigaction(SIGINT, &action, &old_int_);
}

StopSignals::~StopSignals() {
  if (!installed_) return;
  sigaction(SIGTERM, &old_term_, nullptr);
  sigaction(SIGINT, &old_int_, nullptr);
}

int StopSignals::agreed(MPI_Comm comm) {
  int signal = stop_signal;
  MPI_Allreduce(MPI_IN_PLACE, &signal, 1, MPI_INT, MPI_MAX, comm);
  return signal;
}

}  // namespace grainflow
