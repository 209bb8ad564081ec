// `grain run --restart` continues a run: run_scene to T with a checkpoint at T/2, then a
// restart from that checkpoint to T, both on 2 ranks, must end where the uninterrupted run
// ends, with the same snapshot numbering and log rows.
//
// Reference: the uninterrupted run. The checkpoint holds every particle, the step-end forces
// and every contact spring; writing it rebuilds the neighbour lists exactly as the restart
// does (Simulation::write_checkpoint, ties in the bin sort broken by global id), so both runs
// sum every force in the same order and the restart is bit-identical: the tolerance is 0.
// It must be: a dense frictional bed is chaotic, and a 1e-16 change at the checkpoint (as
// before that rebuild existed) grew here to a 2 % difference in kinetic energy and 0.2 m/s
// in velocities by the end, so no small non-zero tolerance would be meaningful.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "dem/engine/checkpoint_series.hpp"
#include "dem/engine/run.hpp"
#include "dem/io/snapshot_reader.hpp"
#include "dem/scene/scene_parser.hpp"

namespace grainflow {
namespace {

namespace fs = std::filesystem;

const fs::path kWork = fs::path(GRAINFLOW_BINARY_DIR) / "test_output/restart_run_mpi";

int rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

std::string last_snapshot(const fs::path& dir) {
  std::string last;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.rfind("particles_", 0) == 0 && e.path().extension() == ".h5")
      last = std::max(last, e.path().string());
  }
  return last;
}

std::vector<std::string> lines_of(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> out;
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

TEST(RestartRun, ContinuesLikeTheUninterruptedRun) {
  Scene scene = load_scene(std::string(GRAINFLOW_TEST_DATA_DIR) + "/scenes/periodic_bed.yaml");
  // Ten times Earth's gravity: the beads land within 0.025 s, so the second half runs with
  // hundreds of frictional contacts (springs and spins in the checkpoint).
  scene.gravity = Vec3(0, 0, -98.1);
  scene.time.end = 0.04;
  scene.output.checkpoint_interval = 0.02;
  scene.output.checkpoint_keep = 1;
  RunOptions options;
  options.progress = false;
  options.handle_stop_signals = false;
  const fs::path whole = kWork / "whole", restarted = kWork / "restarted";
  if (rank() == 0) fs::remove_all(kWork);
  MPI_Barrier(MPI_COMM_WORLD);

  std::ostringstream out;
  options.output_directory = whole.string();
  const RunSummary a = run_scene(scene, options, MPI_COMM_WORLD, out);
  ASSERT_TRUE(a.stop_checkpoint.empty());

  // The restart runs in a copy of the whole run's output, as after a crash past T/2.
  std::string checkpoint;
  for (const auto& e : fs::directory_iterator(whole))
    if (e.path().filename().string().rfind("checkpoint_", 0) == 0)
      checkpoint = (restarted / e.path().filename()).string();
  ASSERT_FALSE(checkpoint.empty()) << "no checkpoint was written at T/2";
  const long checkpoint_step = std::stol(fs::path(checkpoint).stem().string().substr(11));
  EXPECT_EQ(fs::path(checkpoint).filename().string(), CheckpointSeries::file_name(checkpoint_step));
  EXPECT_NEAR(checkpoint_step, a.steps / 2, 1);
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank() == 0) fs::copy(whole, restarted, fs::copy_options::recursive);
  MPI_Barrier(MPI_COMM_WORLD);

  options.output_directory = restarted.string();
  options.restart = checkpoint;
  const RunSummary b = run_scene(scene, options, MPI_COMM_WORLD, out);
  EXPECT_EQ(b.steps, a.steps);
  EXPECT_EQ(b.particles_end, a.particles_end);

  if (rank() != 0) return;
  // Same numbering: the last snapshot has the same name in both directories.
  const std::string last_a = last_snapshot(whole), last_b = last_snapshot(restarted);
  EXPECT_EQ(fs::path(last_a).filename(), fs::path(last_b).filename());
  // Same log rows: time, step, particles, energies, overlap and contacts. (Columns rebuilds
  // and removed count from the restart, wall_s is wall-clock time.)
  auto first_columns = [](const std::string& row) {
    std::size_t at = 0;
    for (int c = 0; c < 7 && at != std::string::npos; ++c) at = row.find(',', at + 1);
    return row.substr(0, at);
  };
  const auto log_a = lines_of(whole / "log.csv"), log_b = lines_of(restarted / "log.csv");
  ASSERT_EQ(log_a.size(), log_b.size());
  for (std::size_t i = 0; i < log_a.size(); ++i)
    EXPECT_EQ(first_columns(log_a[i]), first_columns(log_b[i])) << "log row " << i;
  long contacts = 0;
  for (std::size_t i = log_a.size() / 2; i < log_a.size(); ++i)
    contacts =
        std::max(contacts, std::stol(log_a[i].substr(first_columns(log_a[i]).rfind(',') + 1)));
  EXPECT_GT(contacts, 100) << "too few contacts after the checkpoint: the test shows little";

  const Snapshot sa = read_snapshot(last_a), sb = read_snapshot(last_b);
  ASSERT_EQ(sa.particles.size(), sb.particles.size());
  EXPECT_EQ(sa.time, sb.time);
  std::map<GlobalId, std::size_t> at;
  for (std::size_t i = 0; i < sb.particles.size(); ++i) at[sb.particles.id[i]] = i;
  double dx = 0, dv = 0, dw = 0, vmax = 0, wmax = 0;
  for (std::size_t i = 0; i < sa.particles.size(); ++i) {
    const auto j = at.find(sa.particles.id[i]);
    ASSERT_NE(j, at.end()) << "particle " << sa.particles.id[i] << " missing after restart";
    dx = std::max(dx, (sa.particles.x[i] - sb.particles.x[j->second]).norm());
    dv = std::max(dv, (sa.particles.v[i] - sb.particles.v[j->second]).norm());
    dw = std::max(dw, (sa.particles.omega[i] - sb.particles.omega[j->second]).norm());
    vmax = std::max(vmax, sa.particles.v[i].norm());
    wmax = std::max(wmax, sa.particles.omega[i].norm());
  }
  // Relative to the 0.015 m box and to the largest velocity and spin, for the report.
  const double ex = dx / 0.015, ev = dv / vmax, ew = dw / wmax;
  std::printf(
      "restart vs uninterrupted after %ld steps (checkpoint at %ld): |dx| %.3g m "
      "(%.3g rel), |dv| %.3g m/s (%.3g rel), |dw| %.3g rad/s (%.3g rel)\n",
      a.steps, checkpoint_step, dx, ex, dv, ev, dw, ew);
  EXPECT_EQ(dx, 0.0);
  EXPECT_EQ(dv, 0.0);
  EXPECT_EQ(dw, 0.0);
  EXPECT_GT(wmax, 0.0) << "no particle spins: the springs were not exercised";
}

}  // namespace
}  // namespace grainflow
