#pragma once
// A whole `grain run`: set-up, time-step check, the step loop with snapshots,
// log rows and a progress line, and a closing summary.
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include <mpi.h>

#include "dem/scene/scene.hpp"

namespace grainflow {

struct RunOptions {
  std::optional<std::string> output_directory;  // overrides the scene's
  bool progress = true;                         // AND-ed with the scene's setting
  bool allow_large_time_step = false;           // run even when the check refuses dt
  std::optional<std::string> restart;           // checkpoint to continue from (--restart)
  bool handle_stop_signals = true;              // SIGTERM/SIGINT: checkpoint and stop
  std::string program = "grain";                // as invoked (argv[0]), for "continue with"
};

// The command that continues this run from `checkpoint`, for "continue with:" messages: run
// literally from the same working directory, it writes into the same output directory and
// continues its snapshot numbering. It repeats the program as invoked, `mpirun -np N` when
// the run has N > 1 ranks, the scene and every option given except --restart (--output,
// --allow-large-dt, --no-progress), each quoted for a POSIX shell when needed.
std::string continue_command(const std::string& scene_file, const RunOptions& options, int ranks,
                             const std::string& checkpoint);

struct RunSummary {
  long steps = 0;
  long particles_start = 0, particles_end = 0;
  long removed = 0;
  long rebuilds = 0;
  double wall_seconds = 0;
  double particle_steps_per_second = 0;
  // Start-up: from run_scene's entry to the time loop (insertion or restore, first neighbour
  // lists and forces) plus the first snapshot of a fresh run. Snapshots: all files written by
  // this run, their bytes on disk and the seconds spent writing them (rank 0's clock).
  double startup_seconds = 0;
  double snapshot_seconds = 0, snapshot_bytes = 0;
  long snapshot_files = 0;
  std::string stop_checkpoint;  // set when a SIGTERM/SIGINT stopped the run early
  struct StreamTotal {
    long count = 0;   // particles delivered since t = 0 (a restart continues the count)
    double mass = 0;  // kg
    long lag = 0;     // particles behind the target at the end
  };
  std::vector<StreamTotal> streams;  // one per stream insertion, in scene order
};

// What to do about a time step the check refuses: "use dt <= <s> s (time.step, or
// time.rayleigh_fraction <= <f>), the smallest step proposed above, which every limit above
// allows", or to lower the step when no limit proposes one.
struct TimeStepReport;
std::string refusal_remedy(const TimeStepReport& rep);

// Prints the time-step report (`grain check`); returns the process exit code:
// 0 fine, 1 refused. With `restart`, the checkpoint is read, verified and checked against the
// scene as `grain run --restart` would, and the report judges its state; nothing is written.
int check_scene(const Scene& scene, std::ostream& out,
                const std::optional<std::string>& restart = std::nullopt);

// Throws SceneError / SetupError / InsertionError / OutputError with a message for the user.
RunSummary run_scene(const Scene& scene, const RunOptions& options, MPI_Comm comm,
                     std::ostream& out);

}  // namespace grainflow
