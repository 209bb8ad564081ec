#pragma once
// Beetstra, van der Hoef & Kuipers (2007), "Drag force of intermediate Reynolds number
// flow past mono- and bidisperse arrays of spheres", AIChE J. 53(2):489–501, eq. (16):
//   F = 10φ/ε² + ε² (1 + 1.5√φ)
//       + [0.413 Re / (24 ε²)] · [1/ε + 3φε + 8.4 Re^{−0.343}] / [1 + 10^{3φ} Re^{−(1+4φ)/2}].
// The coefficient of √φ is 1.5 (a widely copied documentation has 1.15, which is wrong).
// Re = ρ_f ε d U/μ (superficial slip). Mean-pressure part: EXCLUDED by its normalisation.
// Beetstra (after van der Hoef et al. 2005, J. Fluid Mech. 528:233–254) normalise so that
// the Stokes limit is the Carman–Kozeny 10φ/ε²: F = ε F_total/(3πμ d εU), i.e. the total
// force already multiplied by ε — our F_drag over Stokes drag at the superficial velocity.
// So K = 3πμd ε F (one ε; Koch–Hill and Tenneti, normalised as F_total with the limit
// 10φ/ε³, need two). Check: at Re → 0 and φ >= 0.4 Beetstra, Koch–Hill and Carman–Kozeny
// agree (drag_laws_test, DenseStokesLimitsAgree).
// At ε → 1: F → 1 + (0.413 Re/24)(1 + 8.4 Re^{−0.343})/(1 + Re^{−1/2}): Stokes as
// Re → 0, but not Schiller–Naumann at finite Re (0.94× at Re = 10, 1.16× at 100, 1.49× at
// 500): the fit covers φ >= 0.1 and its dilute end is not the isolated sphere.
#include <cmath>

#include "dem/fluid/drag_input.hpp"

namespace grainflow {

inline double beetstra(const DragInput& in) {
  const double e = in.void_fraction, phi = 1 - e;
  const double re = reynolds_superficial(in);
  double f = 10 * phi / (e * e) + e * e * (1 + 1.5 * std::sqrt(phi));
  if (re > 0) {
    // Re·[...] is written as Re/ε + 3φε Re + 8.4 Re^0.657 so Re → 0 stays finite.
    const double numerator = re / e + 3 * phi * e * re + 8.4 * std::pow(re, 0.657);
    const double denominator = 1 + std::pow(10.0, 3 * phi) * std::pow(re, -(1 + 4 * phi) / 2);
    f += 0.413 / (24 * e * e) * numerator / denominator;
  }
  return stokes_coefficient(in) * e * f;
}

}  // namespace grainflow
