#pragma once
// Saffman (1965, J. Fluid Mech. 22:385–400; corrigendum 1968) shear lift with Mei's
// (1992, Int. J. Multiphase Flow 18:145–147) correction for finite Re_p, in the form of
// Crowe, Schwarzkopf, Sommerfeld & Tsuji (2011), Multiphase Flows with Droplets and
// Particles, 2nd ed., §4.6:
//   F = 1.615 d² √(ρ_f μ) |ω|^{−1/2} [(u_f − v) × ω] f(Re_p, β),   ω = ∇×u_f,
//   Re_p = ρ_f d |u_f − v|/μ,   Re_s = ρ_f d² |ω|/μ,   β = Re_s/(2 Re_p),
//   f = (1 − 0.3314 √β) exp(−Re_p/10) + 0.3314 √β   for Re_p <= 40,
//   f = 0.0524 √(β Re_p)                              for Re_p > 40.
// (1.615 = 6.46/4: Saffman's 6.46 μ a² U √(G/ν) written with d.) Mei's fit covers
// 0.1 <= Re_p <= 100 and 0.005 <= β <= 0.4. Zero when either ω or the slip is zero.
#include <cmath>

#include "dem/core/types.hpp"

namespace grainflow {

inline double saffman_mei_correction(double re_p, double re_s) {
  if (!(re_p > 0)) return 1;  // Saffman's limit (β → ∞ is outside the fit; f → 1 as Re_p → 0)
  const double beta = re_s / (2 * re_p);
  if (re_p <= 40) {
    const double a = 0.3314 * std::sqrt(beta);
    return (1 - a) * std::exp(-re_p / 10) + a;
  }
  return 0.0524 * std::sqrt(beta * re_p);
}

inline Vec3 saffman_mei_lift(double diameter, double fluid_density, double viscosity,
                             const Vec3& slip, const Vec3& vorticity) {
  const double w = vorticity.norm(), u = slip.norm();
  if (!(w > 0) || !(u > 0)) return Vec3::Zero();
  const double re_p = fluid_density * diameter * u / viscosity;
  const double re_s = fluid_density * diameter * diameter * w / viscosity;
  return 1.615 * diameter * diameter * std::sqrt(fluid_density * viscosity) / std::sqrt(w) *
         saffman_mei_correction(re_p, re_s) * slip.cross(vorticity);
}

}  // namespace grainflow
