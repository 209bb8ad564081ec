#pragma once
// Rong, Dong & Yu (2013), "Lattice-Boltzmann simulation of fluid flow through packed
// beds of uniform spheres: effect of porosity", Chem. Eng. Sci. 99:44–58:
// Di Felice's form (dem/fluid/di_felice.hpp) with the exponent
//   χ = 2.65 (ε + 1) − (5.3 − 3.5 ε) ε² exp(−(1.5 − log₁₀Re)²/2).
// Re = ρ_f ε d U/μ (superficial slip). Mean-pressure part: excluded (same
// convention as Di Felice). At ε = 1 the voidage factor is 1 and the law equals
// Di Felice's single-sphere limit.
#include "dem/fluid/di_felice.hpp"

namespace grainflow {

inline double rong(const DragInput& in) {
  const double e = in.void_fraction;
  const double chi =
      2.65 * (e + 1) - (5.3 - 3.5 * e) * e * e * di_felice_bell(reynolds_superficial(in));
  return di_felice_with_exponent(in, chi);
}

}  // namespace grainflow
