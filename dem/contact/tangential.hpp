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
};

}  // namespace grainflow
