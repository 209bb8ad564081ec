// The NaN / Inf guard (dem/engine/finite_guard.hpp): a particle whose velocity becomes NaN is
// found after the step that carried it, and the message names its id, the step, the bad
// quantity, its position and its force; the step's own check (Simulation::state_finite(), what
// `grain run` asks after each step) says the same. Reference: the particle we poisoned ourselves.
#include "dem/engine/finite_guard.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <string>

#include "dem/engine/simulation.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

TEST(FiniteGuard, NamesTheFirstParticleWithANaNVelocity) {
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5);
  s.gravity = Vec3(0, 0, -9.81);
  Simulation sim(s, false);
  const double r = 1e-3;
  sim.particles().add(1, Vec3(-0.5, 0, 0), Vec3::Zero(), Vec3::Zero(), r, 0, 2500);
  sim.particles().add(2, Vec3(0, 0, 0), Vec3::Zero(), Vec3::Zero(), r, 0, 2500);
  sim.particles().add(3, Vec3(0.5, 0, 0), Vec3::Zero(), Vec3::Zero(), r, 0, 2500);
  sim.initialise();
  for (int k = 0; k < 10; ++k) sim.step();
  EXPECT_FALSE(non_finite_anywhere(sim.particles(), MPI_COMM_WORLD));
  EXPECT_EQ(describe_first_non_finite(sim.particles(), 10, sim.time(), 0), "");
  // The step's own check (in its last pass, which the run's guard uses) agrees.
  EXPECT_TRUE(sim.state_finite());

  // Poison particle 2's velocity; the next step's drift carries the NaN into its position.
  for (std::size_t i = 0; i < sim.particles().size(); ++i)
    if (sim.particles().id[i] == 2)
      sim.particles().v[i].x() = std::numeric_limits<double>::quiet_NaN();
  sim.step();
  ASSERT_TRUE(non_finite_anywhere(sim.particles(), MPI_COMM_WORLD));
  EXPECT_FALSE(sim.state_finite());
  const std::string m = describe_first_non_finite(sim.particles(), 11, sim.time(), 0);
  std::printf("%s\n", m.c_str());
  EXPECT_NE(m.find("step 11"), std::string::npos) << m;
  EXPECT_NE(m.find("particle 2 (rank 0) has a non-finite position"), std::string::npos) << m;
  EXPECT_NE(m.find("velocity (nan, 0, "), std::string::npos) << m;
  // Its force is gravity alone (no contact): m g with m = 2500 * 4/3 pi r^3.
  EXPECT_NE(m.find("force (0, 0, -0.00010273"), std::string::npos) << m;

  // An infinite spin alone is caught too.
  Particles p;
  p.add(7, Vec3::Zero(), Vec3::Zero(), Vec3(0, std::numeric_limits<double>::infinity(), 0), r, 0,
        2500);
  EXPECT_TRUE(non_finite_anywhere(p, MPI_COMM_WORLD));
  EXPECT_NE(describe_first_non_finite(p, 0, 0, 0)
                .find("particle 7 (rank 0) has a non-finite "
                      "angular velocity"),
            std::string::npos);
}

}  // namespace
}  // namespace grainflow
