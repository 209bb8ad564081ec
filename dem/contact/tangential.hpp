#pragma once
// Tangential slot. `history`: incremental spring with Coulomb limit
// (Cundall & Strack 1979; Mindlin 1949 stiffness via the normal slot):
//   xi <- xi rotated into the current tangent plane, xi += v_t dt,
//   F_t = -k_t xi - gamma_t v_t*, and if |F_t| > mu F_n: F_t scaled to mu F_n, and the
//   spring-dashpot, in series with the slider, relaxes towards xi = -F_t / k_t (slid_spring).
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
    const V3<V> xi_start = xi;
    xi += vt * dt;
    V3<V> ft = -kt * xi - gt * vt_pred;
    const V f2 = squared_norm(ft);
    const auto sliding = f2 > coulomb_limit * coulomb_limit;
    if (any(sliding)) {  // lanes that stick keep ft and xi
      const V3<V> ft_slip = ft * (coulomb_limit / lane_sqrt(f2));
      xi = select(sliding, slid_spring(xi_start, ft_slip, coulomb_limit, vt_pred, kt, gt, dt), xi);
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
    const V3<V> xi_start = xi;
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
      xi = select(sliding, slid_spring(xi_start, f_slip, c.limit_now, v_end, kt, gt, c.spring_time),
                  xi);
    }
    return ft;
  }

  // The spring after a step of sliding with the Coulomb limit `limit` (docs/models/
  // contact-models.md, "Tangential slot"): the spring and the dashpot in parallel, in series
  // with the Coulomb slider. While it slides, the slider carries the force f, so
  // -k xi - gamma dxi/dt = f: the spring relaxes from xi_start towards -f / k with the time
  // constant tau = gamma / k, and the slip takes the rest of v_t. Over the step h,
  // xi = -f/k + (xi_start + f/k) rho, with rho the L-stable (2,0) Pade approximant of
  // exp(-h / tau), 1 / (1 + a + a^2 / 2), a = h / tau; without a dashpot, xi = -f/k (Cundall
  // & Strack). The spring does not store the dashpot's share gamma v_t, which, where k and
  // gamma grow with the overlap (Hertz), pulled the next step's trial force inside the
  // Coulomb limit while the contact still slid.
  // With no normal load (limit 0: the normal dashpot's pull at the end of a contact) the
  // spring is set so that the spring-dashpot's force at v_t is zero, xi = -gamma v_t / k: if the
  // normal force comes back (it does not in the continuous contact, but the discrete normal
  // dashpot can bring it back for a step at low restitution) the tangential force resumes
  // from zero, as the continuous contact's, which has ended, does.
  template <class V, class H>
  [[gnu::always_inline]] static V3<V> slid_spring(const V3<V>& xi_start, const V3<V>& f, V limit,
                                                  const V3<V>& v, V k, V gamma, H h) {
    const V kh = k * h;  // h = 0 (the springs of the initial state): no relaxation
    const V rho =
        select(kh > 0.0, gamma * gamma / (gamma * gamma + gamma * kh + 0.5 * kh * kh), V{} + 1.0);
    const V3<V> rest = f / (-k);
    return select(limit > 0.0, V3<V>(rest + (xi_start - rest) * rho), V3<V>(v * (-gamma / k)));
  }
};

}  // namespace grainflow
