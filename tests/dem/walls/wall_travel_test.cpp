// The walls' travel guard (dem/walls/wall_travel.hpp, docs/stability.md) on the two
// reproductions of issue 17 item 1: a mesh plate at 120 m/s and a thin rod (`cylinder`,
// `side: outside`, r = 0.5 mm) at 150 m/s, each with dt = 2.5e-5 s, against a resting sphere
// of r = 1 mm. They move 3 and 3.75 radii per step: without the guard they jump over the
// sphere between two steps and never touch it (checked first, with the guard off).
//
// With the guard (time.max_step_travel = 1 r, the particles' rule) the start-up refuses both
// with the wall's name, its speed, the limit and two steps: one that fits the travel rule
// (for the wall and for a particle it strikes, which leaves at up to twice the wall's speed),
// and the one that resolves the impact (1/20 of the Hertz contact time). Rerun:
// - at the fitting step the check passes and the wall meets the sphere: a contact is found
//   (the run then stops at a contact guard, as it must: at half a radius per step no Hertz
//   contact of at most 25 % overlap lasts two steps);
// - at the impact step the impact is resolved. Reference: a sphere at rest struck by a wall
//   of unbounded mass moving at U leaves at (1 + e) U (in the wall's frame it arrives at U
//   and leaves at e U). Tolerance 3 %: the restitution mapping is good to 1 % at >= 20 steps
//   per contact (docs/models/contact-models.md), the wall's contact with R* = r is the
//   plane's (docs/theory/walls.md).
// Material: Y = 200 GPa, rho = 2500 kg/m^3, so that the elastic Hertz overlap at 150 m/s,
// (15 m v^2 / (16 Y* sqrt(r)))^{2/5} = 0.22 r, stays within time.max_overlap = 0.25 r.
#include "dem/walls/wall_travel.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "dem/engine/simulation.hpp"
#include "dem/walls/wall_contact.hpp"
#include "tests/dem/support/test_scene.hpp"
#include "tests/dem/walls/mesh_support.hpp"

namespace grainflow {
namespace {

using ::testing::HasSubstr;

constexpr double kR = 1e-3, kRho = 2500, kE = 0.9, kSlowDt = 2.5e-5;

enum class Mover { plate, rod };

struct Case {
  Mover mover;
  double speed;  // [m/s], along -z
  double start;  // the wall's height at t = 0 [m]: one big step jumps over the sphere
  const char* name;
};

const Case kPlate{Mover::plate, 120, 0.0045, "plate"};
const Case kRod{Mover::rod, 150, 0.0055, "rod"};

Scene scene_of(const Case& c, double dt) {
  Scene s = test::one_material_scene(2e11, 0.25, kRho, kE);
  s.gravity = Vec3::Zero();
  s.time.step = dt;
  s.time.end = 1e-3;
  s.domain.lo = Vec3::Constant(-0.05);
  s.domain.hi = Vec3::Constant(0.05);
  Wall w;
  if (c.mover == Mover::plate) {
    // 16 x 16 mm, centred above the sphere; a mesh's vertices are its body-frame points.
    w = test::mesh_wall(
        test::write_mesh(test::flat_grid(4, 0.004, -0.008, -0.008, c.start), "travel_plate.stl"),
        c.name);
  } else {
    w.kind = Wall::Kind::cylinder;
    w.name = c.name;
    w.cylinder.axis_point = Vec3(0, 0, c.start);
    w.cylinder.axis = Vec3::UnitX();
    w.cylinder.radius = 0.5e-3;
    w.cylinder.inside = false;
  }
  w.motion.velocity = Vec3(0, 0, -c.speed);
  s.walls.push_back(w);
  return s;
}

// The height of the plate, or of the rod's axis, at time t.
double wall_height(const Case& c, double t) { return c.start - c.speed * t; }

struct Outcome {
  std::string setup_error, stop;
  long contacts = 0;    // most contacts seen in one step
  bool passed = false;  // the sphere's centre ended above the wall: passed through
  double v_out = 0;     // the sphere's z velocity at the end
};

// Runs until the wall is 5 mm past the sphere's start, or a guard stops the run.
Outcome run(const Case& c, double dt, double max_step_travel = 1) {
  Scene s = scene_of(c, dt);
  s.time.max_step_travel = max_step_travel;
  Outcome o;
  Simulation sim(s, false);
  sim.particles().add(1, Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), kR, 0, kRho);
  try {
    sim.initialise();
  } catch (const SetupError& e) {
    o.setup_error = e.what();
    return o;
  }
  try {
    while (wall_height(c, sim.time()) > -0.005) {
      sim.step();
      o.contacts = std::max(o.contacts, sim.counters().contacts);
    }
  } catch (const ParallelError& e) {
    o.stop = e.what();
  }
  const Particles& p = sim.particles();
  if (p.size() == 1) {
    o.passed = p.x[0][2] > wall_height(c, sim.time());
    o.v_out = p.v[0][2];
  }
  return o;
}

// The number after `key` in `text`.
double number_after(const std::string& text, const std::string& key) {
  const auto at = text.find(key);
  if (at == std::string::npos) return 0;
  return std::strtod(text.c_str() + at + key.size(), nullptr);
}

class WallTravel : public ::testing::TestWithParam<Case> {};

TEST_P(WallTravel, FastWallPassesUnseenWithoutTheGuard) {
  const Outcome o = run(GetParam(), kSlowDt, 0);
  EXPECT_EQ(o.setup_error, "");
  EXPECT_EQ(o.stop, "");
  EXPECT_EQ(o.contacts, 0);
  EXPECT_TRUE(o.passed);
  EXPECT_EQ(o.v_out, 0);
}

TEST_P(WallTravel, RefusedWithSpeedLimitAndStepsThatWork) {
  const Case& c = GetParam();
  const Outcome refused = run(c, kSlowDt);
  const std::string& m = refused.setup_error;
  EXPECT_THAT(m, HasSubstr("<test>: error: wall '" + std::string(c.name) + "' moves "));
  // Sweep speed x dt / r: 120 x 2.5e-5 / 1e-3 = 3; 150 x 2.5e-5 / 1e-3 = 3.75.
  EXPECT_THAT(m, HasSubstr(c.mover == Mover::plate ? "moves 3 x the smallest particle radius"
                                                   : "moves 3.75 x the smallest particle radius"));
  EXPECT_THAT(m, HasSubstr("(sweep speed " + std::to_string(static_cast<int>(c.speed)) +
                           " m/s x dt = 2.5e-05 s"));
  EXPECT_THAT(m, HasSubstr("the limit is 1 (key time.max_step_travel"));
  const double fit = number_after(m, "A step of at most ");
  const double travel = number_after(m, "twice the wall's speed (");
  const double startup = number_after(m, "Rayleigh and contact times) need at most ");
  const double impact = number_after(m, " m/s needs at most ");
  // The travel rule: limit r / (2 U), rounded down to three digits.
  EXPECT_LE(travel, kR / (2 * c.speed));
  EXPECT_GT(travel, 0.99 * kR / (2 * c.speed));
  // dt = 2.5e-5 s is refused by the start-up check as well (Rayleigh and contact times of
  // this stiff material): the proposal is the smaller of the two, so that it passes both.
  ASSERT_GT(startup, 0) << m;
  EXPECT_EQ(fit, std::min(travel, startup)) << m;
  ASSERT_GT(impact, 0);
  ASSERT_LT(impact, fit) << m;

  // The fitting step passes the check, and the wall meets the sphere.
  const Outcome at_fit = run(c, fit);
  EXPECT_EQ(at_fit.setup_error, "");
  EXPECT_FALSE(at_fit.passed);
  EXPECT_TRUE(at_fit.contacts > 0 || at_fit.stop.find("particle 1 and wall '") != std::string::npos)
      << at_fit.stop;

  // The impact step resolves the impact: (1 + e) U within 3 %.
  const Outcome resolved = run(c, impact);
  EXPECT_EQ(resolved.setup_error, "");
  EXPECT_EQ(resolved.stop, "");
  EXPECT_GE(resolved.contacts, 1);
  EXPECT_FALSE(resolved.passed);
  EXPECT_NEAR(resolved.v_out, -(1 + kE) * c.speed, 0.03 * (1 + kE) * c.speed);
  std::printf("%s at %g m/s: fit %g s: %ld contacts, stop: %.80s; impact %g s: out at %.5g U\n",
              c.name, c.speed, fit, at_fit.contacts, at_fit.stop.c_str(), impact,
              -resolved.v_out / c.speed);
}

INSTANTIATE_TEST_SUITE_P(Reproductions, WallTravel, ::testing::Values(kPlate, kRod),
                         [](const auto& tp) { return std::string(tp.param.name); });

// A wall that moves only along its own surface (a drum turning about its own axis, a plane
// sliding in itself) moves no surface across a particle: sweep speed 0 whatever its speed.
TEST(WallSweepSpeed, MotionAlongTheSurfaceSweepsNothing) {
  Scene s = test::one_material_scene(2e11, 0.25, kRho, kE);
  Wall drum;
  drum.kind = Wall::Kind::cylinder;
  drum.name = "drum";
  drum.cylinder.axis_point = Vec3(0.1, 0.2, 0);
  drum.cylinder.axis = Vec3::UnitZ();
  drum.cylinder.radius = 0.3;
  drum.motion.angular_velocity = 500;
  drum.motion.axis_point = Vec3(0.1, 0.2, 5);  // on the drum's axis
  drum.motion.velocity = Vec3(0, 0, 40);       // along the axis
  s.walls.push_back(drum);
  Wall slide = test::plane(Vec3::Zero(), Vec3::UnitZ());
  slide.motion.velocity = Vec3(30, -20, 0);
  slide.motion.angular_velocity = 100;  // about z, the plane's normal
  s.walls.push_back(slide);
  // The same drum turning about a parallel axis 0.1 m off its own: its surface sweeps at
  // w times the farthest domain corner's distance from that axis. Domain [-1, 1]^3, axis
  // through (0.1, 0.3): the corner (-1, -1) is sqrt(1.1^2 + 1.3^2) away.
  Wall off = drum;
  off.motion.axis_point = Vec3(0.1, 0.3, 0);
  off.motion.velocity = Vec3(3, 4, 0);  // 5 m/s across the axis
  off.motion.angular_velocity = 2;
  off.name = "off";
  s.walls.push_back(off);
  const WallSet walls(s);
  EXPECT_EQ(wall_sweep_speed(s, walls, 0), 0);
  EXPECT_EQ(wall_sweep_speed(s, walls, 1), 0);
  // 5 m/s + 2 rad/s x (sqrt(1.1^2 + 1.3^2) + 5 m/s x t_end = 1 s).
  EXPECT_NEAR(wall_sweep_speed(s, walls, 2), 5 + 2 * (std::hypot(1.1, 1.3) + 5), 1e-12);
  const WallTravelReport rep = check_wall_travel(s, walls, 1e-6, 1e-3, 0, PairTable(s));
  ASSERT_EQ(rep.notes.size(), 3u);
  EXPECT_EQ(rep.notes[0],
            "wall 'drum' moves only along its own surface (no travel across "
            "particles)");
  EXPECT_EQ(rep.notes[2],
            "wall 'off' moves 1.841e-05 m per step (sweep speed 18.41 m/s x dt = "
            "1e-06 s) = 0.01841 x the smallest radius 0.001 m; limit 1 (key "
            "time.max_step_travel)");
  EXPECT_EQ(rep.error, "");
}

// Issue 17 item 2: a sphere with its centre exactly on the axis of an `outside` cylinder
// (a rod) has the deepest overlap there is, r + R; the contact must be found, with a unit
// normal across the axis.
TEST(CylinderContact, SphereOnTheAxisOfARodIsSeen) {
  for (const Vec3& axis : {Vec3(Vec3::UnitX()), Vec3(1, 1, 0).normalized(), Vec3(0, 0.6, -0.8)}) {
    CylinderWall rod;
    rod.axis_point = Vec3(0.5, 0, 0);
    rod.axis = axis;
    rod.radius = 0.5e-3;
    rod.inside = false;
    WallTouch t;
    ASSERT_TRUE(touch_cylinder(rod, rod.axis_point, kR, t)) << axis.transpose();
    EXPECT_DOUBLE_EQ(t.overlap, kR + rod.radius);
    EXPECT_NEAR(t.n.norm(), 1, 1e-15);
    EXPECT_NEAR(t.n.dot(rod.axis), 0, 1e-15);
    // Deterministic: the same direction for the same axis.
    WallTouch again;
    ASSERT_TRUE(touch_cylinder(rod, rod.axis_point, kR, again));
    EXPECT_EQ(t.n, again.n);
  }
  // Along the axis (exactly: the axis is x), the same.
  CylinderWall rod;
  rod.axis = Vec3::UnitX();
  rod.radius = 0.5e-3;
  rod.inside = false;
  WallTouch t;
  ASSERT_TRUE(touch_cylinder(rod, Vec3(0.25, 0, 0), kR, t));
  EXPECT_DOUBLE_EQ(t.overlap, kR + rod.radius);
  EXPECT_EQ(t.n.dot(rod.axis), 0);
}

}  // namespace
}  // namespace grainflow
