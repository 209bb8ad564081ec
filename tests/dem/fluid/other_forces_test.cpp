// Non-drag fluid forces against their closed forms (references in each test; the
// tolerances are round-off unless stated).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "dem/fluid/magnus_lift.hpp"
#include "dem/fluid/rotational_drag.hpp"
#include "dem/fluid/saffman_mei_lift.hpp"
#include "dem/fluid/virtual_mass.hpp"
#include "dem/fluid/volume_forces.hpp"

namespace grainflow {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRho = 1000, kMu = 1e-3, kD = 1e-3;
const double kVolume = kPi * kD * kD * kD / 6;
const Vec3 kGravity(0, 0, -9.81);

// Buoyancy, issue 5: a particle in a hydrostatic fluid feels exactly ρ_f V_p |g| upward —
// from the pressure gradient when p includes hydrostatics (∇p = ρ_f g, model B), and from
// the Archimedes term when it does not.
TEST(VolumeForces, HydrostaticBuoyancyBothRoutes) {
  const Vec3 up(0, 0, kRho * kVolume * 9.81);
  const Vec3 from_pressure = pressure_gradient_force(kVolume, kRho * kGravity);
  const Vec3 from_archimedes = archimedes_buoyancy(kRho, kVolume, kGravity);
  EXPECT_NEAR((from_pressure - up).norm(), 0, 1e-15 * up.norm());
  EXPECT_NEAR((from_archimedes - up).norm(), 0, 1e-15 * up.norm());
  EXPECT_EQ(viscous_force(2.0, Vec3(1, -2, 3)), Vec3(2, -4, 6));
}

// Virtual mass: the closure must give the added-mass equation's acceleration
// a = (F + K(u − v) + m_a Du/Dt)/(m + m_a) when the integrator applies m a = F + F_vm +
// s K (u − v); and F_vm equals C_vm ρ_f V (Du/Dt − a) at that a.
TEST(VirtualMass, ClosureGivesAddedMassAcceleration) {
  const double m = 2.5e-6, ma = kSphereVirtualMassCoefficient * kRho * kVolume, k = 3e-5;
  const Vec3 f(1e-5, -2e-5, -3e-5), du(0.3, 0, -0.1), u(0.1, 0.2, 0), v(0, 0.1, -0.2);
  double s = 0;
  const Vec3 fvm = virtual_mass_closure(ma, m, f, du, s);
  const Vec3 a = (f + fvm + s * k * (u - v)) / m;
  const Vec3 expected = (f + k * (u - v) + ma * du) / (m + ma);
  EXPECT_NEAR((a - expected).norm(), 0, 1e-12 * expected.norm());
  // The explicit part is the virtual-mass force at the acceleration without drag.
  const Vec3 a_nodrag = (f + fvm) / m;
  EXPECT_NEAR((fvm - virtual_mass_force(0.5, kRho, kVolume, du, a_nodrag)).norm(), 0,
              1e-12 * fvm.norm());
}

// Saffman–Mei: lagging particle (fluid faster) in u = (G z, 0, 0) is lifted towards +z,
// the faster side; magnitude by hand from Mei's correction at Re_p = 1 and Re_p = 50.
TEST(SaffmanMei, DirectionAndMagnitude) {
  const double g = 100;                  // shear rate [1/s]
  const Vec3 vorticity(0, g, 0);         // ∇×(G z x̂) = G ŷ
  for (double re_p : {1.0, 50.0}) {
    const double u = re_p * kMu / (kRho * kD);
    const Vec3 slip(u, 0, 0);
    const Vec3 f = saffman_mei_lift(kD, kRho, kMu, slip, vorticity);
    const double re_s = kRho * kD * kD * g / kMu, beta = re_s / (2 * re_p);
    const double corr = re_p <= 40 ? (1 - 0.3314 * std::sqrt(beta)) * std::exp(-0.1 * re_p) +
                                         0.3314 * std::sqrt(beta)
                                   : 0.0524 * std::sqrt(beta * re_p);
    const double magnitude = 1.615 * kD * kD * std::sqrt(kRho * kMu * g) * u * corr;
    EXPECT_GT(f.z(), 0);  // x̂ × ŷ = ẑ
    EXPECT_NEAR(f.z() / magnitude, 1, 1e-12) << re_p;
    EXPECT_EQ(f.x(), 0);
  }
  EXPECT_EQ(saffman_mei_lift(kD, kRho, kMu, Vec3(1, 0, 0), Vec3::Zero()), Vec3::Zero());
}

// Magnus: at Re_p, Re_r → 0 it tends to Rubinow & Keller's π a³ ρ_f Ω × (u − v); at
// Re_p = 10, Re_r = 5 it matches the Oesterlé–Bui Dinh coefficient by hand.
TEST(Magnus, RubinowKellerLimitAndCoefficient) {
  const double a = kD / 2;
  {
    const Vec3 spin(0, 0, 1e-3), slip(1e-9, 0, 0);
    const Vec3 f = magnus_lift(kD, kRho, kMu, slip, spin);
    const Vec3 rk = kPi * a * a * a * kRho * spin.cross(slip);
    EXPECT_NEAR((f - rk).norm() / rk.norm(), 0, 1e-3);  // exp(−0.057 Re_r^0.4 Re_p^0.3) ≈ 1 − 1e-4
  }
  const double re_p = 10, re_r = 5;
  const Vec3 slip(re_p * kMu / (kRho * kD), 0, 0), spin(0, 0, re_r * kMu / (kRho * kD * kD));
  const double clr = 0.45 + (re_r / re_p - 0.45) * std::exp(-0.05684 * std::pow(re_r, 0.4) *
                                                            std::pow(re_p, 0.3));
  const Vec3 expected = kPi / 8 * std::pow(kD, 3) * kRho * (re_p / re_r) * clr * spin.cross(slip);
  EXPECT_NEAR((magnus_lift(kD, kRho, kMu, slip, spin) - expected).norm() / expected.norm(), 0,
              1e-12);
}

// Rotational drag: the Stokes torque 8πμa³Ω for Re_r <= 32; Dennis et al. above; the
// branches meet within 0.2 % at Re_r = 32 (6.2832 vs 6.2929 for C_R).
TEST(RotationalDrag, StokesAndDennis) {
  const double a = kD / 2;
  const Vec3 slow(0, 0, 10 * kMu / (kRho * kD * kD));  // Re_r = 10
  const Vec3 t = rotational_drag_torque(kD, kRho, kMu, slow);
  EXPECT_NEAR((t - 8 * kPi * kMu * a * a * a * slow).norm() / t.norm(), 0, 1e-14);
  const double re_r = 200;
  const Vec3 fast(re_r * kMu / (kRho * kD * kD), 0, 0);
  const double c_r = 12.9 / std::sqrt(re_r) + 128.4 / re_r;
  const Vec3 expected = 0.5 * kRho * std::pow(a, 5) * c_r * fast.norm() * fast;
  EXPECT_NEAR((rotational_drag_torque(kD, kRho, kMu, fast) - expected).norm() / expected.norm(), 0,
              1e-14);
  const double w32 = 32 * kMu / (kRho * kD * kD);
  const double below = rotational_drag_torque(kD, kRho, kMu, Vec3(w32, 0, 0)).x();
  const double above = rotational_drag_torque(kD, kRho, kMu, Vec3(w32 * (1 + 1e-12), 0, 0)).x();
  EXPECT_NEAR(above / below, 1, 2e-3);
}

}  // namespace
}  // namespace grainflow
