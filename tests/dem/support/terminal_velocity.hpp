#pragma once
// An independent reference for tests: Schiller & Naumann's (1933) terminal velocity of a
// sphere (Re < 1000), by bisection on
//   (pi/8) C_D rho_f d^2 u^2 = (rho_p - rho_f) g pi d^3 / 6,  C_D = 24/Re (1 + 0.15 Re^0.687),
// written out here rather than taken from the drag code under test.
#include <cmath>
#include <numbers>

namespace grainflow::test {

inline double schiller_naumann_terminal_velocity(double d, double rho_p, double rho_f, double mu,
                                                 double g) {
  constexpr double pi = std::numbers::pi;
  const double weight = (rho_p - rho_f) * g * pi * d * d * d / 6;
  double lo = 0, hi = 100;
  for (int k = 0; k < 200; ++k) {
    const double u = 0.5 * (lo + hi), re = rho_f * d * u / mu;
    const double drag = pi / 8 * 24 / re * (1 + 0.15 * std::pow(re, 0.687)) * rho_f * d * d * u * u;
    (drag < weight ? lo : hi) = u;
  }
  return 0.5 * (lo + hi);
}

}  // namespace grainflow::test
