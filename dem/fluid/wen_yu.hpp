#pragma once
// Wen & Yu (1966), "Mechanics of fluidization", Chem. Eng. Prog. Symp. Ser.
// 62(62):100–111, in the interphase form of Gidaspow (1994), Multiphase Flow and
// Fluidization (Academic Press), ch. 5:
//   β = (3/4) C_D ε φ ρ_f U ε^{−2.65} / d,  C_D = 24/Re (1 + 0.15 Re^0.687) (Re < 1000),
//   C_D = 0.44 (Re >= 1000);   K = β V_p/φ = (π/8) C_D ρ_f d² U ε^{−1.65}
//   => K = 3πμd ε^{−2.65} (1 + 0.15 Re^0.687) for Re < 1000.
// Re = ρ_f ε d U/μ (superficial slip). Mean-pressure part: excluded (β is the model-A
// coefficient). At ε = 1 it is exactly Schiller–Naumann.
#include <cmath>
#include <numbers>

#include "dem/fluid/drag_input.hpp"

namespace grainflow {

inline double wen_yu(const DragInput& in) {
  const double re = reynolds_superficial(in);
  const double e = in.void_fraction;
  if (re < 1000) return stokes_coefficient(in) * std::pow(e, -2.65) * (1 + 0.15 * std::pow(re, 0.687));
  return std::numbers::pi / 8 * 0.44 * in.density * in.diameter * in.diameter * in.slip_speed *
         std::pow(e, -1.65);
}

}  // namespace grainflow
