#pragma once
// Ergun (1952), "Fluid flow through packed columns", Chem. Eng. Prog. 48(2):89–94:
//   Δp/L = 150 μ φ² U_s/(ε³ d²) + 1.75 ρ_f φ U_s²/(ε³ d),   U_s = εU (superficial).
// Δp/L is the TOTAL force per bed volume, n F_total with n = φ/V_p. The drag of our
// convention is F_drag = ε F_total (dem/fluid/drag_input.hpp), which gives Gidaspow's
// (1994, ch. 5) β = 150 φ² μ/(ε d²) + 1.75 φ ρ_f U/d and
//   K = β V_p/φ = V_p (150 φ μ/(ε d²) + 1.75 ρ_f U/d).
// Re: none needed (the two terms are written in U directly; in Re = ρ_f ε d U/μ it is
// K/(3πμd) = (25/3) φ/ε + (1.75/18) Re/ε). A packed-bed law: at ε → 1 its viscous part
// vanishes and it does NOT tend to the single-sphere drag.
#include <numbers>

#include "dem/fluid/drag_input.hpp"

namespace grainflow {

inline double ergun(const DragInput& in) {
  const double d = in.diameter, e = in.void_fraction, phi = 1 - e;
  const double volume = std::numbers::pi / 6 * d * d * d;
  return volume * (150 * phi * in.viscosity / (e * d * d) + 1.75 * in.density * in.slip_speed / d);
}

}  // namespace grainflow
