#include "dem/engine/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <ostream>
#include <sstream>

#include "dem/engine/checkpoint_series.hpp"
#include "dem/engine/finite_guard.hpp"
#include "dem/engine/simulation.hpp"
#include "dem/engine/stop_signals.hpp"
#include "dem/fluid/fluid_forces.hpp"
#include "dem/io/log_table.hpp"
#include "dem/io/output_directory.hpp"
#include "dem/io/progress_line.hpp"
#include "dem/io/snapshot_writer.hpp"

namespace grainflow {
namespace {

// Rank 0 speaks for the run; the other ranks write into this sink.
std::ostream& speaker(MPI_Comm comm, std::ostream& out) {
  static std::ostream silent(nullptr);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  return rank == 0 ? out : silent;
}

void print_report(const Simulation& sim, MPI_Comm comm, std::ostream& out) {
  const Particles& p = sim.particles();
  double range[2] = {std::numeric_limits<double>::infinity(), 0};
  for (double r : p.radius) {
    range[0] = std::min(range[0], r);
    range[1] = std::max(range[1], r);
  }
  range[0] = -range[0];
  MPI_Allreduce(MPI_IN_PLACE, range, 2, MPI_DOUBLE, MPI_MAX, comm);
  const GlobalState g = sim.global_state();
  const Decomposition& d = sim.decomposition();
  std::ostream& o = speaker(comm, out);
  o << "scene: " << sim.scene().file << "\n"
    << "particles: " << g.particles << " (radius " << -range[0] << " .. " << range[1] << " m)\n"
    << "contact law: " << sim.contact_law_name() << "\n";
  if (d.size() > 1)
    o << "MPI ranks: " << d.size() << " as a " << d.dims()[0] << " x " << d.dims()[1] << " x "
      << d.dims()[2] << " grid\n";
  for (const std::string& note : sim.time_step_report().notes) o << note << "\n";
  for (const std::string& note : sim.walls().notes()) o << note << "\n";  // meshes read
}

}  // namespace

int check_scene(const Scene& scene, std::ostream& out) {
  Simulation sim(scene);
  // The fluid forces too, so that their stability limits are checked as at start-up.
  if (scene.fluid)
    sim.add_force_term(
        make_fluid_forces(*scene.fluid, scene.gravity, scene.domain, MPI_COMM_WORLD));
  sim.initialise();  // lists and first forces only: no time step is taken
  print_report(sim, MPI_COMM_WORLD, out);
  const TimeStepReport& rep = sim.time_step_report();
  if (rep.dt > 0 && std::isfinite(rep.dt))
    speaker(MPI_COMM_WORLD, out) << "steps to reach t_end = " << scene.time.end << " s: "
                                 << static_cast<long>(std::ceil(scene.time.end / rep.dt - 0.5))
                                 << "\n";
  return rep.verdict == TimeStepReport::Verdict::refuse ? 1 : 0;
}

RunSummary run_scene(const Scene& scene, const RunOptions& options, MPI_Comm comm,
                     std::ostream& out) {
  const std::string dir = options.output_directory.value_or(scene.output.directory);
  prepare_output_directory(dir);  // before any work: an unwritable directory fails now
  std::ostream& say = speaker(comm, out);

  // A restart takes its particles from the checkpoint instead of inserting them.
  if (options.restart && options.restart->ends_with(".part"))
    throw OutputError("cannot restart from '" + *options.restart +
                      "': a .part file is a checkpoint that was being written when its run "
                      "was killed, possibly incomplete; restart from a complete "
                      "checkpoint_<step>.h5");
  Simulation sim(scene, !options.restart, comm);
  if (options.restart) sim.restore(read_checkpoint(*options.restart));
  const long first_step = sim.counters().steps;  // 0, or the checkpoint's step
  if (scene.fluid)
    sim.add_force_term(make_fluid_forces(*scene.fluid, scene.gravity, scene.domain, comm));
  sim.initialise();
  print_report(sim, comm, out);
  if (sim.time_step_report().verdict == TimeStepReport::Verdict::refuse &&
      !options.allow_large_time_step)
    throw SetupError(scene.file + ": error: refusing to run with this time step (see above); "
                                  "lower time.step / time.rayleigh_fraction, or pass "
                                  "--allow-large-dt to run anyway");
  guard_finite(sim, has_non_finite(sim.particles()), dir, comm);

  SnapshotWriter snapshots(comm, dir);
  const std::string log_path = (std::filesystem::path(dir) / "log.csv").string();
  std::optional<LogTable> log_table;
  if (options.restart) {
    const std::size_t kept = snapshots.continue_series(first_step);
    log_table.emplace(comm, log_path, first_step);
    say << "restart: from " << *options.restart << " at step " << first_step
        << " (t = " << sim.time() << " s); continuing " << dir
        << "/log.csv and the snapshot series after " << kept << " earlier snapshot(s)\n";
  } else {
    log_table.emplace(comm, log_path);
  }
  LogTable& log = *log_table;
  ProgressLine progress(comm, scene.time.end, options.progress && scene.output.progress, out);
  CheckpointSeries checkpoints(comm, dir, scene.output.checkpoint_keep,
                               options.restart ? first_step : -1);
  for (const std::string& partial : checkpoints.removed_partial())
    say << "note: deleted the partial checkpoint " << partial
        << " (left by a run killed while writing it; never a complete checkpoint)\n";
  if (!checkpoints.warning().empty()) say << checkpoints.warning() << "\n";
  const StopSignals signals(options.handle_stop_signals);

  const double dt = sim.dt();
  const double snap_every = scene.output.snapshot_interval.value_or(scene.time.end / 20);
  const double log_every = scene.output.log_interval.value_or(scene.time.end / 200);
  const double check_every = scene.output.checkpoint_interval.value_or(0);
  const auto start = std::chrono::steady_clock::now();
  auto wall = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  long removed_reported = 0;
  // A failed output write (full disk, lost mount) stops the run on every rank; the message
  // names the checkpoint to continue from.
  const std::string rerun =
      "grain run " + scene.file + (options.output_directory ? " --output " + dir : std::string());
  auto resumable = [&](const OutputError& e) {
    std::string message = e.what();
    if (!message.ends_with('.')) message += '.';
    return OutputError(message + " " + checkpoints.resume_hint(rerun));
  };
  auto write_log = [&] {
    const GlobalState g = sim.global_state();
    try {
      log.write({sim.time(), sim.counters().steps, g.particles, g.kinetic_translational,
                 g.kinetic_rotational, g.max_overlap_ratio, g.contacts, sim.counters().rebuilds,
                 g.removed, wall()});
    } catch (const OutputError& e) {
      throw resumable(e);
    }
    // Removals are reported once per log interval, not per particle.
    if (g.removed > removed_reported) {
      say << "warning: t = " << sim.time() << " s: " << g.removed - removed_reported
          << " particle(s) left the domain through a bounded side and were removed (total "
          << g.removed << "; see column 'removed' of log.csv)\n";
      removed_reported = g.removed;
    }
    return g;
  };
  auto write_checkpoint = [&] {
    try {
      const std::string path = checkpoints.write(sim);
      if (!checkpoints.warning().empty()) say << checkpoints.warning() << "\n";
      return path;
    } catch (const OutputError& e) {
      throw resumable(e);
    }
  };
  auto write_snapshot = [&](double t, long k) {
    try {
      snapshots.write(sim.particles(), t, k);
    } catch (const OutputError& e) {
      throw resumable(e);
    }
  };

  RunSummary sum;
  // Output counters as the uninterrupted run has them at this step: the index of the last
  // interval written, so a restart writes the same steps as the uninterrupted run.
  const double t0 = sim.time();
  auto written = [&](double every) {
    return every > 0 ? static_cast<long>(std::floor((t0 + 0.5 * dt) / every)) : 0L;
  };
  long snap_index = written(snap_every), log_index = written(log_every);
  long check_index = written(check_every);
  long snap_step = first_step, log_step = first_step;  // last step written
  if (!options.restart) {
    write_snapshot(sim.time(), 0);
    sum.particles_start = write_log().particles;
  } else {
    sum.particles_start = sim.global_state().particles;
  }
  long global_particles = sum.particles_start;
  // The run ends at the step nearest to t_end (within half a step).
  const long total_steps =
      std::max(1L, static_cast<long>(std::ceil(scene.time.end / dt - 0.5 - 1e-9)));
  double particle_steps = 0;  // this rank's
  std::ostringstream stop_message;
  for (long k = first_step + 1; k <= total_steps; ++k) {
    sim.step();
    guard_finite_after_step(sim, dir, comm);
    particle_steps += static_cast<double>(sim.particles().size());
    const double t = sim.time();
    const bool last = k == total_steps;
    if (t >= (log_index + 1) * log_every - 0.5 * dt || (last && log_step != k)) {
      log_step = k;
      log_index = static_cast<long>(std::floor(t / log_every + 0.5));
      global_particles = write_log().particles;
    }
    if (t >= (snap_index + 1) * snap_every - 0.5 * dt || (last && snap_step != k)) {
      snap_step = k;
      snap_index = static_cast<long>(std::floor(t / snap_every + 0.5));
      write_snapshot(t, k);
    }
    if (check_every > 0 && !last && t >= (check_index + 1) * check_every - 0.5 * dt) {
      check_index = static_cast<long>(std::floor(t / check_every + 0.5));
      write_checkpoint();
    }
    if ((k & 255) == 0 || last) progress.update(t, k, global_particles);
    // Stop signals are agreed on every 100 steps: one small reduction, so all ranks stop at
    // the same step.
    if (k % 100 == 0 && !last) {
      const int signal = StopSignals::agreed(comm);
      if (signal != 0) {
        if (log_step != k) write_log();
        sum.stop_checkpoint = write_checkpoint();
        stop_message << "grain: received " << StopSignals::name(signal)
                     << "; stopped after step " << k << " (t = " << t
                     << " s) and wrote the checkpoint " << sum.stop_checkpoint
                     << "; continue with: grain run " << scene.file << " --restart "
                     << sum.stop_checkpoint << "\n";
        break;
      }
    }
  }
  progress.finish();
  say << stop_message.str();

  MPI_Allreduce(MPI_IN_PLACE, &particle_steps, 1, MPI_DOUBLE, MPI_SUM, comm);
  const GlobalState g = sim.global_state();
  sum.steps = sim.counters().steps;
  sum.particles_end = g.particles;
  sum.removed = g.removed;
  sum.rebuilds = sim.counters().rebuilds;
  sum.wall_seconds = wall();
  sum.particle_steps_per_second = sum.wall_seconds > 0 ? particle_steps / sum.wall_seconds : 0;
  say << (sum.stop_checkpoint.empty() ? "done: " : "stopped: ") << sum.steps << " steps, "
      << sum.particles_end << " particles (" << sum.removed << " removed), " << sum.rebuilds
      << " neighbour rebuilds, " << sum.wall_seconds << " s wall, " << sum.particle_steps_per_second
      << " particle-steps/s\n"
      << "output: " << dir << "/particles.xdmf (open in ParaView), " << dir << "/log.csv\n";
  const StreamInsertion& streams = sim.streams();
  for (std::size_t k = 0; k < streams.size(); ++k) {
    sum.streams.push_back({streams.count_inserted(k), streams.mass_inserted(k), streams.lag(k)});
    say << "stream " << streams.source(k) << ": " << streams.count_inserted(k) << " particles, "
        << streams.mass_inserted(k) << " kg delivered since t = 0"
        << (streams.lag(k) > 0 ? ", " + std::to_string(streams.lag(k)) + " behind (face blocked)"
                               : std::string())
        << "\n";
  }
  for (const std::string& line : sim.force_term_reports())
    if (!line.empty()) say << line << "\n";
  return sum;
}

}  // namespace grainflow
