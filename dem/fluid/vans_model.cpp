#include "dem/fluid/vans_model.hpp"

#include <algorithm>
#include <stdexcept>

namespace grainflow {

const char* fluid_force_name(FluidForce f) {
  switch (f) {
    case FluidForce::drag: return "drag";
    case FluidForce::pressure_gradient: return "pressure_gradient";
    case FluidForce::viscous: return "viscous";
    case FluidForce::buoyancy: return "buoyancy";
    case FluidForce::virtual_mass: return "virtual_mass";
    case FluidForce::saffman_mei: return "saffman_mei";
    case FluidForce::magnus: return "magnus";
    case FluidForce::rotational_drag: return "rotational_drag";
  }
  return "?";
}

const std::vector<FluidForce>& all_fluid_forces() {
  static const std::vector<FluidForce> all = {
      FluidForce::drag,         FluidForce::pressure_gradient, FluidForce::viscous,
      FluidForce::buoyancy,     FluidForce::virtual_mass,      FluidForce::saffman_mei,
      FluidForce::magnus,       FluidForce::rotational_drag};
  return all;
}

std::optional<std::string> force_list_problem(const std::vector<FluidForce>& forces,
                                              const ForceListContext& c) {
  auto has = [&](FluidForce f) { return std::count(forces.begin(), forces.end(), f) > 0; };
  for (FluidForce f : all_fluid_forces())
    if (std::count(forces.begin(), forces.end(), f) > 1)
      return std::string("'") + fluid_force_name(f) + "' is listed twice; list each force once";
  if (!has(FluidForce::drag))
    return std::string("the force list has no 'drag'; every fluid coupling needs it");
  const std::string model = c.model == VansModel::A ? "model A" : "model B";
  if (!has(FluidForce::pressure_gradient))
    return c.model == VansModel::A
               ? model + " without 'pressure_gradient': the fluid momentum carries only ε∇p, so "
                         "the particles' share −V_p∇p must act on the particles or it is lost; "
                         "add pressure_gradient"
               : model + " without 'pressure_gradient': the fluid momentum carries the full ∇p and "
                         "expects the exchange term to return −V_p∇p, so without it the particles "
                         "feel no pressure (no buoyancy) and momentum is not conserved; add "
                         "pressure_gradient";
  if (!has(FluidForce::viscous))
    return c.model == VansModel::A
               ? model + " without 'viscous': the fluid momentum carries only ε∇·τ, so the "
                         "particles' share V_p∇·τ must act on the particles or it is lost; add "
                         "viscous"
               : model + " without 'viscous': the fluid momentum carries the full ∇·τ and expects "
                         "the exchange term to return V_p∇·τ; add viscous";
  if (has(FluidForce::buoyancy) && c.pressure_includes_hydrostatic)
    return std::string(
        "'buoyancy' (Archimedes, −ρ_f V_p g) is listed but the pressure includes the hydrostatic "
        "part, so pressure_gradient already gives ρ_f V_p g upward and buoyancy would count it "
        "twice; remove buoyancy, or use a pressure that excludes hydrostatics");
  if (!has(FluidForce::buoyancy) && !c.pressure_includes_hydrostatic && c.gravity)
    return std::string(
        "the pressure excludes the hydrostatic part, so pressure_gradient gives no buoyancy and "
        "the particles would miss ρ_f V_p g; add buoyancy");
  return std::nullopt;
}

void check_force_list(const std::vector<FluidForce>& forces, const ForceListContext& context) {
  if (const auto problem = force_list_problem(forces, context))
    throw std::invalid_argument(*problem);
}

bool carried_by_exchange(FluidForce f, VansModel model) {
  // Archimedes buoyancy is the hydrostatic part of −V_p∇p_total, so it goes where the
  // pressure-gradient force goes.
  if (f == FluidForce::pressure_gradient || f == FluidForce::viscous || f == FluidForce::buoyancy)
    return model == VansModel::B;
  return true;
}

}  // namespace grainflow
