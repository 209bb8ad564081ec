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

// PredictedDashpot: contact.dashpot_velocity: predicted (the sweeps then hand the law the
// predicted end-of-step velocities as well as the half-step ones: the normal dashpot is
// integrated over the step's cell, cell_dashpot(), the others see the predicted velocity; with
// false, every dashpot sees the half-step velocity, as plain velocity Verlet).
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
  // g.v_pred, g.w_pred (contact.dashpot_velocity: half-step, or predicted at the step's end;
  // with predicted, the normal dashpot is cell_dashpot()). The springs advance over
  // `spring_dt`: dt in a step, 0 in the evaluation of the initial state, whose springs have
  // not moved yet (Simulation::initialise); dt alone sizes the dashpot's cell.
  template <class V, class PC>
  [[gnu::always_inline]] static ContactResultT<V> evaluate(const ContactGeometryT<V>& g,
                                                           const PC& pc, const ContactConstants& cc,
                                                           V3<V>& tangential, V3<V>& rolling,
                                                           double dt, double spring_dt) {
    const SpringDashpotT<V> s = Normal::coefficients(pc, cc, g.r_star, g.m_star, g.overlap);
    const V vn = dot(g.v_pred, g.n);
    V fn;
    [[maybe_unused]] V fn_prev{};  // predicted: the previous step's normal force (cell_dashpot)
    if constexpr (PredictedDashpot)
      fn = s.kn * g.overlap + cell_dashpot(g, s, dt, fn_prev);
    else
      fn = s.kn * g.overlap - s.gn * vn;
    const V fn_pos = max0(fn);
    V fn_total = fn;
    if constexpr (Cohesion::enabled) fn_total -= Cohesion::force(g, pc.cohesion_energy_density);

    ContactResultT<V> r{fn_total * g.n, zero3<V>(), zero3<V>()};
    if constexpr (Tangential::enabled) {
      const V3<V> vt = g.v_rel - dot(g.v_rel, g.n) * g.n;
      const V3<V> vt_pred = g.v_pred - vn * g.n;
      V3<V> ft;
      if constexpr (PredictedDashpot) {
        TangentialCell<V> cell = tangential_cell(g, fn, fn_prev, pc.friction, dt);
        if (spring_dt == 0.0) cell.spring_time = V{};  // the initial state: springs unmoved
        ft = Tangential::template cell_force<V>(vt, vt_pred, s.kt, s.gt, cell, g.n, tangential,
                                                dt);
      } else {
        ft = Tangential::template force<V>(vt, vt_pred, s.kt, s.gt, pc.friction * fn_pos, g.n,
                                           tangential, spring_dt);
      }
      r.force += ft;
      const V3<V> n_x_ft = cross(g.n, ft);
      r.torque_i = -g.arm_i * n_x_ft;
      r.torque_j = -g.arm_j * n_x_ft;
    }
    if constexpr (Rolling::enabled) {
      const double m_max = pc.rolling_friction * g.r_star * fn_pos;
      const Vec3 m = Rolling::torque(g, m_max, s.kn, pc.rolling_friction, cc, rolling, spring_dt);
      r.torque_i += m;
      r.torque_j -= m;
    }
    return r;
  }
  // A step's evaluation: the springs advance over dt.
  template <class V, class PC>
  [[gnu::always_inline]] static ContactResultT<V> evaluate(const ContactGeometryT<V>& g,
                                                           const PC& pc, const ContactConstants& cc,
                                                           V3<V>& tangential, V3<V>& rolling,
                                                           double dt) {
    return evaluate(g, pc, cc, tangential, rolling, dt, dt);
  }

  // The normal dashpot force of contact.dashpot_velocity: predicted: its impulse over the
  // step's cell [t - dt/2, t + dt/2] divided by dt (docs/models/contact-models.md,
  // "Integration"). The dashpot force gamma_n(delta) d(delta)/dt is the time derivative of
  // Phi(delta) = int_0^delta gamma_n (Normal::dashpot_potential), so its impulse over the cell
  // is Phi(delta(t + dt/2)) - Phi(delta(t - dt/2)), with Phi = 0 out of contact. Velocity
  // Verlet drifts in straight lines, so the overlap at the cell's edges follows from the
  // approach rates u = -v.n: the half-step one u_h of the drift just made (exact), and the
  // next drift's, predicted from the predicted end-of-step velocity (u_s) and corrected once
  // for the change of this contact's own force since the last step. Where the contact began
  // during the last drift the cell's impulse counts from first touch (Phi(0)); where the
  // half-step velocity lets it end during the next drift, to the last touch, and the step
  // after, if the contact still holds, counts on from zero (both sides reconstruct the
  // decision from the half-step and predicted velocities alone: no state is kept). The
  // impulses then telescope: over a contact they sum to Phi's change, to the prediction's
  // third-order error per step, and a contact that starts or ends part-way through a step
  // gets the impulse of the part it lasts.
  // `f_prev` receives the previous step's force of this contact (spring and cell dashpot; 0
  // if the contact began during the last drift), for tangential_cell().
  template <class V>
  [[gnu::always_inline]] static V cell_dashpot(const ContactGeometryT<V>& g,
                                               const SpringDashpotT<V>& s, double dt, V& f_prev) {
    const double h = 0.5 * dt;
    const V d = g.overlap;
    const auto phi = [&](V x) { return Normal::dashpot_potential(s, d, max0(x)); };
    const V uh = -dot(g.v_rel, g.n);   // over the last drift
    const V us = -dot(g.v_pred, g.n);  // predicted at the step's end
    const V up = 3.0 * uh - 2.0 * us;  // over the drift before (u_h - dt du/dt)
    const V d_prev = d - dt * uh;      // the overlap one step ago
    const auto in_prev = d_prev > 0.0;
    // The step before decided the contact ends within its next drift (then it took the
    // dashpot's impulse down to zero overlap, and this cell counts from zero).
    const auto ended_prev = 0.0 > d_prev + dt * up;
    const V phi_left = phi(d - h * uh);  // Phi at the cell's left edge
    const V lo = select(in_prev, select(ended_prev, V{}, phi_left), V{});
    // The previous step's own force (spring and cell dashpot), for the correction.
    const V lo_prev = select(d_prev - dt * up > 0.0, phi(d_prev - h * up), V{});
    f_prev = select(in_prev,
                            Normal::spring_force(s, d, max0(d_prev)) +
                                (select(ended_prev, V{}, phi_left) - lo_prev) * (1.0 / dt),
                            V{});
    const auto ends = 0.0 > d + dt * uh;  // ends within the next drift
    // The next drift's approach rate: predicted, then corrected once for the change of this
    // contact's force (du/dt = that of the last step minus the change over m*).
    const V accel = (us - uh) * (1.0 / h);
    const V u0 = 2.0 * us - uh;
    const V f0 = s.kn * d + (select(ends, V{}, phi(d + h * u0)) - lo) * (1.0 / dt);
    const V u1 = uh + dt * (accel - (f0 - f_prev) / g.m_star);
    const V hi = select(ends, V{}, phi(d + h * u1));
    return (hi - lo) * (1.0 / dt);
  }

  // What the tangential spring-dashpot of contact.dashpot_velocity: predicted needs to
  // integrate its impulse over the step's cell [t - dt/2, t + dt/2] (docs/models/
  // contact-models.md, "Integration"; TangentialCell, tangential.hpp). The contact began
  // during the last drift if the overlap one step ago, delta - dt u_h, was <= 0: then it has
  // lasted delta / u_h (the drift is straight), the spring's first increment and the left part
  // of the cell. Where F_n > 0 within the cell follows from the line through the previous
  // step's normal force and this one's (both cell averages, so the line's zero, where the
  // Coulomb limit cuts the tangential force, is placed to O(dt^2)); the Coulomb limit is mu
  // times the cell average of max(F_n, 0) along that line.
  template <class V, class F>
  [[gnu::always_inline]] static TangentialCell<V> tangential_cell(const ContactGeometryT<V>& g,
                                                                  V fn, V fn_prev, F friction,
                                                                  double dt) {
    const double h = 0.5 * dt;
    const V zero{}, one = V{} + 1.0;
    const V uh = -dot(g.v_rel, g.n);
    const auto in_prev = g.overlap - dt * uh > 0.0;
    // Since first touch (u_h >= delta / dt > 0 where the contact is new).
    const V since = select(in_prev, V{} + dt, g.overlap / select(in_prev, one, uh));
    // F_n at the cell's edges on the line (t - dt, fn_prev), (t, fn); where the contact is
    // new, fn_prev = 0 and the left part counts from first touch, where F_n > 0.
    const V fa = 0.5 * (fn + fn_prev), fb = 1.5 * fn - 0.5 * fn_prev;
    // The fraction of a segment from a to b on which the line is positive, and the mean of
    // max(line, 0) over it.
    const auto positive = [&](V a, V b) {
      return select(a > 0.0, select(b > 0.0, one, a / (a - b)),
                    select(b > 0.0, b / (b - a), zero));
    };
    const auto mean_positive = [&](V a, V b) {
      return select(a > 0.0, select(b > 0.0, 0.5 * (a + b), a * a / (2.0 * (a - b))),
                    select(b > 0.0, b * b / (2.0 * (b - a)), zero));
    };
    TangentialCell<V> c;
    c.in_prev = select(in_prev, one, zero);
    c.spring_time = since;
    c.left = select(in_prev, h * positive(fa, fn), select(fn > 0.0, since, zero));
    c.right = h * positive(fn, fb);
    const V mean_left = select(in_prev, mean_positive(fa, fn), max0(fn));
    c.limit = friction * 0.5 * (mean_left + mean_positive(fn, fb));
    c.limit_now = friction * max0(fn);
    // Tangential effective mass of solid spheres touching at their surface: 1/m_t =
    // 1/m* + a_i^2/I_i + a_j^2/I_j ~ (1 + 5/2)/m* (I = 2 m r^2 / 5, arms ~ radii).
    c.inv_mass = 3.5 / g.m_star;
    return c;
  }

  // The normal part of evaluate()'s force on i, as its component along g.n (the same
  // operations on the same velocities, so the same value): for contact reports, which split
  // the force. The dashpot reads g.v_pred, or integrates over the step's cell (predicted), as
  // evaluate() does; g.v_rel is not set for every law.
  template <class PC>
  static double normal_force(const ContactGeometry& g, const PC& pc, const ContactConstants& cc,
                             double dt) {
    const SpringDashpot s = Normal::coefficients(pc, cc, g.r_star, g.m_star, g.overlap);
    double fn;
    if constexpr (PredictedDashpot) {
      double fn_prev = 0;
      fn = s.kn * g.overlap + cell_dashpot(g, s, dt, fn_prev);
    } else {
      fn = s.kn * g.overlap - s.gn * dot(g.v_pred, g.n);
    }
    if constexpr (Cohesion::enabled) return fn - Cohesion::force(g, pc.cohesion_energy_density);
    return fn;
  }
};

}  // namespace grainflow
