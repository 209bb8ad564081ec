// A restart with fluid forces continues bit-identically (2 ranks): beads in upward-flowing
// water, drag implicit in the integrator, void fraction from the particles.
//
// The half kick after a step uses that step's implicit drag (K, u) as well as its forces.
// Neither may be recomputed at a restart: the forces already hold the fluid terms (adding
// them again doubled them), and in a coupled run K and u come from the fluid of the step
// before. So the checkpoint stores K and u, and the rebuild that follows writing it carries
// them along with their particles (before, the rebuild reordered the particles and left
// K and u at the old indices: the uninterrupted run itself went wrong after a checkpoint).
// Reference: the uninterrupted run, with tolerance 0 (see restart_run_mpi_test.cpp).
#include <gtest/gtest.h>
#include <mpi.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "dem/engine/run.hpp"
#include "dem/io/checkpoint.hpp"
#include "dem/io/snapshot_reader.hpp"
#include "dem/scene/scene_parser.hpp"

namespace grainflow {
namespace {

namespace fs = std::filesystem;

const fs::path kWork = fs::path(GRAINFLOW_BINARY_DIR) / "test_output/restart_fluid_mpi";

int rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

std::string newest(const fs::path& dir, const std::string& prefix) {
  std::string last;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind(prefix, 0) == 0 && e.path().extension() == ".h5")
      last = std::max(last, e.path().string());
  return last;
}

// Runs `scene` whole and from its checkpoint, into `work`; they must end bit-identically.
void expect_restart_identical(const Scene& scene, const fs::path& work) {
  RunOptions options;
  options.progress = false;
  options.handle_stop_signals = false;
  const fs::path whole = work / "whole", restarted = work / "restarted";
  if (rank() == 0) fs::remove_all(work);
  MPI_Barrier(MPI_COMM_WORLD);
  std::ostringstream out;
  options.output_directory = whole.string();
  const RunSummary a = run_scene(scene, options, MPI_COMM_WORLD, out);

  const std::string checkpoint = newest(whole, "checkpoint_");
  ASSERT_FALSE(checkpoint.empty());
  const CheckpointData c = read_checkpoint(checkpoint);
  ASSERT_EQ(c.drag_coefficient.size(), c.particles.size()) << "the checkpoint holds no drag";
  double k_min = 1e300;
  for (double k : c.drag_coefficient) k_min = std::min(k_min, k);
  // Stokes' K = 3 pi mu d for the smallest bead (d = 0.8 mm) is 7.5e-6 kg/s; dense-bed
  // laws only raise it.
  EXPECT_GT(k_min, 3 * M_PI * 1e-3 * 8e-4 * 0.99);

  MPI_Barrier(MPI_COMM_WORLD);
  if (rank() == 0) fs::copy(whole, restarted, fs::copy_options::recursive);
  MPI_Barrier(MPI_COMM_WORLD);
  options.output_directory = restarted.string();
  options.restart = (restarted / fs::path(checkpoint).filename()).string();
  const RunSummary b = run_scene(scene, options, MPI_COMM_WORLD, out);
  EXPECT_EQ(b.steps, a.steps);
  if (rank() != 0) return;

  const Snapshot sa = read_snapshot(newest(whole, "particles_")),
                 sb = read_snapshot(newest(restarted, "particles_"));
  ASSERT_EQ(sa.particles.size(), 300u);
  ASSERT_EQ(sb.particles.size(), 300u);
  EXPECT_EQ(sa.time, sb.time);
  std::map<GlobalId, std::size_t> at;
  for (std::size_t i = 0; i < sb.particles.size(); ++i) at[sb.particles.id[i]] = i;
  double dx = 0, dv = 0, dw = 0;
  for (std::size_t i = 0; i < sa.particles.size(); ++i) {
    const std::size_t j = at.at(sa.particles.id[i]);
    dx = std::max(dx, (sa.particles.x[i] - sb.particles.x[j]).norm());
    dv = std::max(dv, (sa.particles.v[i] - sb.particles.v[j]).norm());
    dw = std::max(dw, (sa.particles.omega[i] - sb.particles.omega[j]).norm());
  }
  std::printf("restart with fluid forces vs uninterrupted: |dx| %.3g m, |dv| %.3g m/s, "
              "|dw| %.3g rad/s\n", dx, dv, dw);
  EXPECT_EQ(dx, 0.0);
  EXPECT_EQ(dv, 0.0);
  EXPECT_EQ(dw, 0.0);
}

TEST(RestartWithFluidForces, ContinuesBitIdentically) {
  expect_restart_identical(
      load_scene(std::string(GRAINFLOW_TEST_DATA_DIR) + "/scenes/fluid_bed_checkpoint.yaml"),
      kWork / "drag");
}

// The same bed in a shear flow (G = 50/s) with rotational drag, implicit in the spin: the
// spin drag is not in the checkpoint but a function of the restored state, given again after
// the checkpoint's rebuild (in the particles' new order) and at the restart.
TEST(RestartWithFluidForces, RotationalDragContinuesBitIdentically) {
  Scene scene =
      load_scene(std::string(GRAINFLOW_TEST_DATA_DIR) + "/scenes/fluid_bed_checkpoint.yaml");
  scene.fluid->field.shear_rate = 50;
  scene.fluid->field.flow_direction = Vec3::UnitX();
  scene.fluid->field.gradient_direction = Vec3::UnitZ();
  scene.fluid->forces.push_back(FluidForce::rotational_drag);
  expect_restart_identical(scene, kWork / "spin");
}

// The same bed as coarse-grained parcels (docs/models/coarse-graining.md): 300 parcels of
// k = 2 (real radii 0.2-0.3 mm, so the same parcel sizes as above) standing for 2400 beads.
// The factor travels as the parcel class (the material index): restored exactly.
TEST(RestartWithFluidForces, ParcelsContinueBitIdentically) {
  const std::string path = std::string(GRAINFLOW_TEST_DATA_DIR) + "/scenes/fluid_bed_checkpoint.yaml";
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const std::string radius = "radius: {distribution: uniform, min: 4e-4, max: 6e-4}";
  ASSERT_NE(yaml.find(radius), std::string::npos);
  yaml.replace(yaml.find(radius), radius.size(),
               "radius: {distribution: uniform, min: 2e-4, max: 3e-4}\n    coarse_grain: 2");
  const Scene scene = parse_scene(yaml, path);
  ASSERT_EQ(scene.materials.size(), 2u);
  ASSERT_EQ(scene.fluid->coarse_grain, (std::vector<double>{1, 2}));
  expect_restart_identical(scene, kWork / "parcels");
  if (rank() != 0) return;
  const CheckpointData c = read_checkpoint(newest(kWork / "parcels" / "whole", "checkpoint_"));
  for (int m : c.particles.material) EXPECT_EQ(m, 1);  // every particle is a k = 2 parcel
}

}  // namespace
}  // namespace grainflow
