#pragma once
// What a contact can carry within time.max_overlap: the overlap guard's diagnosis
// (docs/stability.md, "The overlap guard"). When a contact passes the limit, either the time
// step is too coarse for the impact (a smaller step resolves it), or the contact is
// overloaded: its approach energy, a load pressing it (weight, cohesion) or a moving wall
// take it beyond the limit whatever the step. The energy balance of the contact tells which:
// from its overlap δ₀ and approach speed v now, an undamped contact under a constant load W
// and the cohesion F_c(δ) stops approaching at the first δ > δ₀ where
//   E_el(δ) − E_el(δ₀) = ½ m* v² + W (δ − δ₀) + ∫_δ₀^δ F_c,
// with E_el = (8/15) Y* √R* δ^{5/2} (Hertz; F = (4/3) Y* √R* δ^{3/2}) or ½ k_n δ² (Hooke).
// A chain (a heavy particle pressing this contact through a light one, ContactLoad::series)
// stores (1 + λ) E_el(δ) in its two contacts, which carry one force, and the load works over
// the driver's travel (1 + λ) δ, where λ is the second contact's overlap per overlap of this
// one (both laws: E₂/E = δ₂/δ at equal force).
// Damping only shortens the approach, so that overlap bounds the damped run's from above.
// Error path only: nothing here runs in a step that passes the guards.
#include <limits>

namespace grainflow {

struct ContactLoad {
  bool hertz = true;
  double y_star = 0;        // Hertz Y* [Pa]
  double kn = 0;            // Hooke k_n [N/m]
  double r_star = 0;        // R* [m]
  double m_star = 0;        // m* [kg]
  double r_small = 0;       // the smaller radius: overlaps are ratios of it [m]
  bool wall = false;        // sphere-wall (SJKR area pi (2 r δ - δ^2)), else sphere-sphere
  double r_i = 0, r_j = 0;  // the radii (sphere-sphere SJKR area)
  double cohesion = 0;      // SJKR energy density k_c [J/m^3]
  double load = 0;          // constant compressive load [N] (weight pressing the contact)
  double speed = 0;         // normal approach speed [m/s] (> 0 approaching)
  double overlap = 0;       // δ₀ [m]
  // A chain: a heavier particle (the driver) presses this contact through the particle
  // between them, by a second contact in series. `m_star`, `speed` and `load` are then the
  // driver's (with the middle particle's own load added); the middle particle is taken as
  // massless, so the two contacts carry one force. `series` is the second contact's
  // overlap per overlap of this one at equal force (k_n/k_n2 for Hooke, (K/K2)^{2/3} for
  // Hertz, K = (4/3) Y* √R*), `series_overlap` its overlap now [m]. 0: a single contact.
  double series = 0;
  double series_overlap = 0;
};

double elastic_force(const ContactLoad& c, double overlap);
double cohesion_force(const ContactLoad& c, double overlap);  // SJKR k_c A(δ)

// The overlap where the contact stops approaching, with its stiffness and cohesion scaled
// by the factors given; infinity when it does not stop before the overlap reaches the
// smaller radius (a ratio of 1, the largest time.max_overlap).
double stopping_overlap(const ContactLoad& c, double stiffness_scale = 1,
                        double cohesion_scale = 1);
// The overlap where the spring alone carries the constant load and the cohesion (the
// contact at rest there stays there); kNoStop when not within the smaller radius.
double equilibrium_overlap(const ContactLoad& c);
// The same contact at its first touch (δ = 0), with the approach speed the energy balance
// gives there: ½ m* v₀² = ½ m* v² + E_el(δ₀) − W δ₀ − ∫₀^δ₀ F_c. What a stiffer material or a
// weaker cohesion would do is asked from there (stiffness_factor_for, cohesion_factor_for).
ContactLoad at_first_touch(const ContactLoad& c);
// The smallest factor on the stiffness (Y* or k_n) that stops the contact within `target`
// (an overlap in m), for a contact given at its first touch; infinity beyond 1e12.
double stiffness_factor_for(const ContactLoad& c, double target);
// The largest factor in [0, 1] on the cohesion that stops it within `target` (a contact at
// its first touch); -1 when even none does.
double cohesion_factor_for(const ContactLoad& c, double target);

inline constexpr double kNoStop = std::numeric_limits<double>::infinity();

}  // namespace grainflow
