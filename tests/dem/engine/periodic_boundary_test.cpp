// Periodic axes: a particle that crosses a periodic side re-enters on the other side,
// and a collision that straddles the periodic side is the same collision as in the
// middle of the box. Reference: translation invariance — the straddling run must
// reproduce the interior run's velocities to round-off, and the
// elastic rebound speed of equal spheres (exchange of velocities, e = 1) to 1e-3.
#include <gtest/gtest.h>

#include "dem/engine/simulation.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

Scene periodic_x_scene() {
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 1.0);
  s.domain.lo = Vec3(0, 0, 0);
  s.domain.hi = Vec3(0.02, 0.02, 0.02);
  s.domain.periodic = {true, false, false};
  return s;
}

// Two spheres approaching head-on along x, centred on `middle` (wrapped into the box).
std::pair<Vec3, Vec3> collide_around(double middle) {
  const double r = 1e-3;
  Simulation sim(periodic_x_scene(), false);
  auto wrap = [](double x) { return x < 0 ? x + 0.02 : (x >= 0.02 ? x - 0.02 : x); };
  sim.particles().add(1, Vec3(wrap(middle - 1.5 * r), 0.01, 0.01), Vec3(0.3, 0, 0), Vec3::Zero(),
                      r, 0, 2500);
  sim.particles().add(2, Vec3(wrap(middle + 1.5 * r), 0.01, 0.01), Vec3(-0.3, 0, 0),
                      Vec3::Zero(), r, 0, 2500);
  sim.set_dt(1e-7);
  sim.initialise();
  sim.advance_to(0.004);  // the collision is over after ~1.7 ms + contact time
  const Particles& p = sim.particles();
  const std::size_t a = p.id[0] == 1 ? 0 : 1;
  EXPECT_EQ(p.size(), 2u);
  return {p.v[a], p.v[1 - a]};
}

TEST(PeriodicBoundary, CollisionAcrossTheSideEqualsCollisionInside) {
  const auto inside = collide_around(0.01);
  const auto straddle = collide_around(0.0);  // contact point exactly on the periodic side
  EXPECT_NEAR(inside.first[0], -0.3, 3e-4);   // elastic exchange of velocities
  EXPECT_NEAR(inside.second[0], 0.3, 3e-4);
  // Round-off: the two placements round positions differently (ulp(0.02 m) ~ 3e-18 m),
  // a ~1e-13 relative error in the ~1e-5 m overlap per step, over ~2e4 contact steps.
  EXPECT_NEAR(straddle.first[0], inside.first[0], 1e-9 * 0.3);
  EXPECT_NEAR(straddle.second[0], inside.second[0], 1e-9 * 0.3);
}

TEST(PeriodicBoundary, ParticleReentersOnTheOtherSide) {
  Simulation sim(periodic_x_scene(), false);
  sim.particles().add(1, Vec3(0.019, 0.01, 0.01), Vec3(1.0, 0, 0), Vec3::Zero(), 1e-3, 0, 2500);
  sim.set_dt(1e-5);
  sim.initialise();
  sim.advance_to(0.05);  // travels 50 mm: two and a half laps of the 20 mm box
  ASSERT_EQ(sim.particles().size(), 1u);
  EXPECT_EQ(sim.counters().removed, 0);
  EXPECT_NEAR(sim.particles().x[0][0], 0.019 + 0.05 - 3 * 0.02, 1e-9);
}

TEST(BoundedDomain, LeavingParticleIsRemovedAndCounted) {
  Scene s = periodic_x_scene();
  Simulation sim(s, false);
  sim.particles().add(1, Vec3(0.01, 0.019, 0.01), Vec3(0, 1.0, 0), Vec3::Zero(), 1e-3, 0, 2500);
  sim.particles().add(2, Vec3(0.01, 0.005, 0.01), Vec3::Zero(), Vec3::Zero(), 1e-3, 0, 2500);
  sim.set_dt(1e-5);
  sim.initialise();
  sim.advance_to(0.01);
  ASSERT_EQ(sim.particles().size(), 1u);
  EXPECT_EQ(sim.particles().id[0], 2);
  EXPECT_EQ(sim.counters().removed, 1);
}

}  // namespace
}  // namespace grainflow
