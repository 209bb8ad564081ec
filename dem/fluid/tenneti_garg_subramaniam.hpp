#pragma once
// Tenneti, Garg & Subramaniam (2011), "Drag law for monodisperse gas–solid systems using
// particle-resolved direct numerical simulation of flow past fixed assemblies of
// spheres", Int. J. Multiphase Flow 37:1072–1092:
//   F = F_isol(Re)/ε³ + F_φ(φ) + F_{φ,Re}(φ, Re),   F_isol = 1 + 0.15 Re^0.687,
//   F_φ = 5.81 φ/ε³ + 0.48 φ^{1/3}/ε⁴,   F_{φ,Re} = φ³ Re (0.95 + 0.61 φ³/ε²).
// Re = Re_m = ρ_f ε d U/μ (mean slip, superficial). Fitted for 0.1 <= φ <= 0.5,
// 0.01 <= Re <= 300. Mean-pressure part: INCLUDED — F is the total mean force normalised
// by 3πμ d εU; our drag is F_drag = ε F_total, so K = 3πμd ε² F.
// At ε = 1 it is exactly Schiller–Naumann (below Re = 1000).
#include <cmath>

#include "dem/fluid/drag_input.hpp"

namespace grainflow {

inline double tenneti_garg_subramaniam(const DragInput& in) {
  const double e = in.void_fraction, phi = 1 - e;
  const double re = reynolds_superficial(in);
  const double e3 = e * e * e, phi3 = phi * phi * phi;
  const double f = (1 + 0.15 * std::pow(re, 0.687)) / e3 + 5.81 * phi / e3 +
                   0.48 * std::cbrt(phi) / (e3 * e) + phi3 * re * (0.95 + 0.61 * phi3 / (e * e));
  return stokes_coefficient(in) * e * e * f;
}

}  // namespace grainflow
