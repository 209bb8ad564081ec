#pragma once
// Hertz-Mindlin normal and tangential stiffness with restitution damping.
// S_n = 2 Y* sqrt(R* d), S_t = 8 G* sqrt(R* d), k_n = (4/3) Y* sqrt(R* d), k_t = S_t,
// gamma_{n,t} = 2 sqrt(5/6) b sqrt(S_{n,t} m*)   (Hertz 1881; Mindlin 1949; Tsuji et al. 1992),
// with b mapped exactly to the requested restitution (restitution_mapping.hpp).
#include <cmath>

#include "dem/contact/contact_geometry.hpp"
#include "dem/contact/pair_coefficients.hpp"

namespace grainflow {

struct HertzNormal {
  static constexpr const char* name = "hertz";
  [[gnu::always_inline]] static SpringDashpot coefficients(const PairCoefficients& pc, const ContactConstants&,
                                    double r_star, double m_star, double overlap) {
    constexpr double two_sqrt_5_6 = 1.8257418583505538;  // 2 sqrt(5/6)
    const double a = std::sqrt(r_star * overlap);
    const double sn = 2 * pc.y_star * a;
    const double st = 8 * pc.g_star * a;
    return {(2.0 / 3.0) * sn, two_sqrt_5_6 * pc.hertz_beta * std::sqrt(sn * m_star), st,
            two_sqrt_5_6 * pc.hertz_beta * std::sqrt(st * m_star)};
  }
};

}  // namespace grainflow
