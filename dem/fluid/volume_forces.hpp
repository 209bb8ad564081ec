#pragma once
// Forces from the fluid stress integrated over the particle volume, for a particle small
// against the scale on which ∇p and ∇·τ vary (Anderson & Jackson 1967; Zhou et al. 2010,
// J. Fluid Mech. 661:482–510, Table 1).
#include "dem/core/types.hpp"

namespace grainflow {

// Pressure-gradient force −V_p ∇p. With a pressure that includes the hydrostatic part
// ρ_f g·x, this is where buoyancy comes from: ∇p = ρ_f g gives −ρ_f V_p g (upward).
inline Vec3 pressure_gradient_force(double volume, const Vec3& pressure_gradient) {
  return -volume * pressure_gradient;
}

// Viscous force V_p ∇·τ.
inline Vec3 viscous_force(double volume, const Vec3& viscous_stress_divergence) {
  return volume * viscous_stress_divergence;
}

// Archimedes buoyancy −ρ_f V_p g, for a fluid solver whose pressure excludes the
// hydrostatic part (p = p_total − ρ_f g·x); never together with a hydrostatic ∇p.
inline Vec3 archimedes_buoyancy(double fluid_density, double volume, const Vec3& gravity) {
  return -fluid_density * volume * gravity;
}

}  // namespace grainflow
