// A time step far too large for an impact stops the run as soon as an overlap
// passes time.max_overlap — before the contact can explode — with a message that
// names the particles, the overlap, the approach speed and a step that would work.
// Reference for that step: 1/20 of the elastic Hertz contact time at the approach
// speed, t_c = 2.868 (m*^2 / (R* Y*^2 v))^{1/5} (DESIGN.md §3).
#include <gtest/gtest.h>

#include <cmath>

#include "dem/engine/simulation.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

TEST(OverlapGuard, StopsBeforeTheContactExplodes) {
  const double r = 1e-3, rho = 2500, y = 1e7, nu = 0.3;
  Scene s = test::one_material_scene(y, nu, rho, 0.5);
  s.time.max_overlap = 0.1;
  Simulation sim(s, false);
  sim.particles().add(1, Vec3(-1.05 * r, 0, 0), Vec3(2.5, 0, 0), Vec3::Zero(), r, 0, rho);
  sim.particles().add(2, Vec3(1.05 * r, 0, 0), Vec3(-2.5, 0, 0), Vec3::Zero(), r, 0, rho);
  // At 5 m/s an elastic Hertz impact would reach ~40 % overlap; with dt = 1e-5 s the
  // overlap grows by up to 5e-5 m (5 % of r) per step.
  sim.set_dt(1e-5);
  sim.initialise();
  try {
    for (int k = 0; k < 100; ++k) sim.step();
    FAIL() << "expected the overlap guard to stop the run";
  } catch (const ParallelError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("particles 1 and 2 overlap by"), std::string::npos) << m;
    // The step it recommends is t_c/20 at the approach speed it reports.
    const auto at = m.find("approaching at ");
    ASSERT_NE(at, std::string::npos) << m;
    const double v = std::stod(m.substr(at + 15));
    EXPECT_GT(v, 0.5);
    EXPECT_LE(v, 5.0);
    const double m_star = rho * sphere_volume(r) / 2, r_star = r / 2;
    const double y_star = y / (2 * (1 - nu * nu));
    const double step = hertz_contact_time(y_star, r_star, m_star, v) / 20;
    const auto most = m.find("at most ");
    ASSERT_NE(most, std::string::npos) << m;
    EXPECT_NEAR(std::stod(m.substr(most + 8)) / step, 1.0, 1e-3) << m;  // 4 printed digits
  }
  // Stopped at the first step beyond 10 %: the overlap grew by at most one step's 5e-5 m.
  EXPECT_LT(sim.counters().max_overlap_ratio, 0.1 + 5e-5 / r + 1e-12);
}

}  // namespace
}  // namespace grainflow
