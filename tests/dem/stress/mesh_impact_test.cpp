// High-speed impacts on triangle-mesh walls (issue 8): the mesh version of
// high_speed_impact_test. 10, 25 and 50 m/s at dt = 0.2 t_R (time.rayleigh_fraction) on
// a flat triangulated floor (2 x 4^2 triangles of 4 mm legs), aimed at a triangle's
// face, at an edge shared by two triangles and at a vertex shared by 8, and on a ramp
// (the same mesh tilted 30 degrees about x) aimed at a face and a vertex, falling
// vertically so that the impact is oblique. Glass (Y = 60 GPa) and a soft Y = 150 MPa;
// frictionless (a face, an edge or a vertex of a flat mesh gives the normal of the plane,
// theory/walls.md, so the impact is the plane's).
//
// Invariants at every step: one particle, finite state, the centre on the mesh's side
// (signed distance to the mesh plane > 0: no tunnelling), at most one contact (one
// contact per touching feature of the mesh, never one per triangle).
//
// Reference: the elastic Hertz closed form for the normal impact at v_n = v cos(tilt),
//   d_max = (15 m v_n^2 / (16 Y* sqrt(R)))^{2/5}        (DESIGN.md §3; R* = r, m* = m)
// with the same margin of a factor 1.4 either side of time.max_overlap as the plane case:
// - resolved: the normal rebound speed is e v_n within 3 % (e = 0.9; the b(e) mapping is
//   good to 1 % at >= 20 steps per contact, docs/models/contact-models.md; 50 m/s on glass
//   gets only ~15), the deepest overlap is d_max within 10 % (damping shortens it by a few
//   %), and the speed along the ramp is kept to 1e-9 relative (frictionless: the force is
//   along the plane normal to round-off);
// - beyond the limit: the overlap guard stops the run with its message, within one step's
//   travel past the limit, the centre still on the mesh's side; the message calls it an
//   overload (no step prevents it), and the scene rerun with the max_overlap it proposes
//   rebounds.
// A last case is faster than one radius per step (50 m/s with dt = 3e-5 s, 1.5 r per
// step): the engine does not claim to resolve that (theory/walls.md: keep overlaps a small
// fraction of r), and the travel guard (time.max_step_travel, 1 r) refuses it before the
// first drift (MeshImpactTravel below). With that guard off, the sphere lands with its
// centre 0.5 r past the two-sided mesh, and the overlap guard must stop it at that step
// with a message that says it tunnelled and gives a step that, rerun, resolves the impact.
// Faster still, 2.5 r per step (dt = 5e-5 s), the sphere jumps from above the mesh to
// 1.5 r below it in one step and never overlaps it at the end of a step: with the travel
// guard off it is through the wall unseen, which is what that guard is for.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <ostream>

#include "tests/dem/stress/stress_support.hpp"
#include "tests/dem/support/test_scene.hpp"
#include "tests/dem/walls/mesh_support.hpp"

namespace grainflow {
namespace {

constexpr double kNu = 0.25, kRho = 2500, kR = 1e-3, kE = 0.9;
constexpr double kLeg = 0.004;  // triangle legs; the mesh spans [-8, 8] mm

struct MeshImpact {
  const char* name;
  double youngs;   // [Pa]
  double speed;    // [m/s]
  double tilt;     // ramp angle about x [rad]; 0: flat floor
  double along_x;  // aim point in the mesh's own (untilted) plane [m]
  double along_y;
  double dt = 0;  // fixed step [s]; 0: 0.2 t_R
};

void PrintTo(const MeshImpact& c, std::ostream* os) {
  *os << c.name << " at " << c.speed << " m/s";
}

// Rotation about x by the tilt: (x, y, 0) -> (x, y cos a, y sin a); the plane's normal is
// (0, -sin a, cos a).
Vec3 tilted(const Vec3& x, double a) {
  return Vec3(x[0], std::cos(a) * x[1] - std::sin(a) * x[2],
              std::sin(a) * x[1] + std::cos(a) * x[2]);
}

double y_star(double youngs) {
  return youngs / (2 * (1 - kNu * kNu));
}  // wall of the same material

double predicted_overlap_ratio(double youngs, double vn) {
  const double m = kRho * sphere_volume(kR);
  return std::pow(15 * m * vn * vn / (16 * y_star(youngs) * std::sqrt(kR)), 0.4) / kR;
}

struct ImpactRun {
  std::string stop;
  double lowest = 1;  // smallest signed distance of the centre to the plane / r
  bool rebounded = false;
  long max_contacts = 0;
  Vec3 v_out = Vec3::Zero();
  double dt = 0, max_overlap_ratio = 0;
};

ImpactRun impact(const MeshImpact& c, double dt, double max_step_travel = 1,
                 long max_steps = 2000 * test::stress_scale(), double max_overlap = 0.25) {
  Scene s = test::one_material_scene(c.youngs, kNu, kRho, kE);
  s.time.max_step_travel = max_step_travel;
  s.time.max_overlap = max_overlap;
  if (dt > 0) {
    s.time.step = dt;
  } else {
    s.time.step.reset();
    s.time.rayleigh_fraction = 0.2;
  }
  s.time.expected_max_speed = c.speed;
  // The domain reaches well below the mesh, so a tunnelled sphere would be seen, not removed.
  s.domain.lo = Vec3(-0.012, -0.012, -0.012);
  s.domain.hi = Vec3(0.012, 0.012, 0.012);
  test::MeshData mesh = test::flat_grid(4, kLeg, -2 * kLeg, -2 * kLeg, 0);
  for (Vec3& v : mesh.v) v = tilted(v, c.tilt);
  // One file per case: CTest runs the cases at once, and several share a mesh name.
  s.walls.push_back(test::mesh_wall(test::write_mesh(
      mesh, std::string(c.name) + "_" + std::to_string(static_cast<int>(c.speed)) + ".stl")));
  const Vec3 normal = tilted(Vec3::UnitZ(), c.tilt),
             target = tilted(Vec3(c.along_x, c.along_y, 0), c.tilt);
  // Falling vertically, 1 um (measured along the normal) before touching at the target.
  const Vec3 velocity(0, 0, -c.speed);
  const Vec3 start = target + kR * normal + (1e-6 / std::cos(c.tilt)) * Vec3::UnitZ();
  Simulation sim(s, false);
  sim.particles().add(1, start, velocity, Vec3::Zero(), kR, 0, kRho);
  ImpactRun r;
  try {
    sim.initialise();
    r.dt = sim.dt();
    for (long k = 0; k < max_steps; ++k) {
      sim.step();
      const Particles& p = sim.particles();
      EXPECT_EQ(p.size(), 1u);
      if (p.size() != 1 || !test::all_finite(p)) {
        ADD_FAILURE() << "lost or non-finite at step " << k;
        break;
      }
      const double side = (p.x[0] - target).dot(normal) / kR;
      r.lowest = std::min(r.lowest, side);
      r.max_contacts = std::max(r.max_contacts, sim.counters().contacts);
      if (side > 1 + 1e-6 && p.v[0].dot(normal) > 0) {
        r.rebounded = true;
        r.v_out = p.v[0];
        break;
      }
    }
  } catch (const ParallelError& e) {
    r.stop = e.what();
  }
  r.max_overlap_ratio = sim.counters().max_overlap_ratio;
  return r;
}

class MeshImpactTest : public testing::TestWithParam<MeshImpact> {};

TEST_P(MeshImpactTest, NeverTunnelsThroughTheMesh) {
  const MeshImpact c = GetParam();
  const Vec3 normal = tilted(Vec3::UnitZ(), c.tilt);
  const Vec3 v_in(0, 0, -c.speed);
  const double vn = -v_in.dot(normal);
  const Vec3 v_tangential = v_in + vn * normal;
  const double expected = predicted_overlap_ratio(c.youngs, vn);
  const double limit = 0.25;  // time.max_overlap, default
  // Beyond one radius per step the travel guard would stop the run before anything
  // moves (MeshImpactTravel): off here, to test the overlap guard behind it.
  const bool too_fast = c.dt > 0 && c.speed * c.dt > kR;
  const ImpactRun r = impact(c, c.dt, too_fast ? 0 : 1);
  const double travel = c.speed * r.dt / kR;  // per step, in radii

  if (travel > 1) {
    // Faster than one radius per step: the guard must stop it at its first step past the mesh.
    ASSERT_FALSE(r.stop.empty()) << "expected the overlap guard to stop a sphere moving " << travel
                                 << " r per step";
    EXPECT_NE(r.stop.find("particle 1 and wall '"), std::string::npos) << r.stop;
    EXPECT_NE(r.stop.find("tunnelled"), std::string::npos) << r.stop;
    EXPECT_NE(r.stop.find("key time.max_overlap"), std::string::npos) << r.stop;
    // Started 1 um before touching and moved 1.5 r: the centre is 0.5 r - 1 um past the
    // mesh plane, so the (two-sided) overlap is 50 % + 1 um (4 printed digits).
    const double landed = 100 * (2 - travel + 1e-6 / kR);
    EXPECT_NEAR(test::number_after(r.stop, "overlap by "), landed, 0.01) << r.stop;
    const double suggested = test::number_after(r.stop, "at most ");
    ASSERT_GT(suggested, 0.0) << r.stop;
    ASSERT_LT(suggested, r.dt) << r.stop;
    // The suggestion (t_c/20 at 50 m/s) resolves the same impact.
    const ImpactRun fine = impact(c, suggested);
    EXPECT_TRUE(fine.stop.empty()) << fine.stop;
    EXPECT_TRUE(fine.rebounded);
    EXPECT_GT(fine.lowest, 0.0);
    const double e = fine.v_out.dot(normal) / vn;
    EXPECT_NEAR(e / kE, 1.0, 0.03);
    std::printf(
        "%s at %4.0f m/s: dt = %.2e s (%.2f r per step) stopped by the overlap guard "
        "at its first step, %.2f %% overlap with the centre past the mesh; suggested dt "
        "%.3e s resolves it: e = %.4f, deepest %.2f %% r\n",
        c.name, c.speed, r.dt, travel, landed, suggested, e, 100 * (1 - fine.lowest));
    return;
  }

  ASSERT_TRUE(expected < limit / 1.4 || expected > 1.4 * limit)
      << "case too close to the guard to state an expectation: " << expected;
  EXPECT_GT(r.lowest, 0.0) << "tunnelled: the centre crossed the mesh plane";
  EXPECT_LE(r.max_contacts, 1) << "more than one contact with one flat mesh";
  const double steps_per_contact =
      hertz_contact_time(y_star(c.youngs), kR, kRho * sphere_volume(kR), vn) / r.dt;
  const double deepest = 1 - r.lowest;
  if (expected < limit) {
    ASSERT_TRUE(r.stop.empty()) << r.stop;
    ASSERT_TRUE(r.rebounded);
    const double e = r.v_out.dot(normal) / vn;
    const Vec3 tangential_out = r.v_out - r.v_out.dot(normal) * normal;
    const double slip = v_tangential.norm() > 0
                            ? (tangential_out - v_tangential).norm() / v_tangential.norm()
                            : tangential_out.norm();
    EXPECT_NEAR(e / kE, 1.0, 0.03);
    EXPECT_NEAR(deepest / expected, 1.0, 0.1);
    EXPECT_LT(slip, 1e-9);
    std::printf(
        "%s at %4.0f m/s: resolved, dt = %.3e s (%.1f steps per contact at v_n = %.1f "
        "m/s), deepest %.2f %% r (closed form %.2f %%), e = %.4f (asked %.2f), "
        "tangential change %.1e\n",
        c.name, c.speed, r.dt, steps_per_contact, vn, 100 * deepest, 100 * expected, e, kE, slip);
  } else {
    // Beyond the limit whatever the step: an overload, with the closed form's undamped stop
    // and a max_overlap that carries the impact when rerun with it.
    ASSERT_FALSE(r.stop.empty()) << "expected the overlap guard to stop an impact predicted to "
                                    "overlap by "
                                 << 100 * expected << " % r";
    EXPECT_NE(r.stop.find("particle 1 and wall '"), std::string::npos) << r.stop;
    EXPECT_NE(r.stop.find("key time.max_overlap"), std::string::npos) << r.stop;
    EXPECT_NE(r.stop.find("The contact is overloaded"), std::string::npos) << r.stop;
    EXPECT_EQ(r.stop.find("A step of at most"), std::string::npos) << r.stop;
    EXPECT_LT(r.max_overlap_ratio, limit + vn * r.dt / kR);
    const double stop = test::number_after(r.stop, "it stops at ") / 100;
    // The state of a step at ~10 steps per contact carries the integration's energy error (+4
    // to +6 % here), so the prediction from it is the closed form's within 10 %.
    EXPECT_NEAR(stop / expected, 1.0, 0.1) << r.stop;
    const double proposed = test::number_after(r.stop, "set time.max_overlap to at least ");
    ASSERT_GT(proposed, expected) << r.stop;
    ASSERT_LE(proposed, 1.0) << r.stop;
    // A limit of 0.5 or more on a mesh needs a smaller travel per step (a centre could cross
    // the sheet unseen): the message gives it, and the rerun takes both.
    const double step_travel =
        proposed >= 0.5 ? test::number_after(r.stop, "time.max_step_travel to at most ") : 1.0;
    ASSERT_GT(step_travel, 0.0) << r.stop;
    if (proposed >= 0.5) {
      EXPECT_LT(step_travel, 2 * (1 - proposed)) << r.stop;
    }
    const ImpactRun rerun = impact(c, c.dt, step_travel, 2000 * test::stress_scale(), proposed);
    EXPECT_TRUE(rerun.stop.empty()) << rerun.stop;
    EXPECT_TRUE(rerun.rebounded);
    EXPECT_GT(rerun.lowest, 0.0);
    EXPECT_LT(1 - rerun.lowest, proposed);
    EXPECT_NEAR(rerun.v_out.dot(normal) / vn / kE, 1.0, 0.03);
    std::printf(
        "%s at %4.0f m/s: stopped by the overlap guard at %.1f %% r (closed form %.1f "
        "%%, predicted undamped stop %.1f %%), dt = %.3e s: overload; rerun with max_overlap "
        "%.3g: deepest %.1f %% r, e = %.4f\n",
        c.name, c.speed, 100 * r.max_overlap_ratio, 100 * expected, 100 * stop, r.dt, proposed,
        100 * (1 - rerun.lowest), rerun.v_out.dot(normal) / vn);
  }
}

// The travel guard: 1.5 and 2.5 r per step at 50 m/s on glass (dt = 3e-5 and 5e-5 s).
TEST(MeshImpactTravel, FasterThanOneRadiusPerStepIsStoppedBeforeItMoves) {
  for (const double dt : {3e-5, 5e-5}) {
    const MeshImpact c{"glass_vertex_travel", 60e9, 50, 0, 0, 0, dt};
    const double travel = c.speed * dt / kR;
    SCOPED_TRACE(travel);

    // Guard on (default 1 r): stopped at start-up, before the first drift, the sphere
    // still 1 um above the mesh.
    const ImpactRun on = impact(c, dt);
    ASSERT_FALSE(on.stop.empty()) << "the travel guard did not stop a sphere moving " << travel
                                  << " r per step";
    EXPECT_NE(on.stop.find("t = 0 s (step 1): particle 1 moves"), std::string::npos) << on.stop;
    EXPECT_NEAR(test::number_after(on.stop, "particle 1 moves "), travel, 1e-3) << on.stop;
    EXPECT_NE(on.stop.find("key time.max_step_travel"), std::string::npos) << on.stop;
    EXPECT_EQ(on.lowest, 1.0);  // nothing moved
    // The step that keeps it within one radius, r / v rounded down to three digits, or the
    // start-up check's step when that check refuses dt too (so a rerun passes both).
    const double proposed = test::number_after(on.stop, "A step of at most ");
    const bool startup = on.stop.find("passes every start-up check") != std::string::npos;
    const double within =
        startup ? test::number_after(on.stop, " s keeps it within the limit (") : proposed;
    if (startup) {
      EXPECT_LT(proposed, within) << on.stop;
    }
    EXPECT_LE(within, kR / c.speed) << on.stop;
    EXPECT_GT(within, 0.99 * kR / c.speed) << on.stop;
    // The step that resolves the impact: t_c / 20 at 50 m/s against a glass wall, Hertz
    // closed form (DESIGN.md §3) with R* = r, m* = m.
    const double tc =
        hertz_contact_time(y_star(c.youngs), kR, kRho * sphere_volume(kR), c.speed);
    const double suggested = test::number_after(on.stop, "needs at most ");
    EXPECT_NEAR(suggested / (tc / 20), 1.0, 1e-3) << on.stop;

    // Rerun with the suggested step: resolved, e within 3 % as for the other glass impacts.
    const ImpactRun fine = impact(c, suggested);
    EXPECT_TRUE(fine.stop.empty()) << fine.stop;
    ASSERT_TRUE(fine.rebounded);
    EXPECT_GT(fine.lowest, 0.0);
    const double e = fine.v_out[2] / c.speed;
    EXPECT_NEAR(e / kE, 1.0, 0.03);

    // Guard off, at 2.5 r per step: the centre goes from 1 um above touching to 1.5 r
    // below the plane in one step, more than r from it, so it never overlaps the mesh at
    // a step's end. No contact guard sees anything, and the sphere is through the wall.
    // (One step: it would then leave the domain through its floor.)
    if (travel > 2) {
      const ImpactRun off = impact(c, dt, 0, 1);
      EXPECT_TRUE(off.stop.empty()) << off.stop;
      EXPECT_EQ(off.max_contacts, 0);
      EXPECT_LT(off.lowest, -1.0) << "expected the unguarded sphere to pass the mesh";
      std::printf("glass vertex at 50 m/s, %.1f r per step, travel guard off: passed the mesh "
                  "unseen (centre %.3f r below it, 0 contacts)\n",
                  travel, -off.lowest);
    }
    std::printf(
        "glass vertex at 50 m/s, dt = %.1e s (%.1f r per step): stopped by the travel guard "
        "at start-up; suggested dt %.3e s resolves it: e = %.4f, deepest %.2f %% r\n",
        dt, travel, suggested, e, 100 * (1 - fine.lowest));
  }
}

constexpr double kRamp = std::numbers::pi / 6;

INSTANTIATE_TEST_SUITE_P(
    Impacts, MeshImpactTest,
    testing::Values(
        // Flat floor: inside a face, on an edge of two triangles, on a vertex of 8.
        MeshImpact{"glass_face", 60e9, 10, 0, 0.001, 0.0015},
        MeshImpact{"glass_face", 60e9, 25, 0, 0.001, 0.0015},
        MeshImpact{"glass_face", 60e9, 50, 0, 0.001, 0.0015},
        MeshImpact{"glass_edge", 60e9, 10, 0, 0.002, 0},
        MeshImpact{"glass_edge", 60e9, 25, 0, 0.002, 0},
        MeshImpact{"glass_edge", 60e9, 50, 0, 0.002, 0},
        MeshImpact{"glass_vertex", 60e9, 10, 0, 0, 0},
        MeshImpact{"glass_vertex", 60e9, 25, 0, 0, 0},
        MeshImpact{"glass_vertex", 60e9, 50, 0, 0, 0},
        // Ramp at 30 degrees, falling vertically: v_n = v cos 30.
        MeshImpact{"glass_ramp_face", 60e9, 50, kRamp, 0.001, 0.0015},
        MeshImpact{"glass_ramp_vertex", 60e9, 50, kRamp, 0, 0},
        MeshImpact{"soft_vertex", 1.5e8, 10, 0, 0, 0},
        MeshImpact{"soft_edge", 1.5e8, 25, 0, 0.002, 0},
        MeshImpact{"soft_vertex", 1.5e8, 50, 0, 0, 0},
        MeshImpact{"soft_ramp_face", 1.5e8, 50, kRamp, 0.001, 0.0015},
        // 1.5 r per step.
        MeshImpact{"glass_vertex_one_and_a_half_radii_per_step", 60e9, 50, 0, 0, 0, 3e-5}),
    [](const testing::TestParamInfo<MeshImpact>& i) {
      return std::string(i.param.name) + "_" + std::to_string(static_cast<int>(i.param.speed)) +
             "ms";
    });

}  // namespace
}  // namespace grainflow
