#pragma once
// Hertz-Mindlin normal and tangential stiffness with restitution damping.
// S_n = 2 Y* sqrt(R* d), S_t = 8 G* sqrt(R* d), k_n = (4/3) Y* sqrt(R* d), k_t = S_t,
// gamma_{n,t} = 2 sqrt(5/6) b sqrt(S_{n,t} m*)   (Hertz 1881; Mindlin 1949; Tsuji et al. 1992),
// with b mapped exactly to the requested restitution (restitution_mapping.hpp). Since
// S_t / S_n = 4 G*/Y* for every overlap, gamma_t = gamma_n sqrt(4 G*/Y*), the square root
// taken once per material pair (PairCoefficients::hertz_gt_per_gn): two square roots per
// contact instead of three (rounding differs from sqrt(S_t m*) in the last bits).
#include <cmath>

#include "dem/contact/contact_geometry.hpp"
#include "dem/contact/pair_coefficients.hpp"

namespace grainflow {

struct HertzNormal {
  static constexpr const char* name = "hertz";
  static constexpr bool lanes = true;  // also evaluates Lanes2 (dem/core/lanes.hpp)
  template <class V, class PC>
  [[gnu::always_inline]] static SpringDashpotT<V> coefficients(const PC& pc,
                                                               const ContactConstants&, V r_star,
                                                               V m_star, V overlap) {
    constexpr double two_sqrt_5_6 = 1.8257418583505538;  // 2 sqrt(5/6)
    const V a = lane_sqrt(r_star * overlap);
    const V sn = 2 * pc.y_star * a;
    const V st = 8 * pc.g_star * a;
    const V gn = two_sqrt_5_6 * pc.hertz_beta * lane_sqrt(sn * m_star);
    return {(2.0 / 3.0) * sn, gn, st, gn * pc.hertz_gt_per_gn};
  }
  // For the cell-integrated dashpot (contact_law.hpp), from the coefficients `s` at `overlap`:
  // the spring force k_n(x) x = (4/3) Y* sqrt(R*) x^{3/2} at overlap x >= 0, and the
  // dashpot's potential Phi(x) = int_0^x gamma_n(y) dy = (4/5) gamma_n(x) x (gamma_n grows as
  // y^{1/4}), whose change over an interval is the dashpot's impulse over it.
  template <class V>
  [[gnu::always_inline]] static V spring_force(const SpringDashpotT<V>& s, V overlap, V x) {
    return s.kn * x * lane_sqrt(x / overlap);
  }
  template <class V>
  [[gnu::always_inline]] static V dashpot_potential(const SpringDashpotT<V>& s, V overlap, V x) {
    return 0.8 * s.gn * x * lane_sqrt(lane_sqrt(x / overlap));
  }
};

}  // namespace grainflow
