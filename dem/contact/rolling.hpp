#pragma once
// Rolling-resistance slot. Both models act on the rolling part of the relative
// angular velocity, w_r = w_rel - (w_rel . n) n (twisting about n is not rolling), and
// are limited by M_max = mu_r R* F_n.
// - cdt: constant directional torque M = -M_max w_r/|w_r| (Ai et al. 2011, model A).
// - epsd: elastic-plastic spring-dashpot (Ai et al. 2011, model C): k_r = 2.25 k_n mu_r^2 R*^2,
//   M_k <- M_k - k_r w_r dt limited to M_max; damping M_d = -C_r w_r with
//   C_r = eta_r 2 sqrt(I_r k_r), switched off once the spring is fully mobilised. The spring
//   turns with the half-step w_r (midpoint rule), the dashpot sees ContactGeometry::w_pred.
//   CDT's direction is that of the half-step w_r.
#include <cmath>

#include "dem/contact/contact_geometry.hpp"

namespace grainflow {

struct NoRolling {
  static constexpr bool enabled = false;
  static constexpr bool needs_inertia = false;
  static constexpr const char* name = "none";
};

// Relative to |w_rel|: below it, w_r is rounding (CdtRolling).
constexpr double kRollingRoundOff = 1e-12;

struct CdtRolling {
  static constexpr bool enabled = true;
  static constexpr bool needs_inertia = false;
  static constexpr const char* name = "cdt";
  static Vec3 torque(const ContactGeometry& g, double m_max, double /*kn*/, double /*mu_r*/,
                     const ContactConstants&, Vec3& /*history*/, double /*dt*/) {
    const Vec3 wr = g.w_rel - g.w_rel.dot(g.n) * g.n;
    const double w = wr.norm();
    // A rolling part at the round-off of the relative spin is none: the spin about n of a
    // sphere on a turntable, or spinning on a tilted plane, leaves |w_r| ~ 1e-16 |w_rel|
    // pointing anywhere (|n| = 1 only to rounding), and the full torque in its direction spun
    // a sphere resting on a turntable's axis up to 9 rad/s in 0.1 s.
    if (!(w > kRollingRoundOff * g.w_rel.norm())) return Vec3::Zero();
    return (-m_max / w) * wr;
  }
};

struct EpsdRolling {
  static constexpr bool enabled = true;
  static constexpr bool needs_inertia = true;
  static constexpr const char* name = "epsd";
  static Vec3 torque(const ContactGeometry& g, double m_max, double kn, double mu_r,
                     const ContactConstants& cc, Vec3& spring, double dt) {
    const Vec3 wr = g.w_rel - g.w_rel.dot(g.n) * g.n;
    const Vec3 wr_pred = g.w_pred - g.w_pred.dot(g.n) * g.n;
    const double kr = 2.25 * kn * mu_r * mu_r * g.r_star * g.r_star;
    rotate_into_tangent_plane(spring, g.n);
    spring -= kr * dt * wr;
    const double s2 = spring.squaredNorm();
    if (s2 > m_max * m_max) {
      spring *= m_max / std::sqrt(s2);
      return spring;  // fully mobilised: no damping (Ai et al. 2011, f = 0)
    }
    const double cr = cc.epsd_damping_ratio * 2 * std::sqrt(g.roll_inertia * kr);
    return spring - cr * wr_pred;
  }
};

}  // namespace grainflow
