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
