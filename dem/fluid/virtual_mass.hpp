#pragma once
// Virtual (added) mass force on a sphere accelerating relative to the fluid
// (Auton, Hunt & Prud'homme 1988, J. Fluid Mech. 197:241–257; C_vm = 1/2 for a sphere):
//   F_vm = C_vm ρ_f V_p (Du_f/Dt − dv/dt).
#include "dem/core/types.hpp"

namespace grainflow {

inline constexpr double kSphereVirtualMassCoefficient = 0.5;

inline Vec3 virtual_mass_force(double coefficient, double fluid_density, double volume,
                               const Vec3& fluid_acceleration, const Vec3& particle_acceleration) {
  return coefficient * fluid_density * volume * (fluid_acceleration - particle_acceleration);
}

// The same force with dv/dt taken from the particle's own equation of motion, so no
// acceleration from a previous step is needed and it stays stable for light particles.
// With the other forces F (explicit) + K (u − v) (implicit drag), the equation
//   m dv/dt = F + K(u − v) + m_a (Du/Dt − dv/dt),   m_a = C_vm ρ_f V_p,
// is m dv/dt = s [F + m_a Du/Dt + K(u − v)] with s = m/(m + m_a). So the particle needs
// the explicit force F_vm = s (F + m_a Du/Dt) − F = m_a (m Du/Dt − F)/(m + m_a), and its
// implicit drag coefficient scaled by s. Returns F_vm; `drag_scale` receives s.
inline Vec3 virtual_mass_closure(double added_mass, double mass, const Vec3& other_forces,
                                 const Vec3& fluid_acceleration, double& drag_scale) {
  drag_scale = mass / (mass + added_mass);
  return added_mass * (mass * fluid_acceleration - other_forces) / (mass + added_mass);
}

}  // namespace grainflow
