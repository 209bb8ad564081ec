#pragma once
// A contact law is one choice per slot: normal x tangential x rolling x cohesion
// (DESIGN.md §3). Each combination is its own type, so a slot that is "none"
// compiles to nothing: `if constexpr` removes its code from the force loop.
#include <algorithm>
#include <type_traits>

#include "dem/contact/cohesion.hpp"
#include "dem/contact/contact_geometry.hpp"
#include "dem/contact/normal_hertz.hpp"
#include "dem/contact/normal_hooke.hpp"
#include "dem/contact/pair_coefficients.hpp"
#include "dem/contact/rolling.hpp"
#include "dem/contact/tangential.hpp"

namespace grainflow {

// PredictedDashpot: contact.dashpot_velocity: predicted (the sweeps then hand the dashpots the
// predicted end-of-step velocities; with false, the half-step ones, as plain velocity Verlet).
template <class Normal, class Tangential, class Rolling, class Cohesion,
          bool PredictedDashpot = false>
struct ContactLaw {
  using normal = Normal;
  using tangential = Tangential;
  using rolling = Rolling;
  using cohesion = Cohesion;
  static constexpr bool predicted_dashpot = PredictedDashpot;
  static constexpr bool keeps_tangential = Tangential::enabled;  // a tangential spring
  static constexpr bool keeps_rolling = std::is_same_v<Rolling, EpsdRolling>;  // a rolling one
  static constexpr bool has_history = keeps_tangential || keeps_rolling;
  static constexpr bool needs_spin = Tangential::enabled || Rolling::enabled;
  static constexpr bool needs_roll_inertia = Rolling::needs_inertia;

  // Whether the law also evaluates two contacts at once (V = Lanes2, dem/core/lanes.hpp):
  // the rolling and cohesion slots take one contact at a time.
  static constexpr bool lanes = Normal::lanes && !Rolling::enabled && !Cohesion::enabled;

  // Force on i (and torques on both) for one touching pair, or for the pairs in the lanes of
  // V. The normal force has no lower clamp: the contact ends when the overlap returns to zero,
  // which is the end-of-contact definition the restitution mappings assume. `tangential` and
  // `rolling` are the contact's springs (each touched only by a law that has it).
  // Springs advance with the half-step velocities (g.v_rel, g.w_rel), dashpots take
  // g.v_pred, g.w_pred (contact.dashpot_velocity: half-step, or predicted at the step's end).
  template <class V, class PC>
  [[gnu::always_inline]] static ContactResultT<V> evaluate(const ContactGeometryT<V>& g,
                                                           const PC& pc, const ContactConstants& cc,
                                                           V3<V>& tangential, V3<V>& rolling,
                                                           double dt) {
    const SpringDashpotT<V> s = Normal::coefficients(pc, cc, g.r_star, g.m_star, g.overlap);
    const V vn = dot(g.v_pred, g.n);
    const V fn = s.kn * g.overlap - s.gn * vn;
    const V fn_pos = max0(fn);
    V fn_total = fn;
    if constexpr (Cohesion::enabled) fn_total -= Cohesion::force(g, pc.cohesion_energy_density);

    ContactResultT<V> r{fn_total * g.n, zero3<V>(), zero3<V>()};
    if constexpr (Tangential::enabled) {
      const V3<V> vt = g.v_rel - dot(g.v_rel, g.n) * g.n;
      const V3<V> vt_pred = g.v_pred - vn * g.n;
      const V3<V> ft = Tangential::template force<V>(vt, vt_pred, s.kt, s.gt, pc.friction * fn_pos,
                                                     g.n, tangential, dt);
      r.force += ft;
      const V3<V> n_x_ft = cross(g.n, ft);
      r.torque_i = -g.arm_i * n_x_ft;
      r.torque_j = -g.arm_j * n_x_ft;
    }
    if constexpr (Rolling::enabled) {
      const double m_max = pc.rolling_friction * g.r_star * fn_pos;
      const Vec3 m = Rolling::torque(g, m_max, s.kn, pc.rolling_friction, cc, rolling, dt);
      r.torque_i += m;
      r.torque_j -= m;
    }
    return r;
  }

  // The normal part of evaluate()'s force on i, as its component along g.n (the same
  // operations, so the same value): for contact reports, which split the force.
  template <class PC>
  static double normal_force(const ContactGeometry& g, const PC& pc, const ContactConstants& cc) {
    const SpringDashpot s = Normal::coefficients(pc, cc, g.r_star, g.m_star, g.overlap);
    const double fn = s.kn * g.overlap - s.gn * dot(g.v_rel, g.n);
    if constexpr (Cohesion::enabled) return fn - Cohesion::force(g, pc.cohesion_energy_density);
    return fn;
  }
};

}  // namespace grainflow
