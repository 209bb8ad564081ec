#include "dem/engine/run.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <ostream>

#include "dem/engine/simulation.hpp"
#include "dem/io/log_table.hpp"
#include "dem/io/output_directory.hpp"
#include "dem/io/progress_line.hpp"
#include "dem/io/snapshot_writer.hpp"

namespace grainflow {
namespace {

void print_report(const Simulation& sim, std::ostream& out) {
  const Particles& p = sim.particles();
  double r_min = p.size() ? p.radius[0] : 0, r_max = r_min;
  for (double r : p.radius) {
    r_min = std::min(r_min, r);
    r_max = std::max(r_max, r);
  }
  out << "scene: " << sim.scene().file << "\n"
      << "particles: " << p.size() << " (radius " << r_min << " .. " << r_max << " m)\n"
      << "contact law: " << sim.contact_law_name() << "\n";
  for (const std::string& note : sim.time_step_report().notes) out << note << "\n";
}

}  // namespace

int check_scene(const Scene& scene, std::ostream& out) {
  Simulation sim(scene);
  sim.initialise();  // lists and first forces only: no time step is taken
  print_report(sim, out);
  const TimeStepReport& rep = sim.time_step_report();
  if (rep.dt > 0 && std::isfinite(rep.dt))
    out << "steps to reach t_end = " << scene.time.end << " s: "
        << static_cast<long>(std::ceil(scene.time.end / rep.dt - 0.5)) << "\n";
  return rep.verdict == TimeStepReport::Verdict::refuse ? 1 : 0;
}

RunSummary run_scene(const Scene& scene, const RunOptions& options, MPI_Comm comm,
                     std::ostream& out) {
  const std::string dir = options.output_directory.value_or(scene.output.directory);
  prepare_output_directory(dir);  // before any work: an unwritable directory fails now

  Simulation sim(scene);
  sim.initialise();
  print_report(sim, out);
  if (sim.time_step_report().verdict == TimeStepReport::Verdict::refuse &&
      !options.allow_large_time_step)
    throw SetupError(scene.file + ": error: refusing to run with this time step (see above); "
                                  "lower time.step / time.rayleigh_fraction, or pass "
                                  "--allow-large-dt to run anyway");

  SnapshotWriter snapshots(comm, dir);
  LogTable log(comm, (std::filesystem::path(dir) / "log.csv").string());
  ProgressLine progress(comm, scene.time.end, options.progress && scene.output.progress, out);

  const double dt = sim.dt();
  const double snap_every = scene.output.snapshot_interval.value_or(scene.time.end / 20);
  const double log_every = scene.output.log_interval.value_or(scene.time.end / 200);
  const auto start = std::chrono::steady_clock::now();
  auto wall = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  auto write_log = [&] {
    const Counters& c = sim.counters();
    log.write({sim.time(), c.steps, static_cast<long>(sim.particles().size()),
               sim.kinetic_energy_translational(), sim.kinetic_energy_rotational(),
               c.max_overlap_ratio, c.contacts, c.rebuilds, c.removed, wall()});
  };

  RunSummary sum;
  sum.particles_start = static_cast<long>(sim.particles().size());
  long snap_index = 0, log_index = 0, removed_reported = 0;
  long snap_step = 0, log_step = 0;  // last step written, so the final step is not written twice
  snapshots.write(sim.particles(), sim.time(), 0);
  write_log();
  // The run ends at the step nearest to t_end (within half a step).
  const long total_steps =
      std::max(1L, static_cast<long>(std::ceil(scene.time.end / dt - 0.5 - 1e-9)));
  long particle_steps = 0;
  for (long k = 1; k <= total_steps; ++k) {
    sim.step();
    particle_steps += static_cast<long>(sim.particles().size());
    const double t = sim.time();
    const bool last = k == total_steps;
    if (t >= (log_index + 1) * log_every - 0.5 * dt || (last && log_step != k)) {
      log_step = k;
      log_index = static_cast<long>(std::floor(t / log_every + 0.5));
      write_log();
      // Removals are reported once per log interval, not per particle.
      if (sim.counters().removed > removed_reported) {
        out << "warning: t = " << t << " s: " << sim.counters().removed - removed_reported
            << " particle(s) left the domain through a bounded side and were removed (total "
            << sim.counters().removed << "; see column 'removed' of log.csv)\n";
        removed_reported = sim.counters().removed;
      }
    }
    if (t >= (snap_index + 1) * snap_every - 0.5 * dt || (last && snap_step != k)) {
      snap_step = k;
      snap_index = static_cast<long>(std::floor(t / snap_every + 0.5));
      snapshots.write(sim.particles(), t, k);
    }
    if ((k & 255) == 0 || last)
      progress.update(t, k, static_cast<long>(sim.particles().size()));
  }
  progress.finish();

  sum.steps = sim.counters().steps;
  sum.particles_end = static_cast<long>(sim.particles().size());
  sum.removed = sim.counters().removed;
  sum.rebuilds = sim.counters().rebuilds;
  sum.wall_seconds = wall();
  sum.particle_steps_per_second = sum.wall_seconds > 0 ? particle_steps / sum.wall_seconds : 0;
  out << "done: " << sum.steps << " steps, " << sum.particles_end << " particles ("
      << sum.removed << " removed), " << sum.rebuilds << " neighbour rebuilds, "
      << sum.wall_seconds << " s wall, " << sum.particle_steps_per_second
      << " particle-steps/s\n"
      << "output: " << dir << "/particles.xdmf (open in ParaView), " << dir << "/log.csv\n";
  return sum;
}

}  // namespace grainflow
