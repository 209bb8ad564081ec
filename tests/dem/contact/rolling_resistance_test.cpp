// A sphere rolling without slip on a plane, slowed by rolling resistance only.
//
// Reference (energy balance): the resisting torque M = mu_r R F_n = mu_r R m g does
// work M s / R over a rolled distance s, and the kinetic energy of rolling is
// (1/2) m v^2 + (1/2) (2/5) m R^2 (v/R)^2 = (7/10) m v^2, so the sphere stops after
//   s = 0.7 v0^2 / (mu_r g).
// CDT applies exactly that torque from the first step: tolerance 2 % (the sphere sits
// in a Hertz dimple of depth ~1e-3 R, which shortens the lever arm by that much).
// EPSD first winds up its spring (elastic phase, distance ~ M_max/k_r R ~ 1e-3 of s)
// and then acts as CDT: tolerance 3 %.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "dem/engine/simulation.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

double stop_distance(RollingModel model, double mu_r, double v0) {
  const double r = 2e-3, rho = 2500, g = 9.81, y = 1e8, nu = 0.3;
  Scene s = test::one_material_scene(y, nu, rho, 0.5, 0.5, mu_r);
  s.gravity = Vec3(0, 0, -g);
  s.contact.tangential = TangentialModel::history;
  s.contact.rolling = model;
  s.walls.push_back(test::plane(Vec3::Zero(), Vec3::UnitZ()));
  Simulation sim(s, false);
  const double m = rho * sphere_volume(r);
  // Start in static equilibrium: m g = (4/3) Y* sqrt(R) d^{3/2}.
  const double y_star = y / (1 - nu * nu);
  const double d_eq = std::pow(m * g / (4.0 / 3.0 * y_star * std::sqrt(r)), 2.0 / 3.0);
  sim.particles().add(1, Vec3(0, 0, r - d_eq), Vec3(v0, 0, 0), Vec3(0, v0 / r, 0), r, 0, rho);
  sim.set_dt(2e-6);
  sim.initialise();
  const double t_max = 3 * v0 / (5.0 / 7.0 * mu_r * g);
  while (sim.time() < t_max) {
    sim.step();
    if (sim.particles().v[0][0] <= 0) break;
  }
  EXPECT_LT(sim.time(), t_max) << "the sphere did not stop";
  return sim.particles().x[0][0];
}

TEST(RollingResistance, CdtStopsAtEnergyBalanceDistance) {
  const double mu_r = 0.1, v0 = 0.1;
  const double s_ref = 0.7 * v0 * v0 / (mu_r * 9.81);
  const double s = stop_distance(RollingModel::cdt, mu_r, v0);
  std::printf("CDT stop distance %.6g m, energy balance %.6g m (ratio %.4f)\n", s, s_ref, s / s_ref);
  EXPECT_NEAR(s / s_ref, 1.0, 0.02);
}

TEST(RollingResistance, EpsdStopsAtEnergyBalanceDistance) {
  const double mu_r = 0.1, v0 = 0.1;
  const double s_ref = 0.7 * v0 * v0 / (mu_r * 9.81);
  const double s = stop_distance(RollingModel::epsd, mu_r, v0);
  std::printf("EPSD stop distance %.6g m, energy balance %.6g m (ratio %.4f)\n", s, s_ref, s / s_ref);
  EXPECT_NEAR(s / s_ref, 1.0, 0.03);
}

TEST(RollingResistance, NoneLetsTheSphereRollOn) {
  // Without rolling resistance (and no slip) nothing dissipates: the speed stays.
  const double r = 2e-3, rho = 2500;
  Scene s = test::one_material_scene(1e8, 0.3, rho, 0.5, 0.5, 0.1);
  s.gravity = Vec3(0, 0, -9.81);
  s.contact.tangential = TangentialModel::history;
  s.walls.push_back(test::plane(Vec3::Zero(), Vec3::UnitZ()));
  Simulation sim(s, false);
  const double m = rho * sphere_volume(r);
  const double d_eq = std::pow(m * 9.81 / (4.0 / 3.0 * 1e8 / 0.91 * std::sqrt(r)), 2.0 / 3.0);
  sim.particles().add(1, Vec3(0, 0, r - d_eq), Vec3(0.1, 0, 0), Vec3(0, 0.1 / r, 0), r, 0, rho);
  sim.set_dt(2e-6);
  sim.initialise();
  sim.advance_to(0.05);
  EXPECT_NEAR(sim.particles().v[0][0], 0.1, 1e-3);
}

}  // namespace
}  // namespace grainflow
