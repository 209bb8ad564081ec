#pragma once
// Linear spring-dashpot. Stiffness either given, or chosen so that a Hertzian
// contact hit at the characteristic speed V reaches the same maximum overlap:
//   k_n = (16/15) sqrt(R*) Y* (15 m* V^2 / (16 sqrt(R*) Y*))^{1/5},
// gamma_n = sqrt(4 m* k_n / (1 + (pi/ln e)^2)) gives restitution e exactly for a linear
// oscillator whose contact ends when the overlap returns to zero. k_t = k_n and
// gamma_t = gamma_n unless k_t is given (Cundall & Strack 1979; LIGGGHTS "hooke" conventions).
#include <cmath>

#include "dem/contact/contact_geometry.hpp"
#include "dem/contact/pair_coefficients.hpp"

namespace grainflow {

struct HookeNormal {
  static constexpr const char* name = "hooke";
  static constexpr bool lanes = false;  // one contact at a time (std::pow)
  static SpringDashpot coefficients(const PairCoefficients& pc, const ContactConstants& cc,
                                    double r_star, double m_star, double /*overlap*/) {
    double kn, kt;
    if (cc.hooke_characteristic_velocity > 0) {
      const double v = cc.hooke_characteristic_velocity;
      const double sr = std::sqrt(r_star);
      kn = (16.0 / 15.0) * sr * pc.y_star *
           std::pow(15.0 * m_star * v * v / (16.0 * sr * pc.y_star), 0.2);
      kt = kn;
    } else {
      kn = cc.hooke_kn;
      kt = cc.hooke_kt;
    }
    const double gn = std::sqrt(4 * m_star * kn) * pc.hooke_damping;
    const double gt = kt == kn ? gn : std::sqrt(4 * m_star * kt) * pc.hooke_damping;
    return {kn, gn, kt, gt};
  }
  // For the cell-integrated dashpot (contact_law.hpp): the spring force at overlap x >= 0 and
  // the dashpot's potential Phi(x) = gamma_n x.
  static double spring_force(const SpringDashpot& s, double /*overlap*/, double x) {
    return s.kn * x;
  }
  static double dashpot_potential(const SpringDashpot& s, double /*overlap*/, double x) {
    return s.gn * x;
  }
};

}  // namespace grainflow
