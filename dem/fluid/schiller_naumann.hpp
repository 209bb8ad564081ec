#pragma once
// Schiller & Naumann (1933), "Über die grundlegenden Berechnungen bei der
// Schwerkraftaufbereitung", Z. Ver. Dtsch. Ing. 77:318–320; form as in Clift, Grace &
// Weber (1978), Bubbles, Drops and Particles, Table 5.2:
//   C_D = 24/Re₀ (1 + 0.15 Re₀^0.687)  for Re₀ < 1000,   C_D = 0.44  above,
//   F = (π/8) C_D ρ_f d² U (u_f - v)  =>  K = 3πμd (1 + 0.15 Re₀^0.687)  (Re₀ < 1000).
// Re₀ = ρ_f d U/μ (single sphere): ε does not enter, the law ignores neighbours.
// Mean-pressure part: none (an isolated sphere in uniform flow has no mean ∇p).
// At Re₀ = 1000 the two branches differ by 0.3 % (C_D 0.4387 vs 0.44).
#include <cmath>
#include <numbers>

#include "dem/fluid/drag_input.hpp"

namespace grainflow {

inline double schiller_naumann(const DragInput& in) {
  const double re = reynolds_single(in);
  if (re < 1000) return stokes_coefficient(in) * (1 + 0.15 * std::pow(re, 0.687));
  return std::numbers::pi / 8 * 0.44 * in.density * in.diameter * in.diameter * in.slip_speed;
}

}  // namespace grainflow
