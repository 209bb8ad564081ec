#pragma once
// Magnus (rotation-induced) lift in the form of Crowe et al. (2011, §4.7) with the lift
// coefficient of Oesterlé & Bui Dinh (1998, Exp. Fluids 25:16–22):
//   F = (π/8) d³ ρ_f (Re_p/Re_r) C_LR [Ω × (u_f − v)],   Ω = ½ ∇×u_f − ω_p,
//   Re_p = ρ_f d |u_f − v|/μ,   Re_r = ρ_f d² |Ω|/μ,
//   C_LR = 0.45 + (Re_r/Re_p − 0.45) exp(−0.05684 Re_r^0.4 Re_p^0.3)   (Re_p < 140).
// As Re_p → 0, (Re_p/Re_r) C_LR → 1 and F → (π/8) d³ ρ_f Ω × (u_f − v), the
// Rubinow & Keller (1961, J. Fluid Mech. 11:447–459) result π a³ ρ_f Ω × (u_f − v).
#include <cmath>
#include <numbers>

#include "dem/core/types.hpp"

namespace grainflow {

// (Re_p/Re_r) C_LR, written so Re_p → 0 stays finite.
inline double magnus_factor(double re_p, double re_r) {
  const double e = std::exp(-0.05684 * std::pow(re_r, 0.4) * std::pow(re_p, 0.3));
  return 0.45 * re_p / re_r + (1 - 0.45 * re_p / re_r) * e;
}

inline Vec3 magnus_lift(double diameter, double fluid_density, double viscosity, const Vec3& slip,
                        const Vec3& relative_rotation) {
  const double w = relative_rotation.norm();
  if (!(w > 0) || !(slip.norm() > 0)) return Vec3::Zero();
  const double re_p = fluid_density * diameter * slip.norm() / viscosity;
  const double re_r = fluid_density * diameter * diameter * w / viscosity;
  return std::numbers::pi / 8 * diameter * diameter * diameter * fluid_density *
         magnus_factor(re_p, re_r) * relative_rotation.cross(slip);
}

}  // namespace grainflow
