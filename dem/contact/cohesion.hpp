#pragma once
// Cohesion slot. `sjkr`: simplified JKR, an attractive normal force k_c A while the
// bodies overlap, with A the area of the overlap disc (k_c cohesion energy density,
// J/m^3) — the LIGGGHTS "sjkr" model (Gilabert et al. 2007 form).
//   sphere-sphere: a^2 = (d - r_i - r_j)(d + r_i - r_j)(d - r_i + r_j)(d + r_i + r_j) / (4 d^2)
//   sphere-wall:   a^2 = 2 r d - d^2
#include <numbers>

#include "dem/contact/contact_geometry.hpp"

namespace grainflow {

struct NoCohesion {
  static constexpr bool enabled = false;
  static constexpr const char* name = "none";
};

struct SjkrCohesion {
  static constexpr bool enabled = true;
  static constexpr const char* name = "sjkr";
  static double contact_area(const ContactGeometry& g) {
    if (g.wall) return std::numbers::pi * (2 * g.r_i * g.overlap - g.overlap * g.overlap);
    const double d = g.distance, ri = g.r_i, rj = g.r_j;
    const double a2 = -(d - ri - rj) * (d + ri - rj) * (d - ri + rj) * (d + ri + rj) / (4 * d * d);
    return std::numbers::pi * a2;
  }
  // Magnitude of the attractive force (acts along -n on i).
  static double force(const ContactGeometry& g, double energy_density) {
    return energy_density * contact_area(g);
  }
};

}  // namespace grainflow
