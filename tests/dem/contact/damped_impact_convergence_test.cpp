// Damped impacts converge at second order in dt with `contact.dashpot_velocity: predicted`,
// impact by impact: the normal dashpot's impulse is that of the step's cell [t - dt/2,
// t + dt/2], so a contact that begins or ends part-way through a step gets the impulse of the
// part it lasts (docs/models/contact-models.md, "Integration").
//
// Reference: a Hooke sphere-wall impact is a damped linear oscillator whose contact ends
// when the overlap returns to zero; its restitution and contact time are the closed forms
//   e = exp(-zeta pi / sqrt(1 - zeta^2)),  t_c = pi / sqrt(k_n/m - (gamma_n/2m)^2),
// zeta = gamma_n / (2 sqrt(m k_n)), which the damping gamma_n = sqrt(4 m k_n / (1 +
// (pi/ln e)^2)) of normal_hooke.hpp makes the requested e. A Hertz impact's reference is the
// requested e as well: the restitution mapping (restitution_mapping.hpp) integrates the scaled
// impact to 1e-9.
//
// Each point is the root mean square of the relative error over 32 impacts: 8 first-touch
// offsets spread evenly within a step x 4 contact lengths spread over N - 1/2 ... N + 1/2 steps
// (where contact begins and ends between two steps is random in a flow). The test follows it
// from N = 20 to 40 steps per impact: second order quarters it (slope 2); with the dashpot at
// the half-step velocity (the default, half_step) or at the predicted velocity alone (the
// start and end of contact sampled at an arbitrary offset) the rms falls as 1/N to N^-1.3.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "dem/engine/simulation.hpp"
#include "dem/engine/time_step.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

constexpr double kY = 5e7, kNu = 0.25, kRho = 2500, kR = 1e-3, kV = 1.0;

// One Simulation for every impact of a (law, e): the sphere is put back in free flight
// before each, so the start-up work (the restitution mapping) is done once.
class Rig {
 public:
  Rig(NormalModel model, double e) : sim_(scene(model, e), false) {
    sim_.particles().add(1, Vec3(kR + 1e-3, 0, 0), Vec3(-kV, 0, 0), Vec3::Zero(), kR, 0, kRho);
    sim_.set_dt(1e-6);
    sim_.initialise();
  }
  struct Impact {
    double restitution, contact_time;
  };
  // Rebound speed / approach speed and contact time of an impact whose first touch falls
  // `phase` into the second step after the reset.
  Impact impact(double dt, double phase) {
    Particles& p = sim_.particles();
    const double t0 = (1.0 + phase) * dt;
    p.x[0] = Vec3(kR + kV * t0, 0, 0);
    p.v[0] = Vec3(-kV, 0, 0);
    p.force[0].setZero();
    sim_.set_dt(dt);
    bool touched = false;
    for (long n = 0; n < 1'000'000; ++n) {
      sim_.step();
      const double d = kR - p.x[0][0];
      if (d > 0)
        touched = true;
      else if (touched)  // free flight since the last drift: it crossed d = 0 at t + d/v
        return {p.v[0][0] / kV, (n + 1) * dt + d / p.v[0][0] - t0};
    }
    ADD_FAILURE() << "contact did not end";
    return {0, 0};
  }

 private:
  static Scene scene(NormalModel model, double e) {
    Scene s = test::one_material_scene(kY, kNu, kRho, e);
    s.contact.normal = model;
    s.contact.dashpot_velocity = DashpotVelocity::predicted;
    if (model == NormalModel::hooke) s.contact.hooke_characteristic_velocity = kV;
    s.domain.lo = Vec3(-0.01, -0.01, -0.01);
    s.domain.hi = Vec3(0.03, 0.01, 0.01);
    s.time.max_overlap = 1;
    s.walls.push_back(test::plane(Vec3::Zero(), Vec3::UnitX()));
    return s;
  }
  Simulation sim_;
};

// Contact time of the impact, for choosing dt = t_c / N. Hooke: the damped oscillator
// pi / sqrt(k/m - (gamma/2m)^2); Hertz: the elastic closed form (Johnson 1985, §11.4), as
// `grain check` counts steps per impact.
double contact_time(NormalModel model, double e) {
  const double m = kRho * sphere_volume(kR);
  const double y_star = kY / (2 * (1 - kNu * kNu));  // wall of the sphere's material
  if (model == NormalModel::hertz) return hertz_contact_time(y_star, kR, m, kV);
  const double sr = std::sqrt(kR);
  const double k = (16.0 / 15.0) * sr * y_star * std::pow(15.0 * m * kV * kV / (16.0 * sr * y_star), 0.2);
  const double zeta = e >= 1 ? 0 : 1.0 / std::sqrt(1 + std::pow(std::numbers::pi / std::log(e), 2));
  return std::numbers::pi / std::sqrt(k / m * (1 - zeta * zeta));
}

struct Case {
  NormalModel model;
  double e;
  double max_rms_at_22;  // restitution error allowed at 22 steps per impact
};

struct Errors {
  double restitution, contact_time;  // rms of the relative errors
};

Errors rms_errors(Rig& rig, const Case& c, double steps) {
  constexpr int kPhases = 8, kLengths = 4;
  const double tc = contact_time(c.model, c.e);
  double se = 0, st = 0;
  for (int j = 0; j < kLengths; ++j) {
    const double dt = tc / (steps + (j + 0.5) / kLengths - 0.5);
    for (int k = 0; k < kPhases; ++k) {
      const Rig::Impact r = rig.impact(dt, (k + 0.5) / kPhases);
      se += std::pow(r.restitution / c.e - 1, 2);
      st += std::pow(r.contact_time / tc - 1, 2);
    }
  }
  return {std::sqrt(se / (kPhases * kLengths)), std::sqrt(st / (kPhases * kLengths))};
}

class DampedImpactConvergence : public ::testing::TestWithParam<Case> {};

TEST_P(DampedImpactConvergence, ImpactErrorsFallAtSecondOrder) {
  const Case c = GetParam();
  Rig rig(c.model, c.e);
  const Errors at22 = rms_errors(rig, c, 22), coarse = rms_errors(rig, c, 20),
               fine = rms_errors(rig, c, 40);
  const double slope_e = std::log2(coarse.restitution / fine.restitution);
  const double slope_t = std::log2(coarse.contact_time / fine.contact_time);
  std::printf("%s e = %.1f: rms restitution error %.3e at 22 steps per impact; %.3e at 20, "
              "%.3e at 40: slope %.2f\n",
              c.model == NormalModel::hooke ? "hooke" : "hertz", c.e, at22.restitution,
              coarse.restitution, fine.restitution, slope_e);
  if (c.model == NormalModel::hooke)
    std::printf("hooke e = %.1f: rms contact-time error %.3e at 20, %.3e at 40: slope %.2f\n", c.e,
                coarse.contact_time, fine.contact_time, slope_t);
  EXPECT_GE(slope_e, 1.8);
  EXPECT_LE(at22.restitution, c.max_rms_at_22);
  // The contact time's closed form is the damped oscillator's (Hooke); for Hertz the elastic
  // closed form only sets N (the damped one needs an integration: accuracy_cost).
  if (c.model == NormalModel::hooke) {
    EXPECT_GE(slope_t, 1.8);
  }
}

// The bounds at 22 steps per impact: Hertz e = 0.5 and 0.1 at the targets of issue 24 (0.1 %
// and 1 %); Hooke, whose force jumps at first touch and separation, at about 1.5x its measured
// error.
INSTANTIATE_TEST_SUITE_P(Laws, DampedImpactConvergence,
                         ::testing::Values(Case{NormalModel::hooke, 0.9, 2e-3},
                                           Case{NormalModel::hooke, 0.5, 2.5e-3},
                                           Case{NormalModel::hooke, 0.1, 8e-3},
                                           Case{NormalModel::hertz, 0.9, 1e-3},
                                           Case{NormalModel::hertz, 0.5, 1e-3},
                                           Case{NormalModel::hertz, 0.1, 1e-2}),
                         [](const ::testing::TestParamInfo<Case>& param_info) {
                           const Case& c = param_info.param;
                           return std::string(c.model == NormalModel::hooke ? "Hooke" : "Hertz") +
                                  "_e0" + std::to_string(static_cast<int>(c.e * 10 + 0.5));
                         });

}  // namespace
}  // namespace grainflow
