#pragma once
// Di Felice (1994), "The voidage function for fluid-particle interaction systems",
// Int. J. Multiphase Flow 20(1):153–159, with the Dallavalle single-sphere
// C_D:
//   C_D = (0.63 + 4.8/√Re)²,   χ = 3.7 − 0.65 exp(−(1.5 − log₁₀Re)²/2),
//   F = (1/2) C_D ρ_f (π d²/4) (εU)² ε^{−χ}  =>  K = (π/8) C_D ρ_f d² U ε^{2−χ}.
// Re = ρ_f ε d U/μ (superficial slip). Mean-pressure part: excluded — Di Felice fitted
// χ to fluidisation data with the pressure-gradient force taken apart (χ ≈ 3.7 =
// n − 1 for the Richardson–Zaki n ≈ 4.7 at low Re), so it is F_drag of our convention.
// K is evaluated as (π/8) ρ_f d² ε^{2−χ} (0.63√U + 4.8√(μ/(ρ_f ε d)))², finite at U = 0.
#include <cmath>
#include <numbers>

#include "dem/fluid/drag_input.hpp"

namespace grainflow {

// exp(−(1.5 − log₁₀Re)²/2); 0 at Re = 0 (log₁₀ → −∞).
inline double di_felice_bell(double re) {
  if (!(re > 0)) return 0;
  const double a = 1.5 - std::log10(re);
  return std::exp(-0.5 * a * a);
}

// K for a given exponent χ (shared with Rong et al. 2013).
inline double di_felice_with_exponent(const DragInput& in, double chi) {
  const double root = 0.63 * std::sqrt(in.slip_speed) +
                      4.8 * std::sqrt(in.viscosity / (in.density * in.void_fraction * in.diameter));
  return std::numbers::pi / 8 * in.density * in.diameter * in.diameter *
         std::pow(in.void_fraction, 2 - chi) * root * root;
}

inline double di_felice(const DragInput& in) {
  const double chi = 3.7 - 0.65 * di_felice_bell(reynolds_superficial(in));
  return di_felice_with_exponent(in, chi);
}

}  // namespace grainflow
