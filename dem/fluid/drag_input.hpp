#pragma once
// What every drag law needs, and the Reynolds numbers they are written in.
//
// Convention shared by ALL drag laws of dem/fluid/ (docs/models/fluid-forces.md):
//  * A law returns the coefficient K >= 0 [kg/s] of F_drag = K (u_f - v).
//  * F_drag is the drag alone: it EXCLUDES the mean-pressure ("buoyancy-like") part
//    -V_p ∇p, which is always a separate force (pressure_gradient). K is therefore the
//    per-particle form of the model-A interphase coefficient β: K = β V_p / φ.
//  * Laws written for the TOTAL fluid-particle force in periodic arrays (Koch–Hill,
//    Tenneti; Ergun's Δp/L) are converted with F_drag = ε F_total (Beetstra's F has
//    this ε inside its normalisation already): in a homogeneous
//    suspension n F_total = -∇P and n F_drag = -ε ∇P (n = φ/V_p), so the part left
//    after -V_p ∇P is taken away is ε F_total. The same K serves model A and model B.
#include <numbers>

namespace grainflow {

struct DragInput {
  double diameter = 0;       // d [m] > 0
  double slip_speed = 0;     // U = |u_f - v| [m/s] >= 0
  double void_fraction = 1;  // ε in (0, 1]
  double density = 0;        // ρ_f [kg/m^3] > 0
  double viscosity = 0;      // μ [Pa s] > 0
};

// Re₀ = ρ_f d U / μ: the single-sphere Reynolds number (no ε).
inline double reynolds_single(const DragInput& in) {
  return in.density * in.diameter * in.slip_speed / in.viscosity;
}

// Re = ρ_f ε d U / μ: the Reynolds number of the superficial slip velocity εU
// (DESIGN.md §4). All dense-suspension laws here are written in this Re.
inline double reynolds_superficial(const DragInput& in) {
  return in.void_fraction * reynolds_single(in);
}

// 3πμd: Stokes drag coefficient of a single sphere.
inline double stokes_coefficient(const DragInput& in) {
  return 3 * std::numbers::pi * in.viscosity * in.diameter;
}

// Lowest void fraction at which the laws are evaluated and tested finite (packed
// beds sit near 0.36; a coupling that clamps ε clamps at or above this).
inline constexpr double kLowestVoidFraction = 0.2;

}  // namespace grainflow
