// Periodic checkpoints keep the newest K files (dem/engine/checkpoint_series.hpp), and a
// restarted run adopts the checkpoints already on disk up to its step. Reference: the file
// names the series must leave behind, counted by hand. Partial files of a killed run are
// deleted, never adopted.
#include "dem/engine/checkpoint_series.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "dem/engine/simulation.hpp"
#include "dem/io/checkpoint.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

namespace fs = std::filesystem;

std::set<std::string> files_in(const fs::path& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.insert(e.path().filename().string());
  return out;
}

TEST(CheckpointSeries, KeepsTheNewestAndAdoptsOnRestart) {
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output/checkpoint_series";
  fs::remove_all(dir);
  fs::create_directories(dir);
  EXPECT_EQ(CheckpointSeries::file_name(1234), "checkpoint_000001234.h5");

  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5);
  Simulation sim(s, false);
  sim.particles().add(1, Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3::Zero(), 1e-3, 0, 2500);
  sim.initialise();
  {
    CheckpointSeries series(MPI_COMM_WORLD, dir.string(), 2);
    for (int k = 0; k < 4; ++k) {
      sim.step();
      series.write(sim);
    }
    EXPECT_EQ(series.warning(), "");
  }
  EXPECT_EQ(files_in(dir),
            (std::set<std::string>{"checkpoint_000000003.h5", "checkpoint_000000004.h5"}));
  EXPECT_EQ(read_checkpoint((dir / "checkpoint_000000004.h5").string()).step, 4);

  // A restart from step 3 adopts checkpoint 3 (and leaves 4, which is past its step, alone
  // until it overwrites it); with K = 1 its next checkpoint replaces 3.
  fs::copy_file(dir / "checkpoint_000000003.h5", dir / "unrelated.h5");
  // What a run killed while writing leaves: partial files, one with a complete checkpoint's
  // content. They are deleted at start and never adopted; other names are left alone.
  fs::copy_file(dir / "checkpoint_000000003.h5", dir / "checkpoint_000000002.h5.part");
  { std::ofstream(dir / "checkpoint_000000009.h5.part") << "cut short"; }
  { std::ofstream(dir / "notes.part") << "not ours"; }
  CheckpointSeries restarted(MPI_COMM_WORLD, dir.string(), 1, 3);
  EXPECT_EQ(restarted.removed_partial().size(), 2u);
  EXPECT_EQ(restarted.newest(), (dir / "checkpoint_000000003.h5").string());
  EXPECT_EQ(files_in(dir),
            (std::set<std::string>{"checkpoint_000000003.h5", "checkpoint_000000004.h5",
                                   "notes.part", "unrelated.h5"}));
  sim.step();
  restarted.write(sim);
  EXPECT_EQ(files_in(dir),
            (std::set<std::string>{"checkpoint_000000004.h5", "checkpoint_000000005.h5",
                                   "notes.part", "unrelated.h5"}));
  EXPECT_EQ(restarted.newest(), (dir / "checkpoint_000000005.h5").string());
}

}  // namespace
}  // namespace grainflow
