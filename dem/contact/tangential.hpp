#pragma once
// Tangential slot. `history`: incremental spring with Coulomb limit
// (Cundall & Strack 1979; Mindlin 1949 stiffness via the normal slot):
//   xi <- xi rotated into the current tangent plane, xi += v_t dt,
//   F_t = -k_t xi - gamma_t v_t, and if |F_t| > mu F_n: F_t scaled to mu F_n and xi reset to
//   the spring length consistent with it (xi = -(F_t + gamma_t v_t) / k_t).
#include "dem/contact/contact_geometry.hpp"

namespace grainflow {

struct NoTangential {
  static constexpr bool enabled = false;
  static constexpr const char* name = "none";
};

struct HistoryTangential {
  static constexpr bool enabled = true;
  static constexpr const char* name = "history";
  [[gnu::always_inline]] static Vec3 force(const Vec3& vt, double kt, double gt, double coulomb_limit, const Vec3& n,
                    Vec3& xi, double dt) {
    rotate_into_tangent_plane(xi, n);
    xi += vt * dt;
    Vec3 ft = -kt * xi - gt * vt;
    const double f2 = ft.squaredNorm();
    if (f2 > coulomb_limit * coulomb_limit) {
      ft *= coulomb_limit / std::sqrt(f2);
      xi = -(ft + gt * vt) / kt;
    }
    return ft;
  }
};

}  // namespace grainflow
