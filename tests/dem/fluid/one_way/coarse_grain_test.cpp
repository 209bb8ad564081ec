// Coarse-grained parcels (docs/models/coarse-graining.md): an insertion's `coarse_grain: k`
// inserts parcels of radius k r standing for k^3 real particles of radius r.
//
// 1. Settling: a lone parcel of glass (real d = 0.2 mm) in quiescent water, drag (Schiller-
//    Naumann) + pressure gradient (hydrostatic) + viscous, model B. Reference: the real
//    particle's terminal velocity from K_SN(d, u) u = (rho_p - rho_f) (pi/6) d^3 g, solved by
//    bisection here (independent of the parcel code). Asserted within 0.5 % for k = 1, 2, 3
//    (Sakai & Koshizuka 2009: the parcel's drag is k^3 times the real particle's at the
//    parcel's slip, and its weight and buoyancy are k^3 times the real one's).
// 2. The fluid's momentum: the implicit drag coefficient of a parcel equals k^3 times that
//    of a real particle at the same slip, to round-off.
// 3. k = 1 is today's path: a bed of 30 beads settling in water onto a floor, with contacts,
//    gives bit-identical positions and velocities with `coarse_grain: 1` and without the key.
// 4. Contact (Bierwisch et al. 2009, energy-conserving scaling: the parcel keeps the real
//    material's properties): a parcel-wall Hertz impact returns the material's restitution
//    e (the Antypov-Elliott mapping, to 0.2 %), and its peak overlap and contact time are k
//    times the real particle's (Hertz: delta ~ (m v^2 / (Y sqrt(R)))^(2/5), t_c ~ delta/v,
//    with m ~ k^3, R ~ k), within 0.5 %.
// 5. Parser: k < 1, a non-number, coarse_grain on a csv insertion, with cohesion and with
//    a lift force are refused naming file:line, the key and what is allowed.
// 6. Output: a run's snapshots hold coarse_grain = k and real_count = k^3 for every parcel.
// 7. Continuing from a snapshot of parcels, 8. a restart with a changed k (below).
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <sstream>
#include <string>

#include "dem/engine/run.hpp"
#include "dem/engine/simulation.hpp"
#include "dem/fluid/fluid_forces.hpp"
#include "dem/fluid/schiller_naumann.hpp"
#include "dem/scene/scene_parser.hpp"

namespace grainflow {
namespace {

constexpr double kRhoP = 2500, kRhoF = 1000, kMu = 1e-3, kG = 9.81;

// A number as YAML text, exactly (std::to_string keeps 6 decimals only).
std::string num(double x) {
  std::ostringstream o;
  o.precision(17);
  o << x;
  return o.str();
}

// A scene around `insert` (YAML lines of one insertion entry, indented by 4).
std::string scene_text(const std::string& insert, double dt, const std::string& extra = "") {
  return R"(domain: {min: [-0.05, -0.05, -0.05], max: [0.05, 0.05, 0.05]}
gravity: [0, 0, -9.81]
time: {step: )" + num(dt) +
         R"(, end: 1}
materials:
  - {name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}
interaction_defaults: {restitution: 0.5, friction: 0.3}
contact: {normal: hertz}
fluid:
  density: 1000
  viscosity: 1e-3
  drag: schiller_naumann
  model: B
  forces: [drag, pressure_gradient, viscous]
)" + extra + "insert:\n  - type: fill\n" +
         insert;
}

// Real-particle terminal velocity: K_SN(d, u) u = (rho_p - rho_f) V g by bisection.
double terminal_velocity(double d) {
  const double weight = (kRhoP - kRhoF) * std::numbers::pi / 6 * d * d * d * kG;
  double lo = 0, hi = 10;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (schiller_naumann({d, mid, 1, kRhoF, kMu}) * mid < weight ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

std::string lone_parcel(double r, const std::string& k_line) {
  return "    region: {box: {min: [-0.001, -0.001, -0.001], max: [0.001, 0.001, 0.001]}}\n"
         "    count: 1\n    material: glass\n    radius: {distribution: constant, value: " +
         num(r) + "}\n" + k_line;
}

TEST(CoarseGrain, ParcelSettlesAtTheRealParticlesTerminalVelocity) {
  const double d = 0.2e-3, ut = terminal_velocity(d);
  const double re = kRhoF * d * ut / kMu;
  const double tau = kRhoP * d * d / (18 * kMu) / (1 + 0.15 * std::pow(re, 0.687));
  for (double k : {1.0, 2.0, 3.0}) {
    const std::string key = k == 1 ? "" : "    coarse_grain: " + num(k) + "\n";
    const Scene s = parse_scene(scene_text(lone_parcel(d / 2, key), tau / 20), "settle.yaml");
    Simulation sim(s, true, MPI_COMM_SELF);
    ASSERT_EQ(sim.particles().size(), 1u);
    const double real_mass = kRhoP * std::numbers::pi / 6 * d * d * d;
    EXPECT_NEAR(sim.particles().radius[0], k * d / 2, 1e-15);
    EXPECT_NEAR(sim.particles().mass[0] / (k * k * k * real_mass), 1, 1e-14);
    sim.add_force_term(make_fluid_forces(*s.fluid, s.gravity, s.domain, MPI_COMM_SELF));
    sim.advance_to(12 * tau);
    const double v = -sim.particles().v[0].z();
    std::printf("k = %g: parcel d = %g m, real u_t = %.6g m/s (Re %.3g), parcel %.6g m/s, "
                "rel. gap %.2e\n",
                k, k * d, ut, re, v, std::abs(v / ut - 1));
    EXPECT_NEAR(v / ut, 1, 0.005) << "k = " << k;
  }
}

TEST(CoarseGrain, ParcelDragIsKCubedTimesTheRealParticles) {
  const double r = 0.1e-3;
  for (double k : {2.0, 3.0, 2.5}) {
    const Scene s = parse_scene(
        scene_text(lone_parcel(r, "    coarse_grain: " + num(k) + "\n"), 1e-5),
        "drag.yaml");
    ASSERT_EQ(s.materials.size(), 2u);  // glass and its parcel class
    EXPECT_EQ(s.materials[1].coarse_grain, k);
    const auto term = make_fluid_forces(*s.fluid, s.gravity, s.domain, MPI_COMM_SELF);
    Particles p;
    const Vec3 v(0.01, -0.02, 0.03);
    p.add(1, Vec3::Zero(), v, Vec3::Zero(), r, 0, kRhoP);          // a real particle
    p.add(2, Vec3::Zero(), v, Vec3::Zero(), k * r, 1, kRhoP);      // a parcel
    ImplicitDrag drag{{0, 0}, {Vec3::Zero(), Vec3::Zero()}, {}, {}};
    term->add(p, 0, drag);
    const double ratio = drag.coefficient[1] / drag.coefficient[0];
    std::printf("k = %g: K_parcel / K_real = %.16g (k^3 = %g)\n", k, ratio, k * k * k);
    EXPECT_NEAR(ratio / (k * k * k), 1, 1e-14);
    // The parcel's buoyant weight (pressure gradient on its volume) is k^3 the real one's.
    EXPECT_NEAR(p.force[1].z() / p.force[0].z() / (k * k * k), 1, 1e-14);
  }
}

TEST(CoarseGrain, FactorOneIsBitIdenticalToNoKey) {
  const std::string bed =
      "    region: {box: {min: [-0.004, -0.004, -0.004], max: [0.004, 0.004, 0.004]}}\n"
      "    count: 30\n    material: glass\n    seed: 7\n"
      "    radius: {distribution: uniform, min: 0.4e-3, max: 0.6e-3}\n";
  const std::string floor =
      "walls:\n  - {type: plane, point: [0, 0, -0.005], normal: [0, 0, 1], material: glass}\n";
  const Scene plain = parse_scene(scene_text(bed, 2e-5, floor), "bed.yaml");
  const Scene one = parse_scene(scene_text(bed + "    coarse_grain: 1\n", 2e-5, floor), "bed.yaml");
  EXPECT_TRUE(one.coarse_grain_table().empty());
  EXPECT_TRUE(one.fluid->coarse_grain.empty());
  Simulation a(plain, true, MPI_COMM_SELF), b(one, true, MPI_COMM_SELF);
  a.add_force_term(make_fluid_forces(*plain.fluid, plain.gravity, plain.domain, MPI_COMM_SELF));
  b.add_force_term(make_fluid_forces(*one.fluid, one.gravity, one.domain, MPI_COMM_SELF));
  a.advance_to(0.06);
  b.advance_to(0.06);
  ASSERT_EQ(a.particles().size(), b.particles().size());
  EXPECT_GT(a.counters().steps, 2000);
  for (std::size_t i = 0; i < a.particles().size(); ++i) {
    EXPECT_EQ(a.particles().id[i], b.particles().id[i]);
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(a.particles().x[i][c], b.particles().x[i][c]);
      EXPECT_EQ(a.particles().v[i][c], b.particles().v[i][c]);
      EXPECT_EQ(a.particles().omega[i][c], b.particles().omega[i][c]);
    }
  }
}

struct WallImpact {
  double restitution = 0, max_overlap = 0, contact_time = 0;
};

// A parcel (real radius 1 mm, factor k) hits the floor at 0.5 m/s without gravity.
// `contact`: the scene's contact block.
WallImpact wall_impact(double k, double e,
                       const std::string& contact = "{normal: hertz, tangential: none}") {
  const double r = 1e-3, v = 0.5;
  const std::string text =
      "domain: {min: [-0.05, -0.05, -0.05], max: [0.05, 0.05, 0.05]}\n"
      "time: {step: 1e-6, end: 1}\n"
      "materials:\n  - {name: glass, youngs_modulus: 1e7, poisson_ratio: 0.3, density: 2500}\n"
      "interaction_defaults: {restitution: " +
      num(e) +
      "}\n"
      "contact: " +
      contact +
      "\n"
      "walls:\n  - {type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: glass}\n"
      "insert:\n  - type: fill\n"
      "    region: {box: {min: [-0.01, -0.01, 0.01], max: [0.01, 0.01, 0.03]}}\n"
      "    count: 1\n    material: glass\n    velocity: [0, 0, -0.5]\n"
      "    radius: {distribution: constant, value: 1e-3}\n"
      "    coarse_grain: " +
      num(k) + "\n";
  const Scene s = parse_scene(text, "impact.yaml");
  Simulation sim(s, true, MPI_COMM_SELF);
  Particles& p = sim.particles();
  p.x[0] = Vec3(0, 0, k * r * 1.0001);  // just above the floor
  // Hertz contact time at 0.5 m/s is about 0.3 ms for k = 1 and k times that for a parcel:
  // about 550 steps per impact.
  sim.set_dt(k * 5e-7);
  sim.initialise();
  WallImpact out;
  double t_start = -1;
  for (long n = 0; n < 1'000'000; ++n) {
    sim.step();
    const double overlap = k * r - p.x[0].z();
    if (overlap > 0) {
      if (t_start < 0) t_start = sim.time();
      out.max_overlap = std::max(out.max_overlap, overlap);
    } else if (t_start >= 0) {
      out.contact_time = sim.time() - t_start;
      out.restitution = p.v[0].z() / v;
      return out;
    }
  }
  ADD_FAILURE() << "no rebound";
  return out;
}

TEST(CoarseGrain, ParcelWallImpactKeepsTheMaterialsRestitution) {
  // Hertz, and Hooke with its stiffness from the characteristic velocity (k_n ∝ sqrt(R*)
  // (m* / sqrt(R*))^(1/5) ∝ k: the energy-conserving rule; normal_hooke.hpp).
  for (const char* contact : {"{normal: hertz, tangential: none}",
                              "{normal: hooke, hooke: {characteristic_velocity: 0.5}, "
                              "tangential: none}"})
    for (double e : {0.5, 0.9}) {
      std::printf("contact %s\n", contact);
      const WallImpact real = wall_impact(1, e, contact);
      std::printf("e = %g, k = 1: restitution %.5f, overlap %.6g m, t_c %.6g s\n", e,
                  real.restitution, real.max_overlap, real.contact_time);
      EXPECT_NEAR(real.restitution / e, 1, 2e-3);
      for (double k : {2.0, 3.0}) {
        const WallImpact w = wall_impact(k, e, contact);
        std::printf("e = %g, k = %g: restitution %.5f, overlap/k %.6g m, t_c/k %.6g s\n", e, k,
                    w.restitution, w.max_overlap / k, w.contact_time / k);
        EXPECT_NEAR(w.restitution / e, 1, 2e-3) << "k = " << k;
        EXPECT_NEAR(w.max_overlap / (k * real.max_overlap), 1, 5e-3) << "k = " << k;
        EXPECT_NEAR(w.contact_time / (k * real.contact_time), 1, 5e-3) << "k = " << k;
      }
    }
}

std::string error_of(const std::string& text) {
  try {
    parse_scene(text, "cg.yaml");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "no error";
}

TEST(CoarseGrain, ParserNamesFileLineKeyAndAllowedValues) {
  // The insertion entry starts at line 15; coarse_grain is its sixth line (20).
  const auto with = [](const std::string& k_line) {
    return scene_text(lone_parcel(1e-4, k_line), 1e-5);
  };
  std::string e = error_of(with("    coarse_grain: 0.5\n"));
  std::printf("%s\n", e.c_str());
  EXPECT_NE(e.find("cg.yaml:20:"), std::string::npos) << e;
  EXPECT_NE(e.find("coarse_grain"), std::string::npos) << e;
  EXPECT_NE(e.find("value 0.5 is out of range; it must be in [1, 1000]"), std::string::npos) << e;
  e = error_of(with("    coarse_grain: two\n"));
  std::printf("%s\n", e.c_str());
  EXPECT_NE(e.find("cg.yaml:20:"), std::string::npos) << e;
  EXPECT_NE(e.find("coarse_grain"), std::string::npos) << e;
  EXPECT_NE(e.find("expected a number, got"), std::string::npos) << e;
  // A csv insertion keeps its particles' sizes.
  e = error_of(R"(domain: {min: [0, 0, 0], max: [1, 1, 1]}
time: {step: 1e-5, end: 1}
materials:
  - {name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}
interaction_defaults: {restitution: 0.5}
contact: {normal: hertz}
insert:
  - {type: csv, file: complete_particles.csv, material: glass, coarse_grain: 2}
)");
  std::printf("%s\n", e.c_str());
  EXPECT_NE(e.find("cg.yaml:8:"), std::string::npos) << e;
  EXPECT_NE(e.find("coarse_grain is available on fill and stream insertions"), std::string::npos)
      << e;
  // Models not scaled for parcels are refused at their own key, naming the insertion: a fixed
  // Hooke stiffness (the advice, the characteristic velocity, is then accepted).
  std::string stiff = with("    coarse_grain: 2\n");
  stiff.replace(stiff.find("contact: {normal: hertz}"), 24,
                "contact: {normal: hooke, hooke: {stiffness: {normal: 100}}}");
  e = error_of(stiff);
  std::printf("%s\n", e.c_str());
  EXPECT_NE(e.find("cg.yaml:7:"), std::string::npos) << e;
  EXPECT_NE(e.find("stiffness"), std::string::npos) << e;
  EXPECT_NE(e.find("does not grow with the parcels as the energy-conserving scaling asks (k_n in "
                   "proportion to k), coarse_grain 2 (the insertion at cg.yaml:15); use `hooke: "
                   "{characteristic_velocity: <m/s>}`"),
            std::string::npos)
      << e;
  stiff.replace(stiff.find("hooke: {stiffness: {normal: 100}}"), 33,
                "hooke: {characteristic_velocity: 1}");
  EXPECT_EQ(error_of(stiff), "no error");
  // Cohesion and rolling resistance are scaled (below): accepted.
  std::string cohesive = with("    coarse_grain: 2\n");
  cohesive.replace(cohesive.find("contact: {normal: hertz}"), 24,
                   "contact: {normal: hertz, cohesion: sjkr, rolling: epsd}");
  EXPECT_EQ(error_of(cohesive), "no error");
  std::string lift = with("    coarse_grain: 2\n");
  lift.replace(lift.find("forces: [drag, pressure_gradient, viscous]"), 42,
               "forces: [drag, pressure_gradient, viscous, saffman_mei]");
  e = error_of(lift);
  std::printf("%s\n", e.c_str());
  EXPECT_NE(e.find("cg.yaml:13:"), std::string::npos) << e;
  EXPECT_NE(e.find("allowed with parcels: drag, pressure_gradient, viscous, buoyancy, "
                   "virtual_mass"),
            std::string::npos)
      << e;
}

// Scene text for two-body contact tests without a fluid: glass (Y = 1e7 Pa), the contact
// block `contact`, interaction defaults `pairs`, gravity `gravity`, a floor when `floor`, and a
// fill of one parcel of factor k whose class (index 1) the tests use for particles they place.
std::string dry_scene(double k, const std::string& contact, const std::string& pairs,
                      const std::string& gravity, bool floor) {
  return "domain: {min: [-0.05, -0.05, -0.05], max: [0.05, 0.05, 0.05]}\n"
         "gravity: " +
         gravity +
         "\n"
         "time: {step: 1e-6, end: 1}\n"
         "materials:\n  - {name: glass, youngs_modulus: 1e7, poisson_ratio: 0.3, density: 2500}\n"
         "interaction_defaults: " +
         pairs +
         "\n"
         "contact: " +
         contact + "\n" +
         (floor ? "walls:\n  - {type: plane, point: [0, 0, -0.04], normal: [0, 0, 1], "
                  "material: glass}\n"
                : "") +
         "insert:\n  - type: fill\n"
         "    region: {box: {min: [-0.01, -0.01, 0.01], max: [0.01, 0.01, 0.03]}}\n"
         "    count: 1\n    material: glass\n"
         "    radius: {distribution: constant, value: 1e-3}\n"
         "    coarse_grain: " +
         num(k) + "\n";
}

// Cohesion (SJKR, the real material's k_c): two parcels that touch without gravity settle where
// the Hertz repulsion balances the cohesion, (4/3) Y* sqrt(R*) d^{3/2} = k_c pi (R d - d^2/4)
// for parcels of radius R = k r (tests/dem/contact/cohesion_test.cpp). Both sides grow as k^2
// when R and d grow as k, so the root is k times the real pair's: the parcels keep the real
// overlap ratio d / R, and their cohesive force is k^2 times the real one, the scaling Thakur
// et al. (2016) find for the adhesive force. Each k's settled overlap against its own root by
// bisection (0.5 %, the residual oscillation) and the roots against k d_1 (1e-9).
TEST(CoarseGrain, CohesiveParcelsSettleAtKTimesTheRealOverlap) {
  const double y = 1e7, nu = 0.3, r = 1e-3, kc = 1.65e5;
  const double y_star = y / (2 * (1 - nu * nu));
  const auto root = [&](double radius) {
    const auto balance = [&](double d) {
      return 4.0 / 3.0 * y_star * std::sqrt(radius / 2) * std::pow(d, 1.5) -
             kc * std::numbers::pi * (radius * d - d * d / 4);
    };
    double lo = 1e-9 * radius, hi = 0.5 * radius;
    for (int i = 0; i < 200; ++i) (balance(0.5 * (lo + hi)) < 0 ? lo : hi) = 0.5 * (lo + hi);
    return lo;
  };
  const double d1 = root(r);
  for (const double k : {1.0, 2.0, 3.0}) {
    const Scene s = parse_scene(
        dry_scene(k, "{normal: hertz, cohesion: sjkr}",
                  "{restitution: 0.3, friction: 0.3, cohesion_energy_density: " + num(kc) + "}",
                  "[0, 0, 0]", false),
        "cohesive_pair.yaml");
    const int cls = k == 1 ? 0 : 1;
    const double radius = k * r, d0 = 1e-3 * radius;
    Simulation sim(s, false);
    sim.particles().add(1, Vec3(-(radius - d0 / 2), 0, 0), Vec3::Zero(), Vec3::Zero(), radius, cls,
                        2500);
    sim.particles().add(2, Vec3(radius - d0 / 2, 0, 0), Vec3::Zero(), Vec3::Zero(), radius, cls,
                        2500);
    sim.next_id() = 3;
    sim.set_dt(k * 5e-8);
    sim.initialise();
    sim.advance_to(k * 0.02);
    const double d = 2 * radius - (sim.particles().x[1] - sim.particles().x[0]).norm();
    const double dk = root(radius);
    const double force = kc * std::numbers::pi * (radius * dk - dk * dk / 4);
    std::printf(
        "k = %g: settled overlap %.6e m, root %.6e m (k d_1 = %.6e m), cohesive force "
        "%.6e N = %.6f k^2 x the real pair's\n",
        k, d, dk, k * d1, force, force / (k * k * kc * std::numbers::pi * (r * d1 - d1 * d1 / 4)));
    EXPECT_NEAR(d / dk, 1, 5e-3) << "k = " << k;
    EXPECT_NEAR(dk / (k * d1), 1, 1e-9) << "k = " << k;
  }
}

// Rolling resistance (the real material's mu_r): a sphere rolling without slip on a floor
// under a torque mu_r R* F_n = mu_r r m g (wall: R* = r) slows at a = (5/7) mu_r g (about the
// contact point, I = (7/5) m r^2), whatever its radius, so a parcel rolls to rest as the real
// bead does. v(t) against v_0 - a t at three times before it stops: cdt within 0.1 % of v_0
// (measured 3e-4 to 7e-4); epsd, whose spring is not always fully mobilised and whose dashpot
// then acts, within 1.5 % (measured 0.44, 0.78, 1.05 % at k = 1, 2, 3: the parcel's weight,
// k^3, is not scaled as its contact forces, k^2, are, so its static overlap ratio grows).
TEST(CoarseGrain, RollingParcelSlowsAsTheRealBead) {
  const double r = 1e-3, g = 9.81, mu_r = 0.1, v0 = 0.2;
  const double a = 5.0 / 7.0 * mu_r * g;
  for (const char* model : {"cdt", "epsd"})
    for (const double k : {1.0, 2.0, 3.0}) {
      const Scene s = parse_scene(
          dry_scene(k, std::string("{normal: hertz, rolling: ") + model + "}",
                    "{restitution: 0.1, friction: 0.5, rolling_friction: " + num(mu_r) + "}",
                    "[0, 0, -9.81]", true),
          "rolling_parcel.yaml");
      const int cls = k == 1 ? 0 : 1;
      const double radius = k * r;
      // At rest on the floor: the static Hertz overlap under the parcel's weight.
      const double m = 2500 * 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
      const double y_star = 1e7 / (2 * (1 - 0.3 * 0.3));
      const double overlap = std::pow(3 * m * g / (4 * y_star * std::sqrt(radius)), 2.0 / 3.0);
      Simulation sim(s, false);
      sim.particles().add(1, Vec3(0, 0, -0.04 + radius - overlap), Vec3(v0, 0, 0),
                          Vec3(0, v0 / radius, 0), radius, cls, 2500);
      sim.next_id() = 2;
      sim.set_dt(k * 2e-6);
      sim.initialise();
      double worst = 0;
      for (const double t : {0.05, 0.1, 0.2}) {  // it stops at v0 / a = 0.285 s
        sim.advance_to(t);
        worst = std::max(worst, std::abs(sim.particles().v[0][0] - (v0 - a * t)) / v0);
      }
      std::printf(
          "%s, k = %g: v(0.2 s) = %.5f m/s, closed form %.5f m/s; largest error %.2e "
          "of v_0\n",
          model, k, sim.particles().v[0][0], v0 - a * 0.2, worst);
      EXPECT_LT(worst, std::string(model) == "cdt" ? 1e-3 : 1.5e-2) << model << ", k = " << k;
    }
}

std::vector<double> dataset(const std::string& file, const char* name) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  std::vector<double> out;
  if (f < 0) return out;
  if (H5Lexists(f, name, H5P_DEFAULT) > 0) {
    const hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    const hid_t space = H5Dget_space(d);
    out.resize(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
    H5Sclose(space);
    H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data());
    H5Dclose(d);
  }
  H5Fclose(f);
  return out;
}

TEST(CoarseGrain, SnapshotsCarryTheFactorAndTheRealCount) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "coarse_grain_snapshots";
  fs::remove_all(dir);
  const Scene s = parse_scene(
      scene_text(lone_parcel(1e-4, "    coarse_grain: 2.5\n"), 1e-4,
                 "output: {snapshot_interval: 0.001, progress: false}\n") ,
      "snapshots.yaml");
  Scene short_run = s;
  short_run.time.end = 0.002;
  RunOptions options;
  options.output_directory = dir.string();
  options.progress = false;
  options.handle_stop_signals = false;
  std::ostringstream log;
  run_scene(short_run, options, MPI_COMM_WORLD, log);
  const std::string file = (dir / "particles_000002.h5").string();
  EXPECT_EQ(dataset(file, "coarse_grain"), std::vector<double>{2.5});
  EXPECT_EQ(dataset(file, "real_count"), std::vector<double>{2.5 * 2.5 * 2.5});
  EXPECT_NE(log.str().find("1 parcels of k = 2.5 stand for 15.625 real particles"),
            std::string::npos)
      << log.str();
}

// 7. A snapshot of parcels continues as parcels: a scene with a `type: snapshot` insertion
//    gets the parcel classes of the scene that wrote the file (its root attributes
//    material_coarse_grain and material_real), shared with its own insertions of the same
//    (material, k). The continued parcel still settles at the real bead's terminal velocity
//    (Schiller-Naumann, solved here), not at that of a bead of the parcel's size. A snapshot
//    of parcels without the classes, and one whose coarse_grain dataset disagrees with its
//    class, are refused naming the file.
TEST(CoarseGrain, SnapshotOfParcelsContinuesAsParcels) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "coarse_grain_continue";
  fs::remove_all(dir);
  const double d = 0.2e-3, ut = terminal_velocity(d);
  const double re = kRhoF * d * ut / kMu;
  const double tau = kRhoP * d * d / (18 * kMu) / (1 + 0.15 * std::pow(re, 0.687));
  Scene writer = parse_scene(
      scene_text(lone_parcel(d / 2, "    coarse_grain: 2\n"), tau / 20,
                 "output: {snapshot_interval: " + num(2 * tau) + ", progress: false}\n"),
      "writer.yaml");
  writer.time.end = 2 * tau;
  RunOptions options;
  options.output_directory = dir.string();
  options.progress = false;
  options.handle_stop_signals = false;
  std::ostringstream log;
  run_scene(writer, options, MPI_COMM_WORLD, log);
  const std::string file = (dir / "particles_000001.h5").string();
  ASSERT_TRUE(fs::exists(file)) << log.str();

  // The reading scene: a snapshot insertion, then optionally a fill of parcels.
  const auto reader = [&](const std::string& file_name, const std::string& fill_k) {
    std::string text = scene_text("", tau / 20);
    text.replace(text.find("  - type: fill\n"), 15,
                 "  - type: snapshot\n    file: " + file_name + "\n");
    if (!fill_k.empty())
      text +=
          "  - type: fill\n    region: {box: {min: [0.02, 0.02, 0.02], max: [0.03, 0.03, "
          "0.03]}}\n    count: 1\n    material: glass\n    radius: {distribution: constant, "
          "value: " +
          num(d / 2) + "}\n    coarse_grain: " + fill_k + "\n";
    return text;
  };
  {
    const Scene s = parse_scene(reader(file, ""), "reader.yaml");
    ASSERT_EQ(s.materials.size(), 2u);
    EXPECT_EQ(s.materials[1].name, "glass[k=2]");
    EXPECT_EQ(s.materials[1].coarse_grain, 2);
    Simulation sim(s, true, MPI_COMM_SELF);
    ASSERT_EQ(sim.particles().size(), 1u);
    EXPECT_EQ(sim.particles().material[0], 1);
    EXPECT_NEAR(sim.particles().radius[0], d, 1e-15);
    sim.add_force_term(make_fluid_forces(*s.fluid, s.gravity, s.domain, MPI_COMM_SELF));
    sim.advance_to(sim.time() + 12 * tau);
    const double v = -sim.particles().v[0].z();
    std::printf(
        "continued parcel of k = 2: %.6g m/s, the real bead's u_t %.6g m/s (the parcel's "
        "size as a bead: %.6g m/s)\n",
        v, ut, terminal_velocity(2 * d));
    EXPECT_NEAR(v / ut, 1, 0.005);
  }
  // A reader that lists another material first: the stored classes are matched by name
  // (root attribute material_names), so the parcel is still a glass parcel, not a steel one.
  {
    std::string text = reader(file, "");
    const std::string glass = "  - {name: glass,";
    text.insert(text.find(glass),
                "  - {name: steel, youngs_modulus: 2e11, poisson_ratio: 0.3, density: 7800}\n");
    const Scene s = parse_scene(text, "reader.yaml");
    Simulation sim(s, true, MPI_COMM_SELF);
    ASSERT_EQ(sim.particles().size(), 1u);
    const Material& m = s.materials[static_cast<std::size_t>(sim.particles().material[0])];
    EXPECT_EQ(m.name, "glass[k=2]");
    EXPECT_EQ(m.density, 2500);
  }
  // With a fill of the same k the class is shared; with another k, both exist.
  EXPECT_EQ(parse_scene(reader(file, "2"), "reader.yaml").materials.size(), 2u);
  const Scene two = parse_scene(reader(file, "3"), "reader.yaml");
  ASSERT_EQ(two.materials.size(), 3u);
  EXPECT_EQ(two.materials[1].name, "glass[k=2]");
  EXPECT_EQ(two.materials[2].name, "glass[k=3]");

  // A copy whose coarse_grain dataset says 3 for the k = 2 parcel.
  const std::string tampered = (dir / "tampered.h5").string();
  fs::copy_file(file, tampered);
  {
    const hid_t f = H5Fopen(tampered.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    const hid_t ds = H5Dopen2(f, "/coarse_grain", H5P_DEFAULT);
    const double three = 3;
    H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, &three);
    H5Dclose(ds);
    H5Fclose(f);
  }
  std::string e = "no error";
  try {
    Simulation sim(parse_scene(reader(tampered, ""), "reader.yaml"), true, MPI_COMM_SELF);
  } catch (const std::exception& x) {
    e = x.what();
  }
  std::printf("%s\n", e.c_str());
  EXPECT_NE(e.find(tampered + ": error: dataset '/coarse_grain', index 0"), std::string::npos) << e;
  EXPECT_NE(e.find("k = 3, but its material 'glass[k=2]' has k = 2"), std::string::npos) << e;

  // A copy whose parcel class copies another parcel class (its listed material changed to 1,
  // the writer's glass[k=2]): a broken class.
  const std::string other = (dir / "other_material.h5").string();
  fs::copy_file(file, other);
  {
    const hid_t f = H5Fopen(other.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    const hid_t a = H5Aopen(f, "material_real", H5P_DEFAULT);
    const std::int64_t real[2] = {0, 1};
    H5Awrite(a, H5T_NATIVE_INT64, real);
    H5Aclose(a);
    H5Fclose(f);
  }
  e = error_of(reader(other, ""));
  std::printf("%s\n", e.c_str());
  EXPECT_NE(e.find("cg.yaml:16:"), std::string::npos) << e;
  EXPECT_NE(e.find("has a broken parcel class: material 1 with k = 2 and listed material 1"),
            std::string::npos)
      << e;

  // Copies whose material_names were edited: the parcel class's name says k = 5 (its
  // numbers say 2), or a listed material's name carries a parcel suffix. Which is meant
  // cannot be told: refused as damaged.
  const auto renamed = [&](const std::string& name, const std::string& names) {
    const std::string path = (dir / name).string();
    fs::copy_file(file, path);
    const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    H5Adelete(f, "material_names");
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, names.size());
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t a = H5Acreate2(f, "material_names", type, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, type, names.c_str());
    H5Aclose(a);
    H5Sclose(space);
    H5Tclose(type);
    H5Fclose(f);
    return path;
  };
  e = error_of(reader(renamed("renamed_class.h5", "glass,glass[k=5]"), ""));
  std::printf("%s\n", e.c_str());
  EXPECT_NE(e.find("cg.yaml:16:"), std::string::npos) << e;
  EXPECT_NE(e.find("names its material 1 'glass[k=5]' (root attribute material_names), but its "
                   "class is parcels of k = 2 of material 'glass' (material_coarse_grain, "
                   "material_real), named 'glass[k=2]'"),
            std::string::npos)
      << e;
  e = error_of(reader(renamed("renamed_listed.h5", "glass[k=2],glass[k=2]"), ""));
  std::printf("%s\n", e.c_str());
  EXPECT_NE(e.find("names its material 0 'glass[k=2]' (root attribute material_names), but its "
                   "class is a listed material (k = 1)"),
            std::string::npos)
      << e;
  // The file as written reads (the check is not a false alarm).
  EXPECT_EQ(error_of(reader(renamed("renamed_same.h5", "glass,glass[k=2]"), "")), "no error");

  // A copy without the classes, as an older grainflow wrote them.
  const std::string old = (dir / "old.h5").string();
  fs::copy_file(file, old);
  {
    const hid_t f = H5Fopen(old.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    H5Adelete(f, "material_coarse_grain");
    H5Adelete(f, "material_real");
    H5Fclose(f);
  }
  e = error_of(reader(old, ""));
  std::printf("%s\n", e.c_str());
  EXPECT_NE(e.find("cg.yaml:16:"), std::string::npos) << e;
  EXPECT_NE(e.find("holds coarse-grained parcels (its dataset /coarse_grain has k != 1) but not "
                   "their classes"),
            std::string::npos)
      << e;
}

// 8. A restart whose scene changed coarse_grain since the checkpoint: the parcels would keep
//    their radii and masses (which every record rule accepts) and continue with another k.
//    Refused naming the checkpoint, the attributes and the material index; the unchanged
//    scene restarts and ends.
TEST(CoarseGrain, RestartRefusesAChangedFactor) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "coarse_grain_restart";
  fs::remove_all(dir);
  const auto scene = [](const std::string& k) {
    Scene s =
        parse_scene(scene_text(lone_parcel(1e-4, "    coarse_grain: " + k + "\n"), 1e-4,
                               "output: {snapshot_interval: 0.001, checkpoint_interval: 0.001, "
                               "progress: false}\n"),
                    "restart.yaml");
    s.time.end = 0.002;
    return s;
  };
  RunOptions options;
  options.output_directory = dir.string();
  options.progress = false;
  options.handle_stop_signals = false;
  std::ostringstream log;
  run_scene(scene("2"), options, MPI_COMM_WORLD, log);
  std::string checkpoint;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind("checkpoint_", 0) == 0) checkpoint = e.path().string();
  ASSERT_FALSE(checkpoint.empty()) << log.str();
  options.restart = checkpoint;
  std::string e = "no error";
  try {
    run_scene(scene("3"), options, MPI_COMM_WORLD, log);
  } catch (const std::exception& x) {
    e = x.what();
  }
  std::printf("%s\n", e.c_str());
  // The checkpoint's record of the run's insertions names the fill and the key.
  EXPECT_NE(e.find(": error: insert[0] (fill) is not the insertion the run that wrote "
                   "checkpoint '" +
                   checkpoint + "' had: coarse_grain is 3 here, 2 in that run"),
            std::string::npos)
      << e;
  // A checkpoint without that record (written before it): the parcel classes, as attributes.
  const fs::path old = dir / "without_record.h5";
  fs::copy_file(checkpoint, old);
  {
    const hid_t f = H5Fopen(old.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    EXPECT_GE(H5Ldelete(f, "/streams/insertions", H5P_DEFAULT), 0);
    H5Fclose(f);
  }
  options.restart = old.string();
  e = "no error";
  try {
    run_scene(scene("3"), options, MPI_COMM_WORLD, log);
  } catch (const std::exception& x) {
    e = x.what();
  }
  EXPECT_NE(e.find(old.string() + ": error: attributes 'material_coarse_grain', 'material_real' "
                                  "of the root group: material index 1 was parcels of k = 2 of "
                                  "listed material 0 when the checkpoint was written, but in "
                                  "restart.yaml it is 'glass[k=3]', parcels of k = 3 of listed "
                                  "material 0"),
            std::string::npos)
      << e;
  // coarse_grain taken out (k = 1): the class is gone, which the same attributes name, not a
  // damaged file.
  e = "no error";
  try {
    run_scene(scene("1"), options, MPI_COMM_WORLD, log);
  } catch (const std::exception& x) {
    e = x.what();
  }
  EXPECT_NE(e.find("material index 1 was parcels of k = 2 of listed material 0 when the "
                   "checkpoint was written (attribute 'material_coarse_grain'), but restart.yaml "
                   "has only 1 material index(es): the scene's materials or coarse_grain changed "
                   "since"),
            std::string::npos)
      << e;
  options.restart = checkpoint;
  std::ostringstream again;
  EXPECT_NO_THROW(run_scene(scene("2"), options, MPI_COMM_WORLD, again));
  EXPECT_NE(again.str().find("done: "), std::string::npos) << again.str();
}

}  // namespace
}  // namespace grainflow
