#pragma once
// Tangential slot. `history`: incremental spring with Coulomb limit
// (Cundall & Strack 1979; Mindlin 1949 stiffness via the normal slot):
//   xi <- xi rotated into the current tangent plane, xi += v_t dt,
//   F_t = -k_t xi - gamma_t v_t*, and if |F_t| > mu F_n: F_t scaled to mu F_n and xi reset to
//   the spring length consistent with it (xi = -(F_t + gamma_t v_t*) / k_t).
// v_t is the half-step tangential velocity (the spring's increment over the step: midpoint
// rule), v_t* the one the dashpot sees (ContactGeometry::v_pred).
#include "dem/contact/contact_geometry.hpp"

namespace grainflow {

// contact.dashpot_velocity: predicted: the parts of the step's cell [t - dt/2, t + dt/2] over
// which the tangential force acts (ContactLaw::tangential_cell): in contact with F_n > 0.
template <class V>
struct TangentialCell {
  V in_prev;      // 1 if the contact held one step ago, else 0 (it began during the last drift)
  V spring_time;  // time in contact during the last drift: dt, or since first touch
  V left, right;  // time with F_n > 0 in [t - dt/2, t] (from first touch if new), [t, t + dt/2]
  V limit;        // Coulomb limit on the cell's mean force: mu x mean of max(F_n, 0) over the cell
  V limit_now;    // on the spring at t: mu max(F_n, 0)
  V inv_mass;     // 1 / the contact's tangential effective mass
};

struct NoTangential {
  static constexpr bool enabled = false;
  static constexpr const char* name = "none";
};

struct HistoryTangential {
  static constexpr bool enabled = true;
  static constexpr const char* name = "history";
  template <class V>
  [[gnu::always_inline]] static V3<V> force(const V3<V>& vt, const V3<V>& vt_pred, V kt, V gt,
                                            V coulomb_limit, const V3<V>& n, V3<V>& xi,
                                            double dt) {
    rotate_into_tangent_plane(xi, n);
    xi += vt * dt;
    V3<V> ft = -kt * xi - gt * vt_pred;
    const V f2 = squared_norm(ft);
    const auto sliding = f2 > coulomb_limit * coulomb_limit;
    if (any(sliding)) {  // lanes that stick keep ft and xi
      const V3<V> ft_slip = ft * (coulomb_limit / lane_sqrt(f2));
      xi = select(sliding, V3<V>(-(ft_slip + gt * vt_pred) / kt), xi);
      ft = select(sliding, ft_slip, ft);
    }
    return ft;
  }

  // contact.dashpot_velocity: predicted (docs/models/contact-models.md, "Integration"): the
  // force whose impulse over the step's cell is that of the spring-dashpot over the parts of
  // the cell in contact with F_n > 0 (c.left, c.right), and the spring's increment over the
  // last drift counts only the time in contact (c.spring_time).
  // The dashpot sees v_e, the end-of-step velocity with this contact's own dashpot's change
  // over the step taken implicitly: v_e = v* + theta (dt / m_t)(F_d(t + dt) - F_d(t)) with
  // F_d(t + dt) = -gamma_t v_e and F_d(t) = -gamma_t v(t), v(t) = 2 v_h - v*, so
  // v_e = (v* (1 - theta x) + 2 theta x v_h) / (1 + theta x), x = gamma_t dt / m_t.
  // theta = 1/2 is the trapezoidal rule (v_e = v(t + dt) to O(dt^3) per step), stable for
  // x < 2; theta = min(1, 1/2 + x^2/4) keeps that accuracy (theta - 1/2 = O(dt^2)) and is
  // stable down to ~7 steps per impact at e = 0.1, where the tangential oscillator
  // (m_t ~ 2/7 m) is faster than the normal one and over-damped; the explicit v* is stable
  // for x < 1 only.
  // The dashpot's impulse over the cell is -gamma_t (v_h left + v_n right), with
  // v_n = 2 v_e - v_h the next drift's velocity.
  // The cell's force is limited to mu times the cell's mean of max(F_n, 0), which where F_n
  // changes sign within the cell is the Coulomb limit's own impulse; the spring is reset to
  // the sliding length with the limit at t, as in force().
  template <class V>
  [[gnu::always_inline]] static V3<V> cell_force(const V3<V>& vt, const V3<V>& vt_pred, V kt,
                                                 V gt, const TangentialCell<V>& c,
                                                 const V3<V>& n, V3<V>& xi, double dt) {
    rotate_into_tangent_plane(xi, n);
    xi += vt * c.spring_time;
    const V x = gt * dt * c.inv_mass;
    const V theta = 0.5 + 0.25 * x * x;
    const V tx = select(theta > 1.0, x, theta * x);
    const V3<V> v_end = select(c.in_prev > 0.0,
                               V3<V>((vt_pred * (1.0 - tx) + (2.0 * tx) * vt) / (1.0 + tx)), vt_pred);
    const V3<V> v_next = 2.0 * v_end - vt;
    const double inv_dt = 1.0 / dt;
    V3<V> ft = -(kt * inv_dt * (c.left + c.right)) * xi -
               (gt * inv_dt) * (c.left * vt + c.right * v_next);
    const V f2 = squared_norm(ft);
    const auto capped = f2 > c.limit * c.limit;
    if (any(capped)) ft = select(capped, V3<V>(ft * (c.limit / lane_sqrt(f2))), ft);
    const V3<V> f_now = -kt * xi - gt * v_end;
    const V g2 = squared_norm(f_now);
    const auto sliding = g2 > c.limit_now * c.limit_now;
    if (any(sliding)) {
      const V3<V> f_slip = f_now * (c.limit_now / lane_sqrt(g2));
      xi = select(sliding, V3<V>(-(f_slip + gt * v_end) / kt), xi);
    }
    return ft;
  }
};

}  // namespace grainflow
