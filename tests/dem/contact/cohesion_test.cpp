// SJKR cohesion: two equal spheres that touch with no gravity pull together and
// settle where the Hertz repulsion balances the cohesive force,
//   (4/3) Y* sqrt(R*) d^{3/2} = k_c pi a^2,   a^2 = r d - d^2/4 (overlap disc of two
// spheres of radius r whose centres are 2r - d apart). Reference: that root, found
// here by bisection. Tolerance 0.5 %: the residual oscillation after damping.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "dem/contact/cohesion.hpp"
#include "dem/engine/simulation.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

TEST(SjkrCohesion, PairSettlesAtForceBalance) {
  const double y = 1e7, nu = 0.3, rho = 2500, r = 1e-3, kc = 1.65e5;
  Scene s = test::one_material_scene(y, nu, rho, 0.3, 0.0, 0.0, kc);
  s.contact.cohesion = CohesionModel::sjkr;
  Simulation sim(s, false);
  const double d0 = 1e-3 * r;  // barely touching, at rest
  sim.particles().add(1, Vec3(-(r - d0 / 2), 0, 0), Vec3::Zero(), Vec3::Zero(), r, 0, rho);
  sim.particles().add(2, Vec3(r - d0 / 2, 0, 0), Vec3::Zero(), Vec3::Zero(), r, 0, rho);
  sim.set_dt(5e-8);
  sim.initialise();
  sim.advance_to(0.02);
  const double d = 2 * r - (sim.particles().x[1] - sim.particles().x[0]).norm();

  const double y_star = y / (2 * (1 - nu * nu)), r_star = r / 2;
  auto balance = [&](double dd) {
    return 4.0 / 3.0 * y_star * std::sqrt(r_star) * std::pow(dd, 1.5) -
           kc * std::numbers::pi * (r * dd - dd * dd / 4);
  };
  double lo = 1e-9 * r, hi = 0.5 * r;  // balance < 0 at lo (cohesion wins), > 0 at hi
  ASSERT_LT(balance(lo), 0);
  ASSERT_GT(balance(hi), 0);
  for (int k = 0; k < 200; ++k) (balance(0.5 * (lo + hi)) < 0 ? lo : hi) = 0.5 * (lo + hi);
  EXPECT_NEAR(d / lo, 1.0, 0.005);
}

TEST(SjkrCohesion, OverlapAreaOfTwoSpheres) {
  // Overlap disc radius of two spheres r_i = 1, r_j = 2 at distance 2.5: the circle
  // where the spheres intersect, a^2 = r_i^2 - x^2 with x = (d^2 + r_i^2 - r_j^2) / (2d).
  ContactGeometry g{};
  g.distance = 2.5;
  g.r_i = 1;
  g.r_j = 2;
  g.wall = false;
  const double x = (2.5 * 2.5 + 1 - 4) / 5.0;
  EXPECT_NEAR(SjkrCohesion::contact_area(g), std::numbers::pi * (1 - x * x), 1e-12);
}

}  // namespace
}  // namespace grainflow
