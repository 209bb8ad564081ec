// Stiff contacts near the time-step limit (issue 8): a dense frictional pile of
// glass-like spheres (Y = 60 GPa) settling under gravity in a walled box, at 0.2 and
// 0.3 of the Rayleigh time (the range DESIGN.md §3 calls acceptable).
//
// Invariants, checked every 50 steps:
// - positions, velocities and spins stay finite; no particle is lost;
// - total energy E = kinetic + rotational + gravity + elastic Hertz (2/5) K d^{5/2}
//   (brute force from positions, stress_support.hpp) never rises above its lowest
//   earlier value by more than the tolerance below. The system is dissipative
//   (e = 0.5, mu = 0.5), so a rise is a sign of integration error.
//
// Tolerance: 1e-4 of the energy released so far, E(0) - min E, plus 1e-12 |E(0)| for
// round-off in the sums. The brute-force E omits the energy held in the tangential
// springs (not recoverable from positions), and a Mindlin spring whose stiffness grows
// with the overlap can hand back slightly more than it took; measured here, E never
// rose between two checks at all. An unstable integrator multiplies the energy
// within a few steps, far beyond this band.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "tests/dem/stress/stress_support.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

constexpr double kY = 60e9, kNu = 0.25, kRho = 2500, kR = 1e-3;

// A jammed pile: 4 x 4 x 8 spheres of radius 1 mm on a simple cubic lattice whose
// pitch is 0.1 um short of a diameter, in a box that squeezes the outer layers by
// 0.05 um, so every one of the 3n - 2 (n = 128) lattice contacts and the 144 wall
// contacts is loaded from the first step (52 % solids). Random velocities of up to
// 0.1 m/s then rattle it; gravity loads the columns. Stress waves run through a
// stiff contact network: what the Rayleigh-time limit is about.
constexpr int kNx = 4, kNz = 8;
constexpr double kPitch = 2 * kR - 1e-7, kWallGap = 5e-8;

Scene glass_box() {
  Scene s = test::one_material_scene(kY, kNu, kRho, 0.5, 0.5);
  const double L = 2 * (kR - kWallGap) + (kNx - 1) * kPitch;
  s.domain.lo = Vec3::Zero();
  s.domain.hi = Vec3(L, L, 3 * L);
  s.contact.tangential = TangentialModel::history;
  s.gravity = Vec3(0, 0, -9.81);
  s.walls = {test::plane(Vec3::Zero(), Vec3::UnitX()), test::plane(Vec3(L, 0, 0), -Vec3::UnitX()),
             test::plane(Vec3::Zero(), Vec3::UnitY()), test::plane(Vec3(0, L, 0), -Vec3::UnitY()),
             test::plane(Vec3::Zero(), Vec3::UnitZ())};
  return s;
}

void fill(Simulation& sim) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  GlobalId id = 1;
  for (int k = 0; k < kNz; ++k)
    for (int j = 0; j < kNx; ++j)
      for (int i = 0; i < kNx; ++i) {
        const Vec3 x = Vec3::Constant(kR - kWallGap) + kPitch * Vec3(i, j, k);
        sim.particles().add(id++, x, 0.1 / std::sqrt(3.0) * Vec3(u(rng), u(rng), u(rng)),
                            Vec3::Zero(), kR, 0, kRho);
      }
}

class StiffContacts : public testing::TestWithParam<double> {};

TEST_P(StiffContacts, EnergyNeverGrowsInADensePile) {
  const double fraction = GetParam();
  Scene s = glass_box();
  s.time.step.reset();
  s.time.rayleigh_fraction = fraction;
  Simulation sim(s, false);
  fill(sim);
  sim.initialise();
  const std::size_t n = sim.particles().size();
  // Rayleigh time of the smallest sphere sets dt (time_step.hpp).
  EXPECT_NEAR(sim.dt() / (fraction * rayleigh_time(s.materials[0], kR)), 1.0, 1e-12);

  const double e0 = test::total_energy(test::gather_grains(sim.particles(), MPI_COMM_SELF), s);
  double lowest = e0, worst_rise = 0, worst_ratio = 0, most_overlap = 0;
  long most_contacts = 0;
  const long chunks = 200 * test::stress_scale();
  for (long c = 0; c < chunks; ++c) {
    for (int k = 0; k < 50; ++k) sim.step();
    ASSERT_TRUE(test::all_finite(sim.particles()))
        << "non-finite state at step " << sim.counters().steps;
    const auto g = test::gather_grains(sim.particles(), MPI_COMM_SELF);
    const double e = test::total_energy(g, s);
    const double rise = e - lowest, released = e0 - lowest;
    worst_rise = std::max(worst_rise, rise);
    if (released > 0) worst_ratio = std::max(worst_ratio, rise / released);
    ASSERT_LE(rise, 1e-4 * released + 1e-12 * std::abs(e0))
        << "energy rose at step " << sim.counters().steps << ": E = " << e << " J, lowest "
        << lowest << " J";
    lowest = std::min(lowest, e);
    most_contacts = std::max(most_contacts, sim.counters().contacts);
    most_overlap = std::max(most_overlap, sim.counters().max_overlap_ratio);
  }
  EXPECT_EQ(sim.particles().size(), n);
  EXPECT_EQ(sim.counters().removed, 0);
  EXPECT_GT(most_contacts, static_cast<long>(2 * n));  // a dense pile, not a gas
  EXPECT_LT(lowest, e0);                               // and it did dissipate
  std::printf(
      "dt = %.3f t_R = %.3e s, %ld steps: E0 = %.6e J, E_end = %.6e J, largest rise %.3e J "
      "(%.2e of the released energy), up to %ld contacts, largest overlap %.2e r\n",
      fraction, sim.dt(), sim.counters().steps, e0, lowest, worst_rise, worst_ratio, most_contacts,
      most_overlap);
}

INSTANTIATE_TEST_SUITE_P(RayleighFraction, StiffContacts, testing::Values(0.2, 0.3),
                         [](const testing::TestParamInfo<double>& i) {
                           return i.param < 0.25 ? std::string("Point2") : std::string("Point3");
                         });

}  // namespace
}  // namespace grainflow
