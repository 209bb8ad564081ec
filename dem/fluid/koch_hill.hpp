#pragma once
// Koch & Hill (2001), "Inertial effects in suspension and porous-media flows",
// Annu. Rev. Fluid Mech. 33:619–647, fitting the lattice-Boltzmann data of Hill, Koch &
// Ladd (2001), J. Fluid Mech. 448:213–241 and 243–278 (eqs. as in Benyahia et al. 2006):
//   F₀ = (1 + 3√(φ/2) + (135/64) φ ln φ + 16.14 φ) / (1 + 0.681 φ − 8.48 φ² + 8.16 φ³)
//        for φ < 0.4,   F₀ = 10 φ/ε³ for φ >= 0.4,
//   F₃ = 0.0673 + 0.212 φ + 0.0232/ε⁵,   F = F₀ + F₃ Re_a  with Re_a = ρ_f ε (d/2) U/μ.
// Here Re = ρ_f ε d U/μ (superficial slip, diameter), so F = F₀ + F₃ Re/2.
// Mean-pressure part: INCLUDED — F = F_total/(3πμ d εU) is the total force in a
// periodic array, normalised by Stokes drag at the superficial velocity. Our drag is
// F_drag = ε F_total, so K = 3πμd ε² F.
// At ε → 1: F₀ → 1, F₃ → 0.0905, K → 3πμd (1 + 0.04525 Re): Stokes as Re → 0 but not
// Schiller–Naumann at finite Re (the fit is for the array's inertial correction).
#include <cmath>

#include "dem/fluid/drag_input.hpp"

namespace grainflow {

inline double koch_hill_f0(double phi) {
  if (phi >= 0.4) return 10 * phi / std::pow(1 - phi, 3);
  const double log_term = phi > 0 ? 135.0 / 64.0 * phi * std::log(phi) : 0.0;  // φ ln φ → 0
  return (1 + 3 * std::sqrt(phi / 2) + log_term + 16.14 * phi) /
         (1 + 0.681 * phi - 8.48 * phi * phi + 8.16 * phi * phi * phi);
}

inline double koch_hill(const DragInput& in) {
  const double e = in.void_fraction, phi = 1 - e;
  const double f3 = 0.0673 + 0.212 * phi + 0.0232 / std::pow(e, 5);
  const double f = koch_hill_f0(phi) + 0.5 * f3 * reynolds_superficial(in);
  return stokes_coefficient(in) * e * e * f;
}

}  // namespace grainflow
