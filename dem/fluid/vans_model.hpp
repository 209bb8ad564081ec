#pragma once
// The fluid forces a scene can list, and the two forms of the volume-averaged
// Navier–Stokes equations they must fit (DESIGN.md §4; Zhou, Kuang, Chu & Yu 2010,
// J. Fluid Mech. 661:482–510; Gidaspow 1994):
//  model A: the fluid momentum carries −ε∇p + ε∇·τ; the exchange term returns to the
//           fluid only drag and the other "local" forces. The remaining −φ∇p + φ∇·τ
//           acts on the particles as −V_p∇p + V_p∇·τ, which therefore must be listed.
//  model B: the fluid momentum carries −∇p + ∇·τ; the exchange term carries every force
//           on the particles, so −V_p∇p and V_p∇·τ must be listed (they are the only
//           route by which the particles feel the pressure, and the fluid gets them back).
// The particle feels the same forces in both; what differs is what the exchange term
// carries (carried_by_exchange). Refused force lists: see force_list_problem().
#include <optional>
#include <string>
#include <vector>

namespace grainflow {

enum class FluidForce {
  drag,               // K (u_f − v), the scene's drag law
  pressure_gradient,  // −V_p ∇p
  viscous,            // V_p ∇·τ
  buoyancy,           // Archimedes −ρ_f V_p g (pressure without hydrostatics only)
  virtual_mass,       // C_vm ρ_f V_p (Du/Dt − dv/dt)
  saffman_mei,        // shear lift
  magnus,             // rotation lift
  rotational_drag,    // torque
};

enum class VansModel { A, B };

const char* fluid_force_name(FluidForce f);
const std::vector<FluidForce>& all_fluid_forces();

// What the force list is checked against.
struct ForceListContext {
  VansModel model = VansModel::B;
  bool pressure_includes_hydrostatic = true;  // ∇p contains ρ_f g
  bool gravity = true;                        // the scene has non-zero gravity
};

// Why `forces` does not fit `context`, or nothing if it does. Refused:
//  1. a force listed twice;
//  2. no drag;
//  3. pressure_gradient missing (model A: the fluid carries only ε∇p, so the particles'
//     share φ∇p would be lost; model B: the fluid carries the full ∇p and expects the
//     exchange to return −V_p∇p, so particles would feel no pressure and no buoyancy);
//  4. viscous missing (same reasons for ∇·τ);
//  5. buoyancy with a pressure that includes hydrostatics (ρ_f V_p g counted twice);
//  6. no buoyancy with a pressure that excludes hydrostatics under gravity (the
//     particles would miss ρ_f V_p g).
std::optional<std::string> force_list_problem(const std::vector<FluidForce>& forces,
                                              const ForceListContext& context);

// Throws std::invalid_argument with force_list_problem's message.
void check_force_list(const std::vector<FluidForce>& forces, const ForceListContext& context);

// Whether the fluid momentum equation gets this force back through the exchange term.
bool carried_by_exchange(FluidForce f, VansModel model);

}  // namespace grainflow
