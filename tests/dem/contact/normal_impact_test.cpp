// Head-on impacts, sphere-sphere and sphere-wall, against closed forms.
//
// Elastic Hertz (Johnson 1985, §11.4): delta_max = (15 m* v^2 / (16 Y* sqrt(R*)))^{2/5},
// t_c = 2.9432 delta_max / v (the 2.868 (m*^2/(R* Y*^2 v))^{1/5} of DESIGN.md §3 is the
// same constant to 1e-4). Damped impacts: the measured restitution must equal the
// requested one. End of contact: the first step after impact at which the overlap is
// no longer positive; the restitution is the ratio of separation to approach speed
// measured then. Time steps are t_c/2000 so integration error stays well below the
// tolerances (velocity Verlet is second order: error ~ (dt/t_c)^2).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "dem/contact/restitution_mapping.hpp"
#include "dem/engine/simulation.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

constexpr double kY = 1e7, kNu = 0.3, kRho = 2500, kR = 1e-3;

struct Impact {
  double max_overlap = 0;
  double contact_time = 0;
  double speed_out = 0;  // normal separation speed after contact
};

// Two equal spheres approaching along x at +-v/2 each (relative speed v), or one
// sphere hitting a plane at x = 0 with speed v when `wall`.
Impact head_on(NormalModel model, double e, double v, bool wall, double hooke_v = 0) {
  Scene s = test::one_material_scene(kY, kNu, kRho, e);
  s.contact.normal = model;
  if (model == NormalModel::hooke) s.contact.hooke_characteristic_velocity = hooke_v;
  if (wall) s.walls.push_back(test::plane(Vec3::Zero(), Vec3::UnitX()));
  Simulation sim(s, false);
  Particles& p = sim.particles();
  if (wall) {
    p.add(1, Vec3(kR * 1.0001, 0, 0), Vec3(-v, 0, 0), Vec3::Zero(), kR, 0, kRho);
  } else {
    p.add(1, Vec3(-kR * 1.0001, 0, 0), Vec3(0.5 * v, 0, 0), Vec3::Zero(), kR, 0, kRho);
    p.add(2, Vec3(kR * 1.0001, 0, 0), Vec3(-0.5 * v, 0, 0), Vec3::Zero(), kR, 0, kRho);
  }
  const double m = kRho * sphere_volume(kR);
  const double m_star = wall ? m : m / 2, r_star = wall ? kR : kR / 2;
  // The wall has the same material as the sphere, so Y* takes both terms here too.
  const double y_star = kY / (2 * (1 - kNu * kNu));
  const double tc = hertz_contact_time(y_star, r_star, m_star, v);
  sim.set_dt(tc / 2000);
  sim.initialise();

  auto overlap = [&] {
    const Particles& q = sim.particles();
    return wall ? kR - q.x[0][0] : 2 * kR - (q.x[1] - q.x[0]).norm();
  };
  Impact r;
  double t_start = -1;
  for (long k = 0; k < 20'000'000; ++k) {
    sim.step();
    const double d = overlap();
    if (d > 0 && t_start < 0) t_start = sim.time() - sim.dt();  // contact began during this step
    if (d > 0) r.max_overlap = std::max(r.max_overlap, d);
    if (t_start >= 0 && d <= 0) {
      r.contact_time = sim.time() - t_start;
      const Particles& q = sim.particles();
      r.speed_out = wall ? q.v[0][0] : q.v[1][0] - q.v[0][0];
      return r;
    }
  }
  ADD_FAILURE() << "contact did not end";
  return r;
}

double hertz_max_overlap(double y_star, double r_star, double m_star, double v) {
  return std::pow(15 * m_star * v * v / (16 * y_star * std::sqrt(r_star)), 0.4);
}

TEST(ElasticHertzImpact, SphereSphereMatchesClosedForm) {
  const double v = 0.5;
  const Impact r = head_on(NormalModel::hertz, 1.0, v, false);
  const double m = kRho * sphere_volume(kR);
  const double y_star = kY / (2 * (1 - kNu * kNu));
  const double d_max = hertz_max_overlap(y_star, kR / 2, m / 2, v);
  const double t_c = 2.9432 * d_max / v;
  // Tolerance 1 % (acceptance); the time is resolved to one step, dt = t_c/2000.
  std::printf("sphere-sphere: overlap %.6f, contact time %.6f, rebound %.7f of closed form\n",
              r.max_overlap / d_max, r.contact_time / t_c, r.speed_out / v);
  EXPECT_NEAR(r.max_overlap / d_max, 1.0, 0.01);
  EXPECT_NEAR(r.contact_time / t_c, 1.0, 0.01);
  EXPECT_NEAR(r.speed_out / v, 1.0, 0.001);
}

TEST(ElasticHertzImpact, SphereWallMatchesClosedForm) {
  const double v = 0.5;
  const Impact r = head_on(NormalModel::hertz, 1.0, v, true);
  const double m = kRho * sphere_volume(kR);
  const double y_star = kY / (2 * (1 - kNu * kNu));  // wall of the sphere's material
  const double d_max = hertz_max_overlap(y_star, kR, m, v);
  const double t_c = 2.9432 * d_max / v;
  std::printf("sphere-wall: overlap %.6f, contact time %.6f, rebound %.7f of closed form\n",
              r.max_overlap / d_max, r.contact_time / t_c, r.speed_out / v);
  EXPECT_NEAR(r.max_overlap / d_max, 1.0, 0.01);
  EXPECT_NEAR(r.contact_time / t_c, 1.0, 0.01);
  EXPECT_NEAR(r.speed_out / v, 1.0, 0.001);
}

TEST(ElasticHertzImpact, ScaledContactTimeConstant) {
  // The scaled oscillator x'' = -x^{3/2}, x'(0)=1 lasts 2.9432 (5/4)^{2/5}... in units where
  // d* = (m v^2/K)^{2/5}; with K = (4/3) Y* sqrt(R*) this is Johnson's 2.9432 delta_max / v
  // and delta_max/d* = (5/4)^{2/5}.
  EXPECT_NEAR(hertz_scaled_contact_time(0.0), 2.9432 * std::pow(1.25, 0.4), 2e-3);
}

// hertz_damping_for_restitution halves its bracket twice per round, evaluating the midpoint
// and both quarter points at once in lanes; its b must be, to the bit, what one halving per
// evaluation of the scalar hertz_restitution gives (the bisection written out here), and its
// restitution the one asked for (to the integration's 1e-9).
TEST(RestitutionMapping, LaneBisectionIsTheScalarBisection) {
  for (const double e : {0.999, 0.5, 0.07}) {
    double lo = 0, hi = 0.25;
    while (hertz_restitution(hi) > e) hi *= 2;
    for (int it = 0; it < 60 && hi - lo > 1e-12 * hi; ++it) {
      const double mid = 0.5 * (lo + hi);
      (hertz_restitution(mid) > e ? lo : hi) = mid;
    }
    const double b = hertz_damping_for_restitution(e);
    EXPECT_EQ(b, 0.5 * (lo + hi)) << "e = " << e;
    EXPECT_NEAR(hertz_restitution(b), e, 1e-9) << "e = " << e;
  }
}

class DampedImpact : public ::testing::TestWithParam<double> {};

TEST_P(DampedImpact, HertzWallRestitutionAsRequested) {
  const double e = GetParam();
  const Impact r = head_on(NormalModel::hertz, e, 0.5, true);
  std::printf("hertz wall: requested e = %.1f, measured %.6f\n", e, r.speed_out / 0.5);
  EXPECT_NEAR(r.speed_out / 0.5, e, 0.01 * e);  // 1 % (acceptance)
}

TEST_P(DampedImpact, HertzPairRestitutionAsRequested) {
  const double e = GetParam();
  const Impact r = head_on(NormalModel::hertz, e, 0.5, false);
  EXPECT_NEAR(r.speed_out / 0.5, e, 0.01 * e);
}

TEST_P(DampedImpact, HertzRestitutionIndependentOfSpeed) {
  const double e = GetParam();
  const Impact r = head_on(NormalModel::hertz, e, 3.0, true);
  EXPECT_NEAR(r.speed_out / 3.0, e, 0.01 * e);
}

TEST_P(DampedImpact, HookeWallRestitutionAsRequested) {
  const double e = GetParam();
  const Impact r = head_on(NormalModel::hooke, e, 0.5, true, 0.5);
  EXPECT_NEAR(r.speed_out / 0.5, e, 0.01 * e);
}

TEST_P(DampedImpact, HookePairRestitutionAsRequested) {
  const double e = GetParam();
  const Impact r = head_on(NormalModel::hooke, e, 0.5, false, 0.5);
  EXPECT_NEAR(r.speed_out / 0.5, e, 0.01 * e);
}

INSTANTIATE_TEST_SUITE_P(Restitution, DampedImpact, ::testing::Values(0.1, 0.3, 0.5, 0.7, 0.9));

TEST(HookeImpact, CharacteristicVelocityReproducesHertzMaxOverlap) {
  // The characteristic-velocity stiffness is defined so that an elastic impact at
  // that speed reaches the Hertz maximum overlap: k delta^2/2 = m v^2/2 with delta = d_max.
  const double v = 0.5;
  const Impact r = head_on(NormalModel::hooke, 1.0, v, true, v);
  const double m = kRho * sphere_volume(kR);
  const double d_max = hertz_max_overlap(kY / (2 * (1 - kNu * kNu)), kR, m, v);
  EXPECT_NEAR(r.max_overlap / d_max, 1.0, 0.01);
  EXPECT_NEAR(r.speed_out / v, 1.0, 0.001);
}

TEST(HookeImpact, ExplicitStiffnessContactTime) {
  // Linear elastic contact lasts half a period: t_c = pi sqrt(m*/k).
  Scene s = test::one_material_scene(kY, kNu, kRho, 1.0);
  s.contact.normal = NormalModel::hooke;
  s.contact.hooke_kn = 500.0;
  s.walls.push_back(test::plane(Vec3::Zero(), Vec3::UnitX()));
  Simulation sim(s, false);
  sim.particles().add(1, Vec3(kR * 1.0001, 0, 0), Vec3(-0.2, 0, 0), Vec3::Zero(), kR, 0, kRho);
  const double m = kRho * sphere_volume(kR);
  const double tc = std::acos(-1.0) * std::sqrt(m / 500.0);
  sim.set_dt(tc / 2000);
  sim.initialise();
  double t_start = -1;
  while (sim.time() < 10 * tc) {
    sim.step();
    const double d = kR - sim.particles().x[0][0];
    if (d > 0 && t_start < 0) t_start = sim.time() - sim.dt();
    if (t_start >= 0 && d <= 0) break;
  }
  EXPECT_NEAR((sim.time() - t_start) / tc, 1.0, 0.002);
  EXPECT_NEAR(sim.particles().v[0][0] / 0.2, 1.0, 0.001);
}

}  // namespace
}  // namespace grainflow
