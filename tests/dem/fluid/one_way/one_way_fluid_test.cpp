// One-way fluid forces inside the DEM steps (FluidForces term on a Simulation).
//
// 1. Stability (issue 5): a 10 µm glass particle in water, dt = 100 × its Stokes response
//    time τ = ρ_p d²/(18 μ), starting at rest in a uniform flow. Reference: the exact
//    solution relaxes monotonically to u_f. Asserted: the speed never decreases (to 1e-14 u_f,
//    the round-off once it sits at u_f), never
//    exceeds u_f (no overshoot, to round-off 1e-12 u_f), equals u_f to 1e-9 after 20 steps,
//    and the cross-stream velocity stays zero.
// 2. Terminal settling (issue 5): a sphere in quiescent water under gravity (drag +
//    pressure gradient with hydrostatic pressure + viscous, model B). Reference: the
//    terminal velocity from the Schiller–Naumann balance K(u_t) u_t = (ρ_p − ρ_f) V g,
//    solved by bisection here. Tolerance 1 % (acceptance); the run resolves τ with 20
//    steps and lasts 12 τ, so the measured gap is far smaller (printed).
// 3. The same fall with Archimedes buoyancy and a pressure without hydrostatics, and with
//    virtual mass listed: the same terminal velocity (virtual mass changes only the
//    transient, which is slower by the added mass).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "dem/engine/simulation.hpp"
#include "dem/fluid/fluid_forces.hpp"
#include "dem/fluid/schiller_naumann.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

constexpr double kRhoP = 2500, kRhoF = 1000, kMu = 1e-3, kG = 9.81;

FluidSettings water(std::vector<FluidForce> forces) {
  FluidSettings f;
  f.field.density = kRhoF;
  f.field.viscosity = kMu;
  f.forces = std::move(forces);
  return f;
}

Scene scene_with(double dt, const Vec3& gravity) {
  Scene s = test::one_material_scene(5e6, 0.3, kRhoP, 0.5);
  s.domain.lo = Vec3::Constant(-10);
  s.domain.hi = Vec3::Constant(10);
  s.gravity = gravity;
  s.time.step = dt;
  return s;
}

double stokes_time(double d) { return kRhoP * d * d / (18 * kMu); }

TEST(OneWayFluid, ImplicitDragIsStableAtHundredResponseTimes) {
  const double d = 10e-6, dt = 100 * stokes_time(d);
  const Vec3 u(0.01, 0, 0);
  Scene s = scene_with(dt, Vec3::Zero());
  // A lone particle with nothing to hit, carried 2.7 radii per step at this dt: the travel
  // guard (time.max_step_travel) would stop it; this test is about the drag's stability.
  s.time.max_step_travel = 0;
  FluidSettings f = water({FluidForce::drag, FluidForce::pressure_gradient, FluidForce::viscous});
  f.field.velocity = u;
  Simulation sim(s, false);
  sim.particles().add(1, Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), d / 2, 0, kRhoP);
  sim.add_force_term(make_fluid_forces(f, s.gravity));
  sim.initialise();
  double previous = 0;
  for (int step = 1; step <= 20; ++step) {
    sim.step();
    const Vec3 v = sim.particles().v[0];
    if (step <= 3) std::printf("step %d: v_x/u_f = %.15f\n", step, v.x() / u.x());
    EXPECT_GE(v.x(), previous - 1e-14 * u.x()) << "step " << step;  // once at u_f: 1-ulp jitter
    EXPECT_LE(v.x(), u.x() * (1 + 1e-12)) << "overshoot at step " << step;
    EXPECT_EQ(v.y(), 0);
    EXPECT_EQ(v.z(), 0);
    previous = v.x();
  }
  EXPECT_NEAR(previous / u.x(), 1, 1e-9);
}

// Terminal velocity from K_SN(u) u = (ρ_p − ρ_f) V g by bisection (K u increases with u).
double schiller_naumann_terminal(double d) {
  const double weight = (kRhoP - kRhoF) * std::numbers::pi / 6 * d * d * d * kG;
  double lo = 0, hi = 10;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (schiller_naumann({d, mid, 1, kRhoF, kMu}) * mid < weight ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double settle(double d, const FluidSettings& f, const Vec3& gravity) {
  const double u_guess = schiller_naumann_terminal(d);
  const double re = kRhoF * d * u_guess / kMu;
  const double tau = stokes_time(d) / (1 + 0.15 * std::pow(re, 0.687));
  Scene s = scene_with(tau / 20, gravity);
  Simulation sim(s, false);
  sim.particles().add(1, Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), d / 2, 0, kRhoP);
  sim.add_force_term(make_fluid_forces(f, s.gravity));
  sim.advance_to(12 * tau);
  return -sim.particles().v[0].z();
}

TEST(OneWayFluid, TerminalSettlingMatchesSchillerNaumannBalance) {
  const Vec3 g(0, 0, -kG);
  const FluidSettings f =
      water({FluidForce::drag, FluidForce::pressure_gradient, FluidForce::viscous});
  for (double d : {50e-6, 0.6e-3}) {  // Re_t ≈ 0.1 (Stokes regime) and ≈ 52
    const double ut = schiller_naumann_terminal(d);
    const double v = settle(d, f, g);
    std::printf("d = %g m: Re_t = %.3g, u_t = %.6g m/s, DEM %.6g m/s, rel. gap %.2e\n", d,
                kRhoF * d * ut / kMu, ut, v, std::abs(v / ut - 1));
    EXPECT_NEAR(v / ut, 1, 0.01) << "d = " << d;
  }
}

TEST(OneWayFluid, ArchimedesRouteAndVirtualMassGiveSameTerminalVelocity) {
  const Vec3 g(0, 0, -kG);
  const double d = 0.6e-3, ut = schiller_naumann_terminal(d);
  FluidSettings archimedes = water(
      {FluidForce::drag, FluidForce::pressure_gradient, FluidForce::viscous, FluidForce::buoyancy});
  archimedes.field.hydrostatic_pressure = false;
  EXPECT_NEAR(settle(d, archimedes, g) / ut, 1, 0.01);
  FluidSettings added = water({FluidForce::drag, FluidForce::pressure_gradient,
                               FluidForce::viscous, FluidForce::virtual_mass});
  // The added mass (0.5 ρ_f V) slows the approach by (m + m_a)/m = 1.2: 12 τ still
  // reaches the plateau well inside 1 %.
  EXPECT_NEAR(settle(d, added, g) / ut, 1, 0.01);
}

// 4. Void fraction computed from the particles: a cubic lattice of spheres, one per
//    grid cell, in a periodic box with no contacts; every cell then holds exactly
//    eps = 1 - V_p / V_cell. Reference: the same fall with that eps given as a number;
//    the two runs must agree to round-off (1e-12).
TEST(OneWayFluid, ComputedVoidFractionEqualsTheGivenOne) {
  const double d = 0.2e-3, cell = 0.5e-3, L = 8 * cell;
  const double eps = 1 - sphere_volume(d / 2) / (cell * cell * cell);
  auto run = [&](bool computed) {
    Scene s = scene_with(stokes_time(d) / 20, Vec3(0, 0, -kG));
    s.domain.lo = Vec3::Zero();
    s.domain.hi = Vec3::Constant(L);
    s.domain.periodic = {true, true, true};
    FluidSettings f = water({FluidForce::drag, FluidForce::pressure_gradient, FluidForce::viscous});
    f.drag_law = "di_felice";
    if (computed)
      f.computed_void_fraction = VoidFractionGridSettings{cell, 0.2};
    else
      f.field.void_fraction = eps;
    Simulation sim(s, false);
    GlobalId id = 1;
    for (int i = 0; i < 8; ++i)
      for (int j = 0; j < 8; ++j)
        for (int k = 0; k < 8; ++k)
          sim.particles().add(id++, (Vec3(i, j, k) + Vec3::Constant(0.5)) * cell, Vec3::Zero(),
                              Vec3::Zero(), d / 2, 0, kRhoP);
    sim.add_force_term(make_fluid_forces(f, s.gravity, s.domain, MPI_COMM_WORLD));
    sim.advance_to(5 * stokes_time(d));
    return -sim.particles().v[0].z();
  };
  const double given = run(false), computed = run(true);
  std::printf("settling with eps = %.4f: given %.9g m/s, computed %.9g m/s\n", eps, given, computed);
  EXPECT_GT(given, 0);
  EXPECT_NEAR(computed / given, 1, 1e-12);
}

}  // namespace
}  // namespace grainflow
