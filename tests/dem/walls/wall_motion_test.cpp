// Rigid wall motion: positions, inverse map and velocity (finite-difference check).
#include <gtest/gtest.h>

#include <numbers>

#include "dem/walls/wall_motion.hpp"
#include "dem/walls/wall_set.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

WallMotion spin_and_shift() {
  WallMotion m;
  m.velocity = Vec3(0.1, -0.2, 0.3);
  m.angular_velocity = 2.0;
  m.axis = Vec3(1, 2, 2).normalized();
  m.axis_point = Vec3(0.5, -0.1, 0.2);
  return m;
}

TEST(WallMotion, AtTimeZeroTheWallIsWhereTheSceneSays) {
  const WallPose pose(spin_and_shift());
  const Vec3 x(0.3, 0.4, -0.7);
  EXPECT_NEAR((pose.to_world(x) - x).norm(), 0, 1e-15);
  EXPECT_NEAR((pose.to_body(x) - x).norm(), 0, 1e-15);
}

// The velocity at a point equals the time derivative of that material point's
// position (central difference, error ~ h^2 |a| = 1e-12 here).
TEST(WallMotion, VelocityIsTheDerivativeOfPosition) {
  WallPose pose(spin_and_shift());
  const Vec3 x0(0.3, 0.4, -0.7);
  const double t = 0.8, h = 1e-6;
  pose.move_to(t + h);
  const Vec3 ahead = pose.to_world(x0);
  pose.move_to(t - h);
  const Vec3 behind = pose.to_world(x0);
  pose.move_to(t);
  const Vec3 y = pose.to_world(x0);
  EXPECT_NEAR((pose.velocity_at(y) - (ahead - behind) / (2 * h)).norm(), 0, 1e-8);
  EXPECT_NEAR((pose.to_body(y) - x0).norm(), 0, 1e-14);
}

// A plane turning a quarter turn about the x axis: its normal z becomes -y.
TEST(WallMotion, WallSetMovesPlanes) {
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5);
  Wall w = test::plane(Vec3(0, 0, 1), Vec3::UnitZ());
  w.motion.angular_velocity = std::numbers::pi / 2;
  w.motion.axis = Vec3::UnitX();
  s.walls.push_back(w);
  WallSet set(s);
  set.move_to(1.0);
  const PlaneWall& p = set.walls()[0].plane;
  EXPECT_NEAR((p.normal - Vec3(0, -1, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR((p.point - Vec3(0, -1, 0)).norm(), 0, 1e-15);
}

}  // namespace
}  // namespace grainflow
