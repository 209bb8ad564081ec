#pragma once
// Torque on a sphere rotating relative to the fluid, in the form of Crowe et al.
// (2011, §4.8):  T = (ρ_f/2) (d/2)⁵ C_R |Ω| Ω,   Ω = ½ ∇×u_f − ω_p,
//   Re_r = ρ_f d² |Ω|/μ,
//   C_R = 64π/Re_r                       for Re_r <= 32 (Rubinow & Keller 1961),
//   C_R = 12.9/√Re_r + 128.4/Re_r        for 32 < Re_r (Dennis, Singh & Ingham 1980,
//                                        J. Fluid Mech. 101:257–279; fitted to Re_r < 1000).
// The low-Re branch is exactly the Stokes torque 8πμ(d/2)³ Ω. The branches meet within
// 0.2 % at Re_r = 32. The torque is K_r Ω with K_r ≥ 0 (rotational_drag_coefficient), so
// the engine integrates it implicitly in the spin, like translational drag in the velocity
// (ImplicitDrag): an explicit torque would need dt below its spin relaxation time
// I/K_r = ρ_p d²/(60 μ) in the Stokes branch (docs/models/fluid-forces.md).
#include <cmath>
#include <numbers>

#include "dem/core/types.hpp"

namespace grainflow {

// K_r [N m s] with T = K_r Ω, at the relative rotation rate w = |Ω|.
inline double rotational_drag_coefficient(double diameter, double fluid_density, double viscosity,
                                          double w) {
  const double r = 0.5 * diameter;
  const double re_r = fluid_density * diameter * diameter * w / viscosity;
  if (re_r <= 32) return 8 * std::numbers::pi * viscosity * r * r * r;
  const double c_r = 12.9 / std::sqrt(re_r) + 128.4 / re_r;
  return 0.5 * fluid_density * std::pow(r, 5) * c_r * w;
}

inline Vec3 rotational_drag_torque(double diameter, double fluid_density, double viscosity,
                                   const Vec3& relative_rotation) {
  return rotational_drag_coefficient(diameter, fluid_density, viscosity, relative_rotation.norm()) *
         relative_rotation;
}

}  // namespace grainflow
