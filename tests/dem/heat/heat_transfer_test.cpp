// Heat transfer in the DEM (docs/models/heat-transfer.md), against independent references:
//  - lumped cooling of one sphere in a prescribed gas: T_f + (T_0 - T_f) exp(-t/tau),
//    tau = rho c d / (6 h), h = Nu k_f / d from Ranz & Marshall (1952), within 0.5 %;
//  - steady conduction along a chain of spheres between a hot and a cold wall: the heat flow
//    equals (T_hot - T_cold) over the closed-form series resistance sum 1/(2 k* a) of the
//    contacts (Batchelor & O'Brien 1977), a = sqrt(R* delta) from the measured overlaps,
//    within 0.5 %;
//  - two equal spheres exchanging heat between adiabatic walls conserve sum m c T to
//    round-off;
//  - a restart from a checkpoint continues the temperatures bit for bit;
//  - a material heat source: T0 + q t / c alone, T_f + q m / (h A) with convection;
//  - a fixed-flux wall: q'' pi a^2 at Hertz's static overlap, and a chain from a flux wall to
//    a fixed-temperature wall in the steady state of the series resistances;
//  - Gunn's (1978) convection in a bed of uniform void fraction: the lumped exponential;
//  - the parser refuses what is not built and thermal keys without `heat:`.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>

#include "dem/engine/simulation.hpp"
#include "dem/fluid/fluid_forces.hpp"
#include "dem/heat/heat_laws.hpp"
#include "dem/scene/scene_parser.hpp"

namespace grainflow {
namespace {

constexpr double kPi = std::numbers::pi;

// Schiller & Naumann's terminal velocity of a sphere (Re < 1000), by bisection on
// (pi/8) C_D rho_f d^2 u^2 = (rho_p - rho_f) g pi d^3 / 6.
double terminal_velocity(double d, double rho_p, double rho_f, double mu, double g) {
  const double weight = (rho_p - rho_f) * g * kPi * d * d * d / 6;
  double lo = 0, hi = 100;
  for (int k = 0; k < 200; ++k) {
    const double u = 0.5 * (lo + hi), re = rho_f * d * u / mu;
    const double drag = kPi / 8 * 24 / re * (1 + 0.15 * std::pow(re, 0.687)) * rho_f * d * d * u * u;
    (drag < weight ? lo : hi) = u;
  }
  return 0.5 * (lo + hi);
}

// A glass bead (d = 1 mm) in air rising at its terminal velocity: the bead stays at rest at a
// constant slip, so h is constant and the cooling exponential.
TEST(HeatTransfer, LumpedCoolingMatchesRanzMarshall) {
  const double d = 1e-3, rho = 2500, c = 840, rho_f = 1.2, mu = 1.8e-5, cf = 1005, kf = 0.026;
  const double t0 = 600, tf = 300, g = 9.81;
  const double ut = terminal_velocity(d, rho, rho_f, mu, g);
  const std::string scene = R"(domain: {min: [-0.1, -0.1, -0.1], max: [0.1, 0.1, 0.1]}
gravity: [0, 0, -9.81]
time: {step: 5e-4, end: 3}
heat: {}
materials:
  - {name: glass, density: 2500, heat_capacity: 840, conductivity: 1}
insert:
  - {type: fill, region: {box: {min: [-0.01, -0.01, -0.01], max: [0.01, 0.01, 0.01]}},
     count: 1, material: glass, radius: {distribution: constant, value: 5e-4}, temperature: 600}
fluid:
  density: 1.2
  viscosity: 1.8e-5
  velocity: [0, 0, )" + std::to_string(ut) + R"(]
  drag: schiller_naumann
  model: B
  forces: [drag, pressure_gradient, viscous]
  temperature: 300
  heat_capacity: 1005
  conductivity: 0.026
  convection: ranz_marshall
)";
  const Scene s = parse_scene(scene, "cooling.yaml");
  Simulation sim(s);
  sim.add_force_term(make_fluid_forces(*s.fluid, s.gravity, s.domain, MPI_COMM_WORLD));
  sim.initialise();
  // Reference: Re at the slip u_t, Nu = 2 + 0.6 Re^1/2 Pr^1/3, tau = rho c d / (6 h).
  const double re = rho_f * d * ut / mu, pr = cf * mu / kf;
  const double h = (2 + 0.6 * std::sqrt(re) * std::cbrt(pr)) * kf / d;
  const double tau = rho * c * d / (6 * h);
  std::printf("u_t = %.4f m/s, Re = %.2f, Pr = %.3f, h = %.2f W/m^2/K, tau = %.4f s\n", ut, re, pr,
              h, tau);
  double worst = 0, fastest = 0;
  for (int k = 1; k <= 6; ++k) {
    sim.advance_to(0.5 * k);
    const double t = sim.time();
    const double expected = tf + (t0 - tf) * std::exp(-t / tau);
    const double got = sim.particles().temperature[0];
    // Relative to the temperature difference that is left (the stricter measure).
    worst = std::max(worst, std::abs((got - expected) / (expected - tf)));
    fastest = std::max(fastest, sim.particles().v[0].norm());
  }
  std::printf("largest error of T - T_f over 3 s (%.2f tau): %.3e; largest speed %.2e m/s\n",
              3 / tau, worst, fastest);
  EXPECT_LT(fastest, 1e-3 * ut);  // held at rest by the balance: the slip is u_t
  EXPECT_LT(worst, 5e-3);         // acceptance 0.5 %; implicit Euler lags by dt / (2 tau)
}

// Equal spheres of radius r in a row along x between walls at x = 0 and x = L, each contact
// first overlapping by delta0; gravity off, restitution 0.1: the row settles in a few contact
// times and stays at rest.
std::string chain_scene(int spheres, double r, double delta0, const std::string& left,
                        const std::string& right, const std::string& parallel = "") {
  const double length = spheres * 2 * r - (spheres + 1) * delta0;
  std::string s = "domain: {min: [0, -0.004, -0.004], max: [" + std::to_string(length) +
                  ", 0.004, 0.004]}\n"
                  "time: {step: 1e-6, end: 1}\n"
                  "heat: {}\n"
                  "materials:\n"
                  // c is small so that the temperatures settle in few steps: the steady state
                  // does not depend on it.
                  "  - {name: glass, youngs_modulus: 1e7, poisson_ratio: 0.3, density: 2500,\n"
                  "     heat_capacity: 0.01, conductivity: 1.2}\n"
                  "  - {name: steel, youngs_modulus: 2e8, poisson_ratio: 0.3, density: 7800,\n"
                  "     heat_capacity: 500, conductivity: 16}\n"
                  "interaction_defaults: {restitution: 0.1, friction: 0.3}\n"
                  "contact: {normal: hertz}\n"
                  "walls:\n"
                  "  - {type: plane, name: left, point: [0, 0, 0], normal: [1, 0, 0], material: "
                  "steel" + left + "}\n"
                  "  - {type: plane, name: right, point: [" + std::to_string(length) +
                  ", 0, 0], normal: [-1, 0, 0], material: steel" + right + "}\n" + parallel;
  return s;
}

void add_chain(Simulation& sim, int spheres, double r, double delta0,
               const std::vector<double>& temperatures) {
  for (int k = 0; k < spheres; ++k) {
    const double x = r - delta0 + k * (2 * r - delta0);
    sim.particles().add(k + 1, Vec3(x, 0, 0), Vec3::Zero(), Vec3::Zero(), r, 0, 2500);
    sim.particles().temperature.back() = temperatures[k];
  }
  sim.next_id() = spheres + 1;
}

TEST(HeatTransfer, SteadyChainMatchesSeriesResistances) {
  const int n = 3;
  const double r = 1e-3, delta0 = 5e-7, k_glass = 1.2, k_steel = 16;
  const double hot = 400, cold = 300;
  const Scene s = parse_scene(chain_scene(n, r, delta0, ", temperature: 400", ", temperature: 300"),
                              "chain.yaml");
  Simulation sim(s, false);
  add_chain(sim, n, r, delta0, {300, 300, 300});
  sim.initialise();
  sim.advance_to(0.05);
  // The closed form from the positions: each contact's resistance 1 / (2 k* a).
  const Particles& p = sim.particles();
  ASSERT_EQ(p.size(), static_cast<std::size_t>(n));
  std::vector<double> x(n);
  for (std::size_t i = 0; i < p.size(); ++i) x[p.id[i] - 1] = p.x[i][0];
  const double length = s.walls[1].plane.point[0];
  const double k_wall = 2 * k_glass * k_steel / (k_glass + k_steel);
  double resistance = 1 / (2 * k_wall * std::sqrt(r * (r - x[0])));
  resistance += 1 / (2 * k_wall * std::sqrt(r * (r - (length - x[n - 1]))));
  for (int k = 0; k + 1 < n; ++k)
    resistance += 1 / (2 * k_glass * std::sqrt(0.5 * r * (2 * r - (x[k + 1] - x[k]))));
  const double expected = (hot - cold) / resistance;
  const std::vector<double>& q = sim.heat()->wall_heat();
  std::printf("overlaps: wall %.4e m, pair %.4e m; heat flow %.6e W, closed form %.6e W\n",
              r - x[0], 2 * r - (x[1] - x[0]), q[0], expected);
  EXPECT_NEAR(q[0] / expected, 1, 5e-3);   // into the chain through the hot wall
  EXPECT_NEAR(-q[1] / expected, 1, 5e-3);  // out through the cold wall
  EXPECT_LT(p.v[0].norm() + p.v[1].norm() + p.v[2].norm(), 1e-6);  // at rest
}

TEST(HeatTransfer, TwoSpheresConserveEnergyToRoundOff) {
  const double r = 1e-3, delta0 = 5e-7;
  const Scene s = parse_scene(chain_scene(2, r, delta0, "", ""), "pair.yaml");
  Simulation sim(s, false);
  add_chain(sim, 2, r, delta0, {300, 400});
  sim.initialise();
  const auto energy = [&] { return sim.heat()->thermal_energy(sim.particles()); };
  const double e0 = energy();
  double worst = 0;
  for (int k = 1; k <= 20; ++k) {
    sim.advance_to(1e-3 * k);
    worst = std::max(worst, std::abs(energy() / e0 - 1));
  }
  const Particles& p = sim.particles();
  std::printf("after %ld steps: T = %.9f, %.9f K; largest relative energy change %.2e\n",
              sim.counters().steps, p.temperature[0], p.temperature[1], worst);
  EXPECT_LT(std::abs(p.temperature[0] - p.temperature[1]), 1e-3);  // equilibrated
  EXPECT_NEAR(0.5 * (p.temperature[0] + p.temperature[1]), 350, 1e-9);
  EXPECT_LT(worst, 1e-14);  // round-off: 20 000 steps of ~1e-16 each, mostly cancelling
}

// Reference: the uninterrupted run (Simulation::write_checkpoint rebuilds the lists as a
// restart from the file does, so both continue from the same state, bit for bit).
TEST(HeatTransfer, RestartContinuesTemperaturesExactly) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "heat_transfer_test";
  fs::create_directories(dir);
  const std::string file = (dir / "checkpoint.h5").string();
  const double r = 1e-3, delta0 = 5e-7;
  const Scene s = parse_scene(chain_scene(3, r, delta0, ", temperature: 400", ", heat_flux: -5e3"),
                              "restart.yaml");
  Simulation whole(s, false);
  add_chain(whole, 3, r, delta0, {300, 320, 340});
  whole.advance_to(2e-3);
  whole.write_checkpoint(file);
  whole.advance_to(4e-3);
  Simulation resumed(s, false);
  resumed.restore(read_checkpoint(file));
  resumed.advance_to(4e-3);
  ASSERT_EQ(whole.counters().steps, resumed.counters().steps);
  const Particles &a = whole.particles(), &b = resumed.particles();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.id[i], b.id[i]);
    EXPECT_EQ(a.temperature[i], b.temperature[i]) << "particle " << a.id[i];
    EXPECT_EQ(a.x[i], b.x[i]) << "particle " << a.id[i];
  }
  EXPECT_NE(a.temperature[0], 300);  // heat flowed
}

// One sphere alone, away from walls, gravity off: m c dT/dt = m q, so T(t) = T0 + q t / c.
// Explicit Euler integrates a constant rate exactly; the tolerance is the round-off of the
// 1000 additions to T and to the clock (a few times 1000 x 2^-53 of T).
TEST(HeatTransfer, HeatSourceRaisesAnIsolatedSphereLinearly) {
  const double q = 1e3, c = 500, t0 = 300;
  const Scene s = parse_scene(R"(domain: {min: [-0.01, -0.01, -0.01], max: [0.01, 0.01, 0.01]}
time: {step: 1e-3, end: 1}
heat: {}
materials:
  - {name: glass, youngs_modulus: 1e7, poisson_ratio: 0.3, density: 2500, heat_capacity: 500,
     conductivity: 1, heat_source: 1000}
interaction_defaults: {restitution: 0.5, friction: 0.3}
contact: {normal: hertz}
)",
                              "source.yaml");
  Simulation sim(s, false);
  sim.particles().add(1, Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), 5e-4, 0, 2500);
  sim.particles().temperature.back() = t0;
  sim.next_id() = 2;
  sim.initialise();
  sim.advance_to(1.0);
  ASSERT_EQ(sim.counters().steps, 1000);
  const double expected = t0 + q * sim.time() / c;
  std::printf("T(1 s) = %.15f K, T0 + q t / c = %.15f K\n", sim.particles().temperature[0],
              expected);
  EXPECT_NEAR(sim.particles().temperature[0], expected, 4 * 1000 * 0x1p-53 * expected);
  EXPECT_DOUBLE_EQ(sim.heat()->source_heat(), q * sim.particles().mass[0]);
}

// The same sphere at rest in still water at T_f (Re = 0: Ranz-Marshall Nu = 2, h A = 2 k_f pi d)
// with its source on: T -> T_inf = T_f + q m / (h A), approached as
// T_inf + (T0 - T_inf) exp(-t / tau), tau = m c / (h A). Tolerances: 0.5 % of T - T_inf over
// 3 tau (implicit Euler lags by dt / (2 tau) = 5e-4 per tau), and the fixed point of the
// implicit step is T_inf exactly, reached to 1e-9 K after 40 tau.
TEST(HeatTransfer, HeatSourceWithConvectionReachesItsSteadyExcess) {
  const double d = 1e-3, rho = 2500, c = 840, q = 1e4, kf = 0.6, t0 = 300, tf = 290;
  const double m = rho * kPi * d * d * d / 6, ha = 2 * kf * kPi * d;
  const double tau = m * c / ha, t_inf = tf + q * m / ha;
  const double dt = tau / 1000;
  const std::string yaml = R"(domain: {min: [-0.01, -0.01, -0.01], max: [0.01, 0.01, 0.01]}
time: {step: )" + std::to_string(dt) +
                           R"(, end: 100}
heat: {}
materials:
  - {name: glass, youngs_modulus: 1e7, poisson_ratio: 0.3, density: 2500, heat_capacity: 840,
     conductivity: 1, heat_source: 1e4}
interaction_defaults: {restitution: 0.5, friction: 0.3}
contact: {normal: hertz}
fluid:
  density: 1000
  viscosity: 1e-3
  drag: schiller_naumann
  model: B
  forces: [drag, pressure_gradient, viscous]
  temperature: 290
  heat_capacity: 4180
  conductivity: 0.6
)";
  Scene s = parse_scene(yaml, "source_convection.yaml");
  s.time.step = dt;  // to the last bit
  Simulation sim(s, false);
  sim.add_force_term(make_fluid_forces(*s.fluid, s.gravity, s.domain, MPI_COMM_WORLD));
  sim.particles().add(1, Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), 0.5 * d, 0, rho);
  sim.particles().temperature.back() = t0;
  sim.next_id() = 2;
  sim.set_dt(dt);
  sim.initialise();
  double worst = 0;
  for (int k = 1; k <= 6; ++k) {
    sim.advance_to(0.5 * k * tau);
    const double expected = t_inf + (t0 - t_inf) * std::exp(-sim.time() / tau);
    worst =
        std::max(worst, std::abs((sim.particles().temperature[0] - expected) / (expected - t_inf)));
  }
  sim.advance_to(40 * tau);
  std::printf(
      "tau = %.4f s, T_inf = %.6f K; largest error of T - T_inf over 3 tau %.3e; "
      "T(40 tau) = %.9f K\n",
      tau, t_inf, worst, sim.particles().temperature[0]);
  EXPECT_LT(worst, 5e-3);
  EXPECT_NEAR(sim.particles().temperature[0], t_inf, 1e-9);
  EXPECT_EQ(sim.particles().v[0].norm(), 0.0);  // at rest in still fluid, gravity off
}

// A sphere resting on a floor that feeds a fixed heat flux density q'' [W/m^2] through its
// contact area pi a^2 (docs/models/heat-transfer.md, "Walls"). It is placed at Hertz's static
// overlap, m g = (4/3) Y* sqrt(r) delta^(3/2) with 1/Y* = 2 (1 - nu^2) / Y (sphere and floor
// of one material), a^2 = r delta, and stays there; no other exchange (adiabatic elsewhere, no
// fluid): T(t) = T0 + q'' pi r delta t / (m c). Tolerances: 1e-9 relative for the rate (the
// sphere's drift from the computed equilibrium, round-off, changes delta at that level); for T
// the round-off of adding the same small increment to T = 300 K in each of the N steps, which
// rounds the same way every time: N ulp(T) / 2.
TEST(HeatTransfer, FixedFluxWallFeedsItsFluxThroughTheContactArea) {
  const double r = 1e-3, rho = 2500, c = 800, y = 1e7, nu = 0.3, g = 9.81, flux = 2e5, t0 = 300;
  const double m = rho * 4.0 / 3.0 * kPi * r * r * r;
  const double y_star = y / (2 * (1 - nu * nu));
  const double delta = std::pow(3 * m * g / (4 * y_star * std::sqrt(r)), 2.0 / 3.0);
  const double rate = flux * kPi * r * delta;
  const Scene s = parse_scene(R"(domain: {min: [-0.01, -0.01, 0], max: [0.01, 0.01, 0.01]}
gravity: [0, 0, -9.81]
time: {step: 1e-6, end: 1}
heat: {}
materials:
  - {name: glass, youngs_modulus: 1e7, poisson_ratio: 0.3, density: 2500, heat_capacity: 800,
     conductivity: 1}
interaction_defaults: {restitution: 0.5, friction: 0.3}
contact: {normal: hertz}
walls:
  - {type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass,
     heat_flux: 2e5}
)",
                              "flux.yaml");
  Simulation sim(s, false);
  sim.particles().add(1, Vec3(0, 0, r - delta), Vec3::Zero(), Vec3::Zero(), r, 0, rho);
  sim.particles().temperature.back() = t0;
  sim.next_id() = 2;
  sim.initialise();
  sim.advance_to(0.02);
  const double expected = t0 + rate * sim.time() / (m * c);
  const Particles& p = sim.particles();
  std::printf(
      "delta = %.6e m (Hertz), %.6e m (run); wall heat %.9e W, q'' pi r delta %.9e W; "
      "T = %.12f K, closed form %.12f K\n",
      delta, r - p.x[0][2], sim.heat()->wall_heat()[0], rate, p.temperature[0], expected);
  EXPECT_NEAR(sim.heat()->wall_heat()[0], rate, 1e-9 * rate);
  const double steps = static_cast<double>(sim.counters().steps);
  EXPECT_NEAR(p.temperature[0], expected, steps * 0x1p-53 * expected);
}

// The chain of SteadyChainMatchesSeriesResistances between a wall feeding q'' and a wall at
// 300 K: in the steady state all that enters, Q = q'' pi r delta_in, leaves through the cold
// wall, and the sphere at the flux wall is Q sum 1/(2 k* a) above 300 K (the contacts
// between it and the cold wall in series; a from the measured overlaps). Tolerance 0.5 %.
TEST(HeatTransfer, SteadyChainFromAFixedFluxToAFixedTemperature) {
  const int n = 3;
  const double r = 1e-3, delta0 = 5e-7, k_glass = 1.2, k_steel = 16, flux = 1e6, cold = 300;
  const Scene s = parse_scene(chain_scene(n, r, delta0, ", heat_flux: 1e6", ", temperature: 300"),
                              "flux_chain.yaml");
  Simulation sim(s, false);
  add_chain(sim, n, r, delta0, {300, 300, 300});
  sim.initialise();
  sim.advance_to(0.08);
  const Particles& p = sim.particles();
  std::vector<double> x(n), t(n);
  for (std::size_t i = 0; i < p.size(); ++i) {
    x[p.id[i] - 1] = p.x[i][0];
    t[p.id[i] - 1] = p.temperature[i];
  }
  const double length = s.walls[1].plane.point[0];
  const double k_wall = 2 * k_glass * k_steel / (k_glass + k_steel);
  const double q_in = flux * kPi * r * (r - x[0]);
  double resistance = 1 / (2 * k_wall * std::sqrt(r * (r - (length - x[n - 1]))));
  for (int k = 0; k + 1 < n; ++k)
    resistance += 1 / (2 * k_glass * std::sqrt(0.5 * r * (2 * r - (x[k + 1] - x[k]))));
  const std::vector<double>& q = sim.heat()->wall_heat();
  std::printf("in %.6e W (q'' pi a^2 %.6e W), out %.6e W; T1 - T_w = %.6f K, Q R = %.6f K\n", q[0],
              q_in, -q[1], t[0] - cold, q_in * resistance);
  EXPECT_NEAR(q[0] / q_in, 1, 1e-9);   // the flux wall's definition, at the run's overlap
  EXPECT_NEAR(-q[1] / q_in, 1, 5e-3);  // steady: all of it leaves through the cold wall
  EXPECT_NEAR((t[0] - cold) / (q_in * resistance), 1, 5e-3);
}

// Gunn (1978, eq. 21) in a run: a sphere in air flowing through a bed of uniform void
// fraction eps = 0.5 at u = 1 m/s. The sphere is so dense (1e9 kg/m^3) that drag changes its
// slip by < 1e-5 over the run, and its heat capacity so small that tau = rho c d / (6 h) is
// 0.1 s. Reference: Nu written out here from Gunn's paper, Re = eps rho_f d |u| / mu (his
// superficial Reynolds number), h = Nu k_f / d; T_f + (T0 - T_f) exp(-t / tau) within 0.5 % of
// T - T_f over 3 tau (dt = tau / 2000: the implicit step's lag is 2.5e-4 per tau).
TEST(HeatTransfer, GunnConvectionInABedMatchesTheLumpedExponential) {
  const double d = 1e-3, rho = 1e9, eps = 0.5, u = 1, rho_f = 1.2, mu = 1.8e-5, cf = 1005,
               kf = 0.026, t0 = 400, tf = 300;
  const double re = eps * rho_f * d * u / mu, pr = cf * mu / kf;
  const double nu_gunn =
      (7 - 10 * eps + 5 * eps * eps) * (1 + 0.7 * std::pow(re, 0.2) * std::pow(pr, 1.0 / 3.0)) +
      (1.33 - 2.4 * eps + 1.2 * eps * eps) * std::pow(re, 0.7) * std::pow(pr, 1.0 / 3.0);
  const double h = nu_gunn * kf / d;
  const double c = 0.1 * 6 * h / (rho * d);  // tau = 0.1 s
  const double tau = rho * c * d / (6 * h), dt = tau / 2000;
  char material[256];
  std::snprintf(material, sizeof material,
                "  - {name: heavy, youngs_modulus: 1e7, poisson_ratio: 0.3, density: 1e9, "
                "heat_capacity: %.17g, conductivity: 1}\n",
                c);
  const std::string yaml = std::string(
                               R"(domain: {min: [-0.01, -0.01, -0.01], max: [0.01, 0.01, 0.01]}
time: {step: 1e-4, end: 1}
heat: {}
materials:
)") + material + R"(interaction_defaults: {restitution: 0.5, friction: 0.3}
contact: {normal: hertz}
fluid:
  density: 1.2
  viscosity: 1.8e-5
  velocity: [1, 0, 0]
  void_fraction: 0.5
  drag: di_felice
  model: B
  forces: [drag, pressure_gradient, viscous]
  temperature: 300
  heat_capacity: 1005
  conductivity: 0.026
  convection: gunn
)";
  Scene s = parse_scene(yaml, "gunn.yaml");
  s.time.step = dt;
  Simulation sim(s, false);
  sim.add_force_term(make_fluid_forces(*s.fluid, s.gravity, s.domain, MPI_COMM_WORLD));
  sim.particles().add(1, Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), 0.5 * d, 0, rho);
  sim.particles().temperature.back() = t0;
  sim.next_id() = 2;
  sim.set_dt(dt);
  sim.initialise();
  double worst = 0;
  for (int k = 1; k <= 6; ++k) {
    sim.advance_to(0.5 * k * tau);
    const double expected = tf + (t0 - tf) * std::exp(-sim.time() / tau);
    worst =
        std::max(worst, std::abs((sim.particles().temperature[0] - expected) / (expected - tf)));
  }
  const double slip_change = sim.particles().v[0].norm() / u;
  std::printf(
      "Re = %.3f, Pr = %.4f, Nu (Gunn) = %.5f, h = %.3f W/m^2/K; largest error of "
      "T - T_f over 3 tau %.3e; slip change %.1e\n",
      re, pr, nu_gunn, h, worst, slip_change);
  EXPECT_LT(slip_change, 1e-5);
  EXPECT_LT(worst, 5e-3);
}

std::string error_of(const std::string& yaml) {
  try {
    parse_scene(yaml, "bad.yaml");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "no error";
}

TEST(HeatTransfer, ParserRefusesWhatIsNotBuiltOrSwitchedOff) {
  const std::string head = R"(domain: {min: [0, 0, 0], max: [1, 1, 1]}
time: {step: 1e-5, end: 1}
)";
  const std::string material =
      "materials: [{name: glass, youngs_modulus: 1e7, poisson_ratio: 0.3, density: 2500, "
      "heat_capacity: 800, conductivity: 1}]\n";
  const std::string plain =
      "materials: [{name: glass, youngs_modulus: 1e7, poisson_ratio: 0.3, density: 2500}]\n";
  std::string e = error_of(head + material);
  EXPECT_NE(e.find("bad.yaml:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("heat transfer is off; add a top-level `heat: {}`"), std::string::npos) << e;
  e = error_of(head + "heat: {}\n" + plain);
  EXPECT_NE(e.find("add `heat_capacity: <J/(kg K)>` (heat is on, bad.yaml:3)"),
            std::string::npos)
      << e;
  e = error_of(head + "heat: {contact_radius: morris}\n" + material);
  EXPECT_NE(e.find("bad.yaml:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("not built yet"), std::string::npos) << e;
  EXPECT_NE(e.find("allowed: geometric"), std::string::npos) << e;
  e = error_of(head + "heat: {}\n" + material +
               "insert: [{type: fill, region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}, count: 1, "
               "material: glass, radius: {distribution: constant, value: 0.01}}]\n");
  EXPECT_NE(e.find("add `temperature: <K>`"), std::string::npos) << e;
  e = error_of(head + "heat: {}\n" + material +
               "walls: [{type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: glass, "
               "temperature: 300, heat_flux: 10}]\n");
  EXPECT_NE(e.find("either a fixed `temperature` or a fixed `heat_flux`"), std::string::npos) << e;
  e = error_of(head + "heat: {}\n" + material +
               "fluid: {density: 1, viscosity: 1e-5, drag: schiller_naumann, model: B, forces: "
               "[drag, pressure_gradient, viscous], temperature: 300, conductivity: 0.03, "
               "convection: ranz}\n");
  EXPECT_NE(e.find("add the fluid's `heat_capacity"), std::string::npos) << e;
  e = error_of(head + "heat: {}\n" + material +
               "fluid: {density: 1, viscosity: 1e-5, drag: schiller_naumann, model: B, forces: "
               "[drag, pressure_gradient, viscous], temperature: 300, heat_capacity: 1000, "
               "conductivity: 0.03, convection: ranz}\n");
  EXPECT_NE(e.find("allowed: ranz_marshall, gunn"), std::string::npos) << e;
  e = error_of(head + plain + "output: {fields: [velocity, temperature]}\n");
  EXPECT_NE(e.find("the field 'temperature' needs heat transfer"), std::string::npos) << e;
}

// Gunn (1978) at eps = 1 is 2 + 0.7 Re^0.2 Pr^1/3 + 0.13 Re^0.7 Pr^1/3 (his eq. 21 evaluated),
// and Ranz-Marshall at Re = 0 is 2 (conduction into still fluid).
TEST(HeatTransfer, NusseltLaws) {
  EXPECT_DOUBLE_EQ(nusselt_ranz_marshall(0, 0.7), 2);
  EXPECT_DOUBLE_EQ(nusselt_ranz_marshall(100, 1), 8);
  const double re = 50, pr = 0.7;
  EXPECT_NEAR(nusselt_gunn(1, re, pr),
              2 * (1 + 0.7 * std::pow(re, 0.2) * std::cbrt(pr)) +
                  0.13 * std::pow(re, 0.7) * std::cbrt(pr),
              1e-12);
  EXPECT_DOUBLE_EQ(effective_conductivity(2, 2), 2);
  EXPECT_DOUBLE_EQ(effective_conductivity(1, 3), 1.5);
}

}  // namespace
}  // namespace grainflow
