#pragma once
// Time-step limits of a scene: the Rayleigh time of the smallest particle of each
// material, t_R = pi r sqrt(rho/G) / (0.1631 nu + 0.8766), G = Y / (2 (1 + nu))
// (Li et al. 2005; Thornton's form), and the contact time of the fastest expected
// impact between the smallest particles (and particle-wall):
//   Hertz: t_c = 2.868 (m*^2 / (R* Y*^2 v))^{1/5}   (elastic; damping lengthens it)
//   Hooke: t_c = pi / sqrt(k_n/m* - (gamma_n / 2 m*)^2)
#include <algorithm>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "dem/contact/contact_geometry.hpp"
#include "dem/contact/pair_coefficients.hpp"
#include "dem/core/particles.hpp"
#include "dem/engine/time_step_accuracy.hpp"
#include "dem/scene/scene.hpp"

namespace grainflow {

struct TimeStepReport {
  double rayleigh_time = 0;  // smallest over materials present
  double contact_time = 0;   // smallest over material pairs present, at expected_max_speed
  double dt = 0;
  // The step the check recommends (its `use dt <=` / `is recommended` figure): at most
  // kWarnRayleighFraction t_R and kWarnStepsPerContact steps per impact [s].
  double recommended_step = 0;
  // Measured impact errors at dt (docs/accuracy-vs-cost.md) for the material pair (or
  // particle-wall pair) whose restitution suffers most at its steps per impact and e.
  std::optional<ImpactAccuracy> accuracy;
  enum class Verdict { ok, warn, refuse } verdict = Verdict::ok;
  // The smallest step that the refusing checks propose (each its `use dt <=` figure), so
  // that the final refusal names one step that every limit allows; infinity without one.
  double refusal_step = std::numeric_limits<double>::infinity();
  void refuse_above(double proposed_step) {
    verdict = Verdict::refuse;
    refusal_step = std::min(refusal_step, proposed_step);
  }
  std::vector<std::string> notes;  // human-readable findings, one per line
};

// Thresholds: warn above 0.3 t_R or below 10 steps per impact (restitution and
// peak force then err by a few %, docs/models/contact-models.md),
// refuse above 1.0 t_R or t_c/5 — such a run cannot resolve a contact at all.
constexpr double kWarnRayleighFraction = 0.3;
constexpr double kRefuseRayleighFraction = 1.0;
constexpr double kWarnStepsPerContact = 10;
constexpr double kRefuseStepsPerContact = 5;

double rayleigh_time(const Material& m, double radius);
double hertz_contact_time(double y_star, double r_star, double m_star, double speed);
// The contact time of a pair under the scene's normal law (Hertz at approach speed v; Hooke,
// damped, independent of v; infinity for an overdamped Hooke contact).
double pair_contact_time(const ContactSettings& cs, const PairCoefficients& pc,
                         const ContactConstants& cc, double r_star, double m_star, double v);
// The speed at first touch of a free head-on impact (no load, no cohesion) that passes
// `overlap` [m] approaching at `speed` [m/s], under the pair's damped normal law: the
// dimensionless damped approach (RK4, as for the overlap guard's speed in grain check) is one
// curve for every impact speed, scaled by the elastic peak overlap.
double damped_impact_speed(const ContactSettings& cs, const PairCoefficients& pc,
                           const ContactConstants& cc, double r_star, double m_star, double overlap,
                           double speed);

// `restart_step`: the step of the checkpoint a restart continues with (Simulation::restore),
// which the report then judges and prints instead of the scene's, and says so: its smallest
// particle may have left, so time.rayleigh_fraction would give another step now.
TimeStepReport check_time_step(const Scene& scene, const Particles& p, const PairTable& table,
                               const ContactConstants& constants,
                               std::optional<double> restart_step = std::nullopt);

}  // namespace grainflow
