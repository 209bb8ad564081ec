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
//
// The second test does the same with a stream insertion pouring beads across the checkpoint:
// the streams' progress is in the checkpoint (group 'streams'), so the restart inserts the
// same beads at the same steps. References: the uninterrupted run (==) and the stream's
// closed form, delivered mass = rate x (stop - start) within half a bead.
//
// The third has its largest particle leave the domain before the checkpoint: the run chose its
// neighbour skin and bins from that radius at the start, so the restart must keep them (the
// checkpoint's largest_radius) and count the removed particles on (its `removed`). Before it
// did, the restart took the range from the beads left, rebuilt its lists 194 times instead of
// 75, and ended 2.2e-10 m and 3.4e-4 rad/s away from the uninterrupted run, one removed
// particle short in its log and summary.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <string>

#include "dem/engine/checkpoint_series.hpp"
#include "dem/engine/run.hpp"
#include "dem/engine/simulation.hpp"
#include "dem/io/checkpoint.hpp"
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

// The uninterrupted run and the restart from its only checkpoint, both on 2 ranks.
struct TwoRuns {
  RunSummary whole_run, restarted_run;
  fs::path whole, restarted;
  std::string checkpoint;  // in `restarted`
  long checkpoint_step = 0;
  std::string restart_report;  // what the restart printed
};

TwoRuns run_and_restart(const Scene& scene, const fs::path& work) {
  RunOptions options;
  options.progress = false;
  options.handle_stop_signals = false;
  TwoRuns r;
  r.whole = work / "whole";
  r.restarted = work / "restarted";
  if (rank() == 0) fs::remove_all(work);
  MPI_Barrier(MPI_COMM_WORLD);

  std::ostringstream out;
  options.output_directory = r.whole.string();
  r.whole_run = run_scene(scene, options, MPI_COMM_WORLD, out);
  EXPECT_TRUE(r.whole_run.stop_checkpoint.empty());

  // The restart runs in a copy of the whole run's output, as after a crash past T/2.
  for (const auto& e : fs::directory_iterator(r.whole))
    if (e.path().filename().string().rfind("checkpoint_", 0) == 0)
      r.checkpoint = (r.restarted / e.path().filename()).string();
  if (r.checkpoint.empty()) {
    ADD_FAILURE() << "no checkpoint was written at T/2";
    return r;
  }
  r.checkpoint_step = std::stol(fs::path(r.checkpoint).stem().string().substr(11));
  EXPECT_EQ(fs::path(r.checkpoint).filename().string(),
            CheckpointSeries::file_name(r.checkpoint_step));
  EXPECT_NEAR(r.checkpoint_step, r.whole_run.steps / 2, 1);
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank() == 0) fs::copy(r.whole, r.restarted, fs::copy_options::recursive);
  MPI_Barrier(MPI_COMM_WORLD);

  options.output_directory = r.restarted.string();
  options.restart = r.checkpoint;
  std::ostringstream restart_out;
  r.restarted_run = run_scene(scene, options, MPI_COMM_WORLD, restart_out);
  r.restart_report = restart_out.str();
  EXPECT_EQ(r.restarted_run.steps, r.whole_run.steps);
  EXPECT_EQ(r.restarted_run.particles_end, r.whole_run.particles_end);
  EXPECT_EQ(r.restarted_run.removed, r.whole_run.removed);
  EXPECT_EQ(r.restarted_run.rebuilds, r.whole_run.rebuilds);
  return r;
}

// Compares the two runs' log rows and last snapshots (rank 0). Returns the largest number
// of contacts logged after the checkpoint.
long expect_same_end(const TwoRuns& r) {
  // Same numbering: the last snapshot has the same name in both directories.
  const std::string last_a = last_snapshot(r.whole), last_b = last_snapshot(r.restarted);
  EXPECT_EQ(fs::path(last_a).filename(), fs::path(last_b).filename());
  // Same log rows: time, step, particles, energies, overlap, contacts, rebuilds and removed
  // (all but wall_s, the wall-clock time).
  auto first_columns = [](const std::string& row) {
    std::size_t at = 0;
    for (int c = 0; c < 9 && at != std::string::npos; ++c) at = row.find(',', at + 1);
    return row.substr(0, at);
  };
  const auto log_a = lines_of(r.whole / "log.csv"), log_b = lines_of(r.restarted / "log.csv");
  EXPECT_EQ(log_a.size(), log_b.size());
  for (std::size_t i = 0; i < std::min(log_a.size(), log_b.size()); ++i)
    EXPECT_EQ(first_columns(log_a[i]), first_columns(log_b[i])) << "log row " << i;
  long contacts = 0;
  for (std::size_t i = log_a.size() / 2; i < log_a.size(); ++i) {
    std::stringstream row(log_a[i]);
    std::string cell;
    for (int c = 0; c <= 6; ++c) std::getline(row, cell, ',');  // column 6: contacts
    contacts = std::max(contacts, std::stol(cell));
  }

  const Snapshot sa = read_snapshot(last_a), sb = read_snapshot(last_b);
  EXPECT_EQ(sa.particles.size(), sb.particles.size());
  EXPECT_EQ(sa.time, sb.time);
  std::map<GlobalId, std::size_t> at;
  for (std::size_t i = 0; i < sb.particles.size(); ++i) at[sb.particles.id[i]] = i;
  double dx = 0, dv = 0, dw = 0, dr = 0, vmax = 0, wmax = 0;
  for (std::size_t i = 0; i < sa.particles.size(); ++i) {
    const auto j = at.find(sa.particles.id[i]);
    if (j == at.end()) {
      ADD_FAILURE() << "particle " << sa.particles.id[i] << " missing after restart";
      continue;
    }
    dx = std::max(dx, (sa.particles.x[i] - sb.particles.x[j->second]).norm());
    dv = std::max(dv, (sa.particles.v[i] - sb.particles.v[j->second]).norm());
    dw = std::max(dw, (sa.particles.omega[i] - sb.particles.omega[j->second]).norm());
    dr = std::max(dr, std::abs(sa.particles.radius[i] - sb.particles.radius[j->second]));
    vmax = std::max(vmax, sa.particles.v[i].norm());
    wmax = std::max(wmax, sa.particles.omega[i].norm());
  }
  // Relative to the 0.015 m box and to the largest velocity and spin, for the report.
  std::printf(
      "restart vs uninterrupted after %ld steps (checkpoint at %ld): %zu particles, |dx| %.3g m "
      "(%.3g rel), |dv| %.3g m/s (%.3g rel), |dw| %.3g rad/s (%.3g rel), |dr| %.3g m\n",
      r.whole_run.steps, r.checkpoint_step, sa.particles.size(), dx, dx / 0.015, dv, dv / vmax, dw,
      dw / wmax, dr);
  EXPECT_EQ(dx, 0.0);
  EXPECT_EQ(dv, 0.0);
  EXPECT_EQ(dw, 0.0);
  EXPECT_EQ(dr, 0.0);
  EXPECT_GT(wmax, 0.0) << "no particle spins: the springs were not exercised";
  return contacts;
}

TEST(RestartRun, ContinuesLikeTheUninterruptedRun) {
  Scene scene = load_scene(std::string(GRAINFLOW_TEST_DATA_DIR) + "/scenes/periodic_bed.yaml");
  // Ten times Earth's gravity: the beads land within 0.025 s, so the second half runs with
  // hundreds of frictional contacts (springs and spins in the checkpoint).
  scene.gravity = Vec3(0, 0, -98.1);
  scene.time.end = 0.04;
  scene.output.checkpoint_interval = 0.02;
  scene.output.checkpoint_keep = 1;
  const TwoRuns r = run_and_restart(scene, kWork / "bed");
  if (rank() != 0 || r.checkpoint.empty()) return;
  EXPECT_GT(expect_same_end(r), 100)
      << "too few contacts after the checkpoint: the test shows little";
}

TEST(RestartRun, LargestParticleLeftBeforeTheCheckpoint) {
  const Scene scene =
      load_scene(std::string(GRAINFLOW_TEST_DATA_DIR) + "/scenes/largest_leaves.yaml");
  const TwoRuns r = run_and_restart(scene, kWork / "largest_leaves");
  ASSERT_FALSE(r.checkpoint.empty());
  const CheckpointData c = read_checkpoint(r.checkpoint);
  double r_left = 0;
  for (double radius : c.particles.radius) r_left = std::max(r_left, radius);
  ASSERT_TRUE(c.largest_radius.has_value());
  if (rank() == 0)
    std::printf(
        "checkpoint: largest radius %.4g m (the beads left: %.4g m), %ld removed; "
        "%ld / %ld removed and %ld / %ld rebuilds in all (uninterrupted / restarted)\n",
        *c.largest_radius, r_left, c.removed, r.whole_run.removed, r.restarted_run.removed,
        r.whole_run.rebuilds, r.restarted_run.rebuilds);
  EXPECT_EQ(*c.largest_radius, 1.5e-3);  // the thrown bead's, not the beads' <= 0.6 mm
  EXPECT_LE(r_left, 6e-4);
  EXPECT_GE(c.removed, 1);
  EXPECT_GT(r.whole_run.removed, c.removed);  // beads keep leaving after the checkpoint
  if (rank() == 0) {
    EXPECT_GT(expect_same_end(r), 30) << "too few contacts after the checkpoint";
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

// The same scene with the thrown bead the smallest (0.2 mm): it set the time step, 0.1 of its
// Rayleigh time. The restart keeps the checkpoint's step, and its report says so and judges
// that step (before, it printed the step the beads left would give, twice the one it ran).
TEST(RestartRun, SmallestParticleLeftBeforeTheCheckpoint) {
  Scene scene = load_scene(std::string(GRAINFLOW_TEST_DATA_DIR) + "/scenes/largest_leaves.yaml");
  ASSERT_EQ(scene.insertions.size(), 2u);
  scene.insertions[1].radius.value = 2e-4;
  const TwoRuns r = run_and_restart(scene, kWork / "smallest_leaves");
  ASSERT_FALSE(r.checkpoint.empty());
  if (rank() != 0) return;
  const CheckpointData c = read_checkpoint(r.checkpoint);
  std::printf("restart report: %s\n", r.restart_report.c_str());
  // dt = 0.1 t_R(0.2 mm) = 2.448e-6 s; the beads left (>= 0.4 mm) would give 4.9e-6 s.
  EXPECT_NEAR(c.dt, 2.448e-6, 1e-9);
  EXPECT_THAT(r.restart_report,
              testing::ContainsRegex("dt = 2.448e-06 s = 0.0499[0-9]* t_R .*, the checkpoint's "
                                     "step, which the restart keeps \\(time.rayleigh_fraction "
                                     "gives 4\\.[89][0-9]*e-06 s for the particles present\\)"));
  expect_same_end(r);
}

// stream_bed.yaml: 0.025 kg/s of beads (radius 0.4-0.6 mm) from t = 0.002 s to 0.03 s onto a
// floor, checkpoint at 0.018 s, end 0.036 s; a bed with up to ~200 contacts forms after the
// checkpoint.
TEST(RestartRun, StreamInsertionContinuesLikeTheUninterruptedRun) {
  const Scene scene = load_scene(std::string(GRAINFLOW_TEST_DATA_DIR) + "/scenes/stream_bed.yaml");
  const Insertion& stream = scene.insertions.at(0);
  ASSERT_EQ(stream.kind, Insertion::Kind::stream);
  const TwoRuns r = run_and_restart(scene, kWork / "stream");
  ASSERT_FALSE(r.checkpoint.empty());

  // The stream was half-way at the checkpoint and went on delivering after the restart.
  const CheckpointData c = read_checkpoint(r.checkpoint);
  ASSERT_TRUE(c.streams.has_value());
  const long at_checkpoint = static_cast<long>(c.particles.size());
  ASSERT_EQ(r.whole_run.streams.size(), 1u);
  ASSERT_EQ(r.restarted_run.streams.size(), 1u);
  const RunSummary::StreamTotal a = r.whole_run.streams[0], b = r.restarted_run.streams[0];
  if (rank() == 0)
    std::printf(
        "stream: %ld particles at the checkpoint (t = %.4g s), %ld at the end; "
        "delivered %ld / %ld particles, %.9g / %.9g kg (uninterrupted / restarted)\n",
        at_checkpoint, c.time, r.whole_run.particles_end, a.count, b.count, a.mass, b.mass);
  EXPECT_GT(at_checkpoint, 100);
  EXPECT_GT(r.whole_run.particles_end, at_checkpoint + 100);
  EXPECT_EQ(b.count, a.count);
  EXPECT_EQ(b.mass, a.mass);
  EXPECT_EQ(b.count, r.restarted_run.particles_end);  // nothing left the box
  EXPECT_EQ(a.lag, 0);
  EXPECT_EQ(b.lag, 0);
  // Closed form: rate x (stop - start), within half the heaviest bead (the count due is the
  // largest n with m_1 + ... + m_{n-1} + m_n / 2 <= target; stream_insertion.hpp).
  const double target = *stream.mass_rate * (*stream.stop - stream.start);
  const double r_max = stream.radius.max;
  const double half_bead = 0.5 * 2500 * 4.0 / 3.0 * std::numbers::pi * r_max * r_max * r_max;
  if (rank() == 0)
    std::printf(
        "stream: delivered %.9g kg, rate x time = %.9g kg, difference %.3g kg (half the "
        "heaviest bead: %.3g kg)\n",
        b.mass, target, b.mass - target, half_bead);
  EXPECT_LE(std::abs(b.mass - target), half_bead);

  if (rank() == 0) {
    EXPECT_GT(expect_same_end(r), 100) << "too few contacts after the checkpoint";
  }
  MPI_Barrier(MPI_COMM_WORLD);

  // A checkpoint without the group 'streams' (format 1, written before stream state was
  // saved) cannot continue this scene: the restart says what is missing.
  const fs::path old = kWork / "stream" / "old_format.h5";
  if (rank() == 0) {
    fs::copy_file(r.checkpoint, old);
    const hid_t f = H5Fopen(old.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    EXPECT_GE(f, 0);
    EXPECT_GE(H5Ldelete(f, "streams", H5P_DEFAULT), 0);
    H5Fclose(f);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  RunOptions options;
  options.progress = false;
  options.handle_stop_signals = false;
  options.output_directory = (kWork / "stream" / "from_old").string();
  options.restart = old.string();
  std::ostringstream out;
  try {
    run_scene(scene, options, MPI_COMM_WORLD, out);
    ADD_FAILURE() << "a checkpoint without stream state restarted a scene with a stream";
  } catch (const SetupError& e) {
    EXPECT_THAT(e.what(), testing::HasSubstr("stream_bed.yaml: error: the scene has 1 stream "
                                             "insertion(s), but checkpoint '" +
                                             old.string() + "' holds no stream state"));
    if (rank() == 0) std::printf("old checkpoint: %s\n", e.what());
  }
}

}  // namespace
}  // namespace grainflow
