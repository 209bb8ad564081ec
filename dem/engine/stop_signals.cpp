#include "dem/engine/stop_signals.hpp"

#include <unistd.h>

#include <csignal>
#include <ctime>
#include <utility>

namespace grainflow {
namespace {

// The signal that asked the run to stop (0: none). A signal handler can reach nothing but a
// global, and may only store to a volatile sig_atomic_t (C++20 [support.signal]).
volatile std::sig_atomic_t stop_signal = 0;
// When it came (CLOCK_MONOTONIC); written and read by the handler only.
timespec stop_signal_time = {};

// A second signal within this many seconds of the first is the same request delivered twice:
// GNU timeout sends its signal to the process and then to its process group, and a batch
// system may signal both mpiexec and the ranks. Later, it kills the run as the signal would.
constexpr double kSameRequestSeconds = 1.0;

extern "C" void on_stop_signal(int signal) {
  timespec now = {};
  clock_gettime(CLOCK_MONOTONIC, &now);  // async-signal-safe (POSIX)
  if (stop_signal == 0) {
    stop_signal_time = now;
    stop_signal = signal;
    return;
  }
  const double since = static_cast<double>(now.tv_sec - stop_signal_time.tv_sec) +
                       1e-9 * static_cast<double>(now.tv_nsec - stop_signal_time.tv_nsec);
  if (since < kSameRequestSeconds) return;
  // Asked again: the default action, once this handler returns (the signal is blocked in it).
  struct sigaction fallback = {};
  fallback.sa_handler = SIG_DFL;
  sigemptyset(&fallback.sa_mask);
  sigaction(signal, &fallback, nullptr);
  raise(signal);
}

// What the start-up handler needs, prepared before it is installed.
struct Startup {
  std::string term_message, int_message;
  std::vector<std::string> files, folders;
};
Startup* startup = nullptr;

extern "C" void on_startup_signal(int signal) {
  if (startup != nullptr) {
    const std::string& m = signal == SIGINT ? startup->int_message : startup->term_message;
    [[maybe_unused]] const ssize_t n = ::write(2, m.data(), m.size());
    for (const std::string& f : startup->files) ::unlink(f.c_str());
    for (const std::string& d : startup->folders) ::rmdir(d.c_str());  // only if empty
  }
  ::_exit(128 + signal);
}

// Installs `handler` for SIGTERM and SIGINT, keeping the handlers it replaces; restore_handlers
// puts them back.
void install_handlers(void (*handler)(int), int flags, struct sigaction& old_term,
                      struct sigaction& old_int) {
  struct sigaction action = {};
  action.sa_handler = handler;
  sigemptyset(&action.sa_mask);
  action.sa_flags = flags;
  sigaction(SIGTERM, &action, &old_term);
  sigaction(SIGINT, &action, &old_int);
}

void restore_handlers(const struct sigaction& old_term, const struct sigaction& old_int) {
  sigaction(SIGTERM, &old_term, nullptr);
  sigaction(SIGINT, &old_int, nullptr);
}

}  // namespace

StartupSignals::StartupSignals(bool install, bool speak, const std::string& what,
                               std::vector<std::string> files, std::vector<std::string> folders)
    : installed_(install) {
  if (!installed_) return;
  static Startup state;
  state.files = std::move(files);
  state.folders = std::move(folders);
  for (const int signal : {SIGTERM, SIGINT}) {
    std::string& m = signal == SIGINT ? state.int_message : state.term_message;
    m.clear();
    if (speak)
      m = std::string("grain: received ") + StopSignals::name(signal) + " during start-up (" +
          what +
          "); stopped before the first step: nothing was run, no checkpoint or snapshot was "
          "written (a run stops at a step with a checkpoint only once it steps)\n";
  }
  startup = &state;
  install_handlers(on_startup_signal, 0, old_term_, old_int_);
}

StartupSignals::~StartupSignals() {
  if (!installed_) return;
  restore_handlers(old_term_, old_int_);
  startup = nullptr;
}

StopSignals::StopSignals(bool install) : installed_(install) {
  stop_signal = 0;
  if (!installed_) return;
  install_handlers(on_stop_signal, 0, old_term_, old_int_);
}

StopSignals::~StopSignals() {
  // After a stop, the handler stays: the run is ending, and a copy of the same request that
  // comes while it writes its last lines is still the same request (GNU timeout's second
  // SIGTERM had killed runs that had stopped within the millisecond before it).
  if (!installed_ || stop_signal != 0) return;
  restore_handlers(old_term_, old_int_);
}

int StopSignals::agreed(MPI_Comm comm) {
  int signal = stop_signal;
  MPI_Allreduce(MPI_IN_PLACE, &signal, 1, MPI_INT, MPI_MAX, comm);
  return signal;
}

}  // namespace grainflow
