#pragma once
// The laws of particle heat transfer (docs/models/heat-transfer.md), as pure functions.
//
// Contact conduction, Batchelor & O'Brien (1977): two bodies touching over a circle of
// radius a conduct Q = 2 k* a (T_j - T_i) when the solids conduct far better than the gap
// fluid. Each body is a half-space to the constriction at the circle, of resistance
// 1/(4 k a) (Holm); in series 1/(4 k_i a) + 1/(4 k_j a) = 1/(2 k* a) with the harmonic
// k* = 2 k_i k_j / (k_i + k_j), which is k for like materials.
// The contact radius is that of Hertz theory, a = sqrt(R* delta), for Hertz and Hooke
// contacts alike (a Hooke spring has no contact area of its own; the geometric radius of
// the overlap is the common choice).
//
// Convection: h = Nu k_f / d on the area pi d^2, with Re = eps rho_f d |u - v| / mu and
// Pr = c_p,f mu / k_f:
//   Ranz & Marshall (1952), a single sphere:  Nu = 2 + 0.6 Re^(1/2) Pr^(1/3);
//   Gunn (1978, eq. 21), fixed and fluidised beds, 0.35 <= eps <= 1:
//     Nu = (7 - 10 eps + 5 eps^2)(1 + 0.7 Re^0.2 Pr^(1/3))
//          + (1.33 - 2.4 eps + 1.2 eps^2) Re^0.7 Pr^(1/3).
#include <cmath>
#include <numbers>

#include "dem/fluid/prescribed_fluid.hpp"

namespace grainflow {

// Harmonic effective conductivity of a contact [W/(m K)].
// (As 2 / (1/k_i + 1/k_j): the product k_i k_j overflows above 1.3e154 W/(m K).)
inline double effective_conductivity(double k_i, double k_j) { return 2 / (1 / k_i + 1 / k_j); }

// Contact radius a = sqrt(R* delta) [m] (Hertz; used for Hooke contacts too).
inline double contact_radius(double r_star, double overlap) { return std::sqrt(r_star * overlap); }

// Hertz's effective modulus 1/Y* = (1 - nu_a^2)/Y_a + (1 - nu_b^2)/Y_b [Pa].
inline double hertz_effective_modulus(double y_a, double nu_a, double y_b, double nu_b) {
  return 1 / ((1 - nu_a * nu_a) / y_a + (1 - nu_b * nu_b) / y_b);
}

// Soft-particle corrections of the contact radius (Morris et al. 2016): a simulation run
// with a Young's modulus below the real one has, under the same load, a larger overlap and
// contact radius than the real material, and in an impact a longer contact. With Hertz's
// theory, a = sqrt(R* delta) and the ratio s = Y*_sim / Y*_real (< 1 when softened):
//  - an enduring contact under a load F: a = (3 F R* / (4 Y*))^(1/3), so the real radius is
//    a_sim s^(1/3);
//  - an elastic impact at speed v: a_max = sqrt(R* delta_max) with
//    delta_max = (15 m* v^2 / (16 Y* R*^(1/2)))^(2/5), and the contact time t_c is
//    proportional to delta_max / v, so the heat 2 k* dT integral(a dt) = 2 k* dT a_max t_c c0
//    of the whole impact scales as Y*^(-1/5) Y*^(-2/5) = Y*^(-3/5): the simulated impact
//    conducts the real impact's heat with a = a_sim s^(3/5) (the enduring factor s^(1/3)
//    times the contact-time factor (t_c,real / t_c,sim)^(2/3) = s^(4/15)).
inline double morris_static_radius_factor(double y_star_sim, double y_star_real) {
  return std::cbrt(y_star_sim / y_star_real);
}
inline double morris_collision_radius_factor(double y_star_sim, double y_star_real) {
  return std::pow(y_star_sim / y_star_real, 0.6);
}

// Batchelor & O'Brien's conductance 2 k* a [W/K].
inline double contact_conductance(double k_star, double a) { return 2 * k_star * a; }

inline double prandtl_number(double heat_capacity, double viscosity, double conductivity) {
  return heat_capacity * viscosity / conductivity;
}

inline double nusselt_ranz_marshall(double re, double pr) {
  return 2 + 0.6 * std::sqrt(re) * std::cbrt(pr);
}

// Gunn (1978): fitted for void fractions from this to 1 (grain check warns below it).
inline constexpr double kGunnLowestVoidFraction = 0.35;

inline double nusselt_gunn(double eps, double re, double pr) {
  const double pr3 = std::cbrt(pr);
  return (7 - 10 * eps + 5 * eps * eps) * (1 + 0.7 * std::pow(re, 0.2) * pr3) +
         (1.33 - 2.4 * eps + 1.2 * eps * eps) * std::pow(re, 0.7) * pr3;
}

inline double nusselt_number(NusseltLaw law, double eps, double re, double pr) {
  return law == NusseltLaw::gunn ? nusselt_gunn(eps, re, pr) : nusselt_ranz_marshall(re, pr);
}

// h A = Nu k_f pi d [W/K] of a sphere of diameter d at slip speed `slip`.
// At void fraction eps, fluid density and viscosity given (the coupled fluid's samples).
inline double convective_conductance(const FluidThermal& th, double eps, double density,
                                     double viscosity, double d, double slip) {
  const double re = eps * density * d * slip / viscosity;
  const double pr = prandtl_number(th.heat_capacity, viscosity, th.conductivity);
  return nusselt_number(th.nusselt, eps, re, pr) * th.conductivity * std::numbers::pi * d;
}

// h A [W/K] of a coarse-grained parcel of diameter `parcel_d` standing for k^3 real particles
// of diameter parcel_d / k (docs/models/coarse-graining.md, "Heat transfer"): each real
// particle exchanges with the gas at the parcel's eps and slip as its Nusselt law gives for
// the real diameter, so the parcel's conductance is k^3 times the real particle's and its time
// constant m c / (h A) is the real particle's. At k = 1 this is convective_conductance, bit
// for bit (the factors 1 and parcel_d / 1 are exact).
inline double parcel_convective_conductance(const FluidThermal& th, double eps, double density,
                                            double viscosity, double parcel_d, double k,
                                            double slip) {
  return k * k * k * convective_conductance(th, eps, density, viscosity, parcel_d / k, slip);
}

inline double convective_conductance(const FluidThermal& th, const PrescribedFluid& f, double d,
                                     double slip) {
  return convective_conductance(th, f.void_fraction, f.density, f.viscosity, d, slip);
}

}  // namespace grainflow
