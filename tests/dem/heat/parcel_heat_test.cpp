// Heat transfer of coarse-grained parcels (docs/models/coarse-graining.md, "Heat transfer"),
// against independent references:
//  - convection: a parcel of k^3 glass beads (real d = 1 mm) held at rest in rising air cools
//    as the lumped exponential of the *real* bead, tau = rho c d / (6 h) with Ranz &
//    Marshall's h for the real d (1952), within 0.5 % at k = 1, 2, 3; `grain check`'s
//    convection time scale is that same tau;
//  - conduction: a row of parcels under the real rows' stress between a hot and a cold wall
//    carries the heat of the series resistances 1 / (2 k* a), a = sqrt(R* delta) from the
//    measured overlaps (Batchelor & O'Brien 1977), within 0.5 %; its overlaps are k times the
//    beads' and, per unit cross-section, it carries what k^2 rows of real beads of the same
//    length carry but for its two wall contacts: the ratio predicted from the beads' own
//    contact resistances holds to 0.5 %.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "dem/engine/simulation.hpp"
#include "dem/engine/time_step.hpp"
#include "dem/fluid/fluid_forces.hpp"
#include "dem/heat/heat_transfer.hpp"
#include "dem/heat/thermal_limits.hpp"
#include "dem/scene/scene_parser.hpp"
#include "tests/dem/support/terminal_velocity.hpp"

namespace grainflow {
namespace {

constexpr double kPi = std::numbers::pi;

std::string num(double x) {
  std::ostringstream o;
  o.precision(17);
  o << x;
  return o.str();
}

using test::schiller_naumann_terminal_velocity;

// The air rises at the real bead's terminal velocity: the parcel, whose drag is k^3 times the
// real bead's at the same slip, stays at rest, so its h is constant and its cooling
// exponential.
TEST(ParcelHeat, ParcelCoolsAtTheRealBeadsRate) {
  const double d = 1e-3, rho = 2500, c = 840, rho_f = 1.2, mu = 1.8e-5, cf = 1005, kf = 0.026;
  const double t0 = 600, tf = 300, g = 9.81;
  const double ut = schiller_naumann_terminal_velocity(d, rho, rho_f, mu, g);
  const double re = rho_f * d * ut / mu, pr = cf * mu / kf;
  const double h = (2 + 0.6 * std::sqrt(re) * std::cbrt(pr)) * kf / d;
  const double tau = rho * c * d / (6 * h);
  for (const double k : {1.0, 2.0, 3.0}) {
    const std::string scene = R"(domain: {min: [-0.1, -0.1, -0.1], max: [0.1, 0.1, 0.1]}
gravity: [0, 0, -9.81]
time: {step: 5e-4, end: 3}
heat: {}
materials:
  - {name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500, heat_capacity: 840,
     conductivity: 1}
interaction_defaults: {restitution: 0.5, friction: 0.3}
contact: {normal: hertz}
insert:
  - {type: fill, region: {box: {min: [-0.01, -0.01, -0.01], max: [0.01, 0.01, 0.01]}},
     count: 1, material: glass, radius: {distribution: constant, value: 5e-4}, temperature: 600,
     coarse_grain: )" + num(k) +
                              R"(}
fluid:
  density: 1.2
  viscosity: 1.8e-5
  velocity: [0, 0, )" + num(ut) +
                              R"(]
  drag: schiller_naumann
  model: B
  forces: [drag, pressure_gradient, viscous]
  temperature: 300
  heat_capacity: 1005
  conductivity: 0.026
  convection: ranz_marshall
)";
    const Scene s = parse_scene(scene, "parcel_cooling.yaml");
    Simulation sim(s);
    sim.add_force_term(make_fluid_forces(*s.fluid, s.gravity, s.domain, MPI_COMM_WORLD));
    sim.initialise();
    ASSERT_EQ(sim.particles().size(), 1u);
    EXPECT_DOUBLE_EQ(sim.particles().radius[0], k * d / 2);
    // `grain check`'s time scale: m c / (h A) of the parcel is the real bead's tau.
    TimeStepReport rep;
    rep.dt = *s.time.step;
    const ThermalLimits limits = check_thermal_limits(s, sim.particles(), rep);
    EXPECT_NEAR(limits.convection_time / tau, 1, 1e-12) << "k = " << k;
    double worst = 0, fastest = 0;
    for (int step = 1; step <= 6; ++step) {
      sim.advance_to(0.5 * step);
      const double expected = tf + (t0 - tf) * std::exp(-sim.time() / tau);
      const double got = sim.particles().temperature[0];
      worst = std::max(worst, std::abs((got - expected) / (expected - tf)));
      fastest = std::max(fastest, sim.particles().v[0].norm());
    }
    // What the parcel's own size would give instead: h(k d) k^2 A / (k^3 m c).
    const double re_k = rho_f * k * d * ut / mu;
    const double h_k = (2 + 0.6 * std::sqrt(re_k) * std::cbrt(pr)) * kf / (k * d);
    std::printf(
        "k = %g: tau %.4f s (a bead of the parcel's size: %.4f s), check's tau %.4f s; "
        "largest error of T - T_f over 3 s: %.3e, largest speed %.2e m/s\n",
        k, tau, rho * c * k * d / (6 * h_k), limits.convection_time, worst, fastest);
    EXPECT_LT(fastest, 1e-3 * ut) << "k = " << k;  // held at rest: the slip is u_t
    EXPECT_LT(worst, 5e-3) << "k = " << k;         // implicit Euler lags by dt / (2 tau)
  }
}

// A row of `n` parcels (radius k r_real) along x between a hot steel wall at x = 0 and a cold
// one at x = L, gravity off, each contact carrying the load k^2 F: the stress on the row's
// cross-section (2 k r)^2 is the real rows', so each overlap is k times the real one (Hertz:
// delta = (3 F / (4 Y* sqrt(R*)))^(2/3) with F ∝ k^2, R* ∝ k). The row is placed at that
// equilibrium (wall overlaps and pair overlaps from the Hertz law, L from them) and stays at
// rest. The fill insertion only makes the parcel class (material index 2: glass, steel, then
// glass[k]); the row is placed by hand.
struct Row {
  double heat_flow = 0;    // into the row through the hot wall [W]
  double closed_form = 0;  // (T_hot - T_cold) / sum of the contacts' 1 / (2 k* a)
  double wall_resistance = 0, pair_resistance = 0;  // one contact of each, from the overlaps
  double out_flow = 0, speed = 0;
};

Row conducting_row(int n, double k) {
  const double r = 5e-4 * k, k_glass = 1.2, k_steel = 16, nu = 0.3, load = 1e-6 * k * k;
  const auto y_star = [&](double ya, double yb) {
    return 1 / ((1 - nu * nu) / ya + (1 - nu * nu) / yb);
  };
  const auto hertz_overlap = [&](double y, double rs) {
    return std::pow(3 * load / (4 * y * std::sqrt(rs)), 2.0 / 3.0);
  };
  const double wall_overlap = hertz_overlap(y_star(1e7, 2e8), r);
  const double pair_overlap = hertz_overlap(y_star(1e7, 1e7), 0.5 * r);
  const double length = n * 2 * r - (n - 1) * pair_overlap - 2 * wall_overlap;
  const std::string yaml =
      "domain: {min: [0, -0.004, -0.004], max: [" + num(length) +
      ", 0.004, 0.004]}\n"
      "time: {step: 1e-6, end: 1}\n"
      "heat: {}\n"
      "materials:\n"
      "  - {name: glass, youngs_modulus: 1e7, poisson_ratio: 0.3, density: 2500,\n"
      "     heat_capacity: 1e-3, conductivity: 1.2}\n"
      "  - {name: steel, youngs_modulus: 2e8, poisson_ratio: 0.3, density: 7800,\n"
      "     heat_capacity: 500, conductivity: 16}\n"
      "interaction_defaults: {restitution: 0.1, friction: 0.3}\n"
      "contact: {normal: hertz}\n"
      "walls:\n"
      "  - {type: plane, name: hot, point: [0, 0, 0], normal: [1, 0, 0], material: steel,\n"
      "     temperature: 400}\n"
      "  - {type: plane, name: cold, point: [" +
      num(length) +
      ", 0, 0], normal: [-1, 0, 0],\n"
      "     material: steel, temperature: 300}\n"
      "insert:\n"
      "  - {type: fill, region: {box: {min: [0, -0.003, -0.003], max: [" +
      num(length) +
      ", 0.003, 0.003]}},\n"
      "     count: 1, material: glass, radius: {distribution: constant, value: 5e-4},\n"
      "     temperature: 300, coarse_grain: " +
      num(k) + "}\n";
  const Scene s = parse_scene(yaml, "parcel_row.yaml");
  const int parcel = k == 1 ? 0 : 2;
  if (k != 1) {
    EXPECT_EQ(s.materials[parcel].coarse_grain, k);
  }
  Simulation sim(s, false);
  for (int i = 0; i < n; ++i) {
    sim.particles().add(i + 1, Vec3(r - wall_overlap + i * (2 * r - pair_overlap), 0, 0),
                        Vec3::Zero(), Vec3::Zero(), r, parcel, 2500);
    sim.particles().temperature.back() = 300;
  }
  sim.next_id() = n + 1;
  sim.initialise();
  sim.advance_to(0.05);
  const Particles& p = sim.particles();
  EXPECT_EQ(p.size(), static_cast<std::size_t>(n));
  std::vector<double> x(n);
  for (std::size_t i = 0; i < p.size(); ++i) x[p.id[i] - 1] = p.x[i][0];
  Row row;
  const double k_wall = 2 * k_glass * k_steel / (k_glass + k_steel);
  row.wall_resistance = 1 / (2 * k_wall * std::sqrt(r * (r - x[0])));
  row.pair_resistance = 1 / (2 * k_glass * std::sqrt(0.5 * r * (2 * r - (x[1] - x[0]))));
  double resistance =
      row.wall_resistance + 1 / (2 * k_wall * std::sqrt(r * (r - (length - x[n - 1]))));
  for (int i = 0; i + 1 < n; ++i)
    resistance += 1 / (2 * k_glass * std::sqrt(0.5 * r * (2 * r - (x[i + 1] - x[i]))));
  row.closed_form = 100 / resistance;
  row.heat_flow = sim.heat()->wall_heat()[0];
  row.out_flow = -sim.heat()->wall_heat()[1];
  for (std::size_t i = 0; i < p.size(); ++i) row.speed = std::max(row.speed, p.v[i].norm());
  return row;
}

TEST(ParcelHeat, RowOfParcelsConductsAsTheRealRowsPerCrossSection) {
  const int beads = 12;  // real beads of d = 1 mm along the row; 6 parcels of k = 2, 4 of k = 3
  const Row real = conducting_row(beads, 1);
  for (const double k : {1.0, 2.0, 3.0}) {
    const int n = static_cast<int>(beads / k);
    const Row row = k == 1 ? real : conducting_row(n, k);
    EXPECT_NEAR(row.heat_flow / row.closed_form, 1, 5e-3) << "k = " << k;
    EXPECT_NEAR(row.out_flow / row.closed_form, 1, 5e-3) << "k = " << k;
    EXPECT_LT(row.speed, 1e-6) << "k = " << k;  // at rest
    // A parcel row stands for k^2 real rows side by side. Its contacts have k times the real
    // overlaps and radii, so a = sqrt(R* delta) is k times the real one and each resistance
    // 1/k of it: the parcel row's sum is ((n - 1) R_pair + 2 R_wall) / k with the beads' own
    // R_pair and R_wall. Per cross-section it carries, against the real rows,
    //   ((N - 1) R_pair + 2 R_wall) / ((N - k) R_pair + 2 k R_wall),   N = 12 beads:
    // more than 1 when a wall contact resists less than half a pair contact (here: steel).
    const double per_area = row.heat_flow / (k * k * real.heat_flow);
    const double predicted = ((beads - 1) * real.pair_resistance + 2 * real.wall_resistance) /
                             ((beads - k) * real.pair_resistance + 2 * k * real.wall_resistance);
    std::printf(
        "k = %g: %d parcels, heat flow %.6e W (closed form %.6e W); per cross-section "
        "%.5f of the beads' rows, predicted %.5f (R_wall / R_pair = %.4f)\n",
        k, n, row.heat_flow, row.closed_form, per_area, predicted,
        real.wall_resistance / real.pair_resistance);
    EXPECT_NEAR(per_area / predicted, 1, 5e-3) << "k = " << k;
    EXPECT_NEAR(row.wall_resistance * k / real.wall_resistance, 1, 5e-3) << "k = " << k;
    EXPECT_NEAR(row.pair_resistance * k / real.pair_resistance, 1, 5e-3) << "k = " << k;
  }
}

}  // namespace
}  // namespace grainflow
