#pragma once
// The fluid state at one particle, as the coupling (or a prescribed one-way field)
// samples it. Plain data, SI units. Every fluid-force law is a pure function of this
// sample and of the particle's own state.
#include "dem/core/types.hpp"

namespace grainflow {

struct FluidSample {
  Vec3 velocity = Vec3::Zero();                    // u_f [m/s]
  double void_fraction = 1;                        // ε in (0, 1]
  Vec3 pressure_gradient = Vec3::Zero();           // ∇p [Pa/m]
  Vec3 viscous_stress_divergence = Vec3::Zero();   // ∇·τ [Pa/m]
  double density = 0;                              // ρ_f [kg/m^3]
  double viscosity = 0;                            // dynamic viscosity μ [Pa s]
  Vec3 vorticity = Vec3::Zero();                   // ∇×u_f [1/s]
  Vec3 material_derivative = Vec3::Zero();         // Du_f/Dt = ∂u/∂t + (u·∇)u [m/s^2]
  double temperature = 0;  // T_f [K], read by coupled convection only (CoupledFluid)
};

}  // namespace grainflow
