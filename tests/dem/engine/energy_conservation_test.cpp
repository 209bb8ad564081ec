// A frictionless, elastic box of particles conserves total energy.
//
// Reference: conservation of energy. E = sum (1/2) m v^2 + sum over touching pairs
// and particle-wall contacts of the Hertz potential (2/5) K d^{5/2}, K = (4/3) Y* sqrt(R*),
// computed here by brute force from positions (independent of the engine's lists).
// Tolerance 0.1 % over 1e5 steps (acceptance); velocity Verlet is symplectic, so the
// error oscillates with amplitude ~ (dt/t_c)^2 instead of drifting.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "dem/engine/simulation.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

double total_energy(const Simulation& sim, double y, double nu) {
  const Particles& p = sim.particles();
  // Walls are of the particles' material, so Y* has both terms for walls too.
  const double y_pair = y / (2 * (1 - nu * nu)), y_wall = y_pair;
  double e = sim.kinetic_energy_translational() + sim.kinetic_energy_rotational();
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      const double d = p.radius[i] + p.radius[j] - (p.x[i] - p.x[j]).norm();
      if (d > 0) {
        const double rs = p.radius[i] * p.radius[j] / (p.radius[i] + p.radius[j]);
        e += 0.4 * (4.0 / 3.0) * y_pair * std::sqrt(rs) * std::pow(d, 2.5);
      }
    }
    for (const Wall& w : sim.scene().walls) {
      const double d = p.radius[i] - (p.x[i] - w.plane.point).dot(w.plane.normal);
      if (d > 0) e += 0.4 * (4.0 / 3.0) * y_wall * std::sqrt(p.radius[i]) * std::pow(d, 2.5);
    }
  }
  return e;
}

TEST(EnergyConservation, FrictionlessElasticBox) {
  const double y = 1e7, nu = 0.3, rho = 2500, L = 0.02;
  Scene s = test::one_material_scene(y, nu, rho, 1.0);
  s.domain.lo = Vec3::Zero();
  s.domain.hi = Vec3(L, L, L);
  s.walls = {test::plane(Vec3::Zero(), Vec3::UnitX()), test::plane(Vec3(L, 0, 0), -Vec3::UnitX()),
             test::plane(Vec3::Zero(), Vec3::UnitY()), test::plane(Vec3(0, L, 0), -Vec3::UnitY()),
             test::plane(Vec3::Zero(), Vec3::UnitZ()), test::plane(Vec3(0, 0, L), -Vec3::UnitZ())};
  Simulation sim(s, false);
  // 125 polydisperse spheres on a jittered lattice with random velocities (~30 % solids).
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  GlobalId id = 1;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      for (int k = 0; k < 5; ++k) {
        const double r = 1.2e-3 * (1 + 0.2 * u(rng));
        const Vec3 x = (Vec3(i, j, k) + Vec3::Constant(0.5)) * (L / 5);
        sim.particles().add(id++, x, 0.5 * Vec3(u(rng), u(rng), u(rng)), Vec3::Zero(), r, 0, rho);
      }
  sim.set_dt(2e-6);  // ~ t_c / 50 at 1 m/s for these particles
  sim.initialise();
  const double e0 = total_energy(sim, y, nu);
  double worst = 0;
  for (int chunk = 0; chunk < 100; ++chunk) {
    for (int k = 0; k < 1000; ++k) sim.step();
    worst = std::max(worst, std::abs(total_energy(sim, y, nu) / e0 - 1));
  }
  EXPECT_EQ(sim.counters().steps, 100000);
  EXPECT_EQ(sim.particles().size(), 125u);
  EXPECT_GT(sim.counters().rebuilds, 10);  // the test really exercised list rebuilds
  std::printf("largest relative energy error over 1e5 steps: %.3e (%ld rebuilds)\n", worst,
              sim.counters().rebuilds);
  EXPECT_LT(worst, 1e-3);
}

}  // namespace
}  // namespace grainflow
