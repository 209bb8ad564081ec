#pragma once
// One-way mode (`grain` without a fluid solver): a fluid prescribed by the scene, and the
// fluid-force settings. The field is steady and analytic:
//   u(x) = u₀ + G ((x − x₀)·n_g) n_u       (uniform when G = 0; n_u ⟂ n_g, unit vectors)
//   ε given and uniform; ∇p = ∇p_extra (+ ρ_f g when the pressure includes hydrostatics);
//   ∇·τ = μ∇²u = 0;  ∇×u = G n_g × n_u;  Du/Dt = (u·∇)u = G (n_g·u₀) n_u.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dem/fluid/fluid_sample.hpp"
#include "dem/fluid/vans_model.hpp"
#include "dem/fluid/virtual_mass.hpp"

namespace grainflow {

struct PrescribedFluid {
  double density = 1000;                        // ρ_f [kg/m^3] > 0
  double viscosity = 1e-3;                      // μ [Pa s] > 0
  Vec3 velocity = Vec3::Zero();                 // u₀ [m/s], at x₀
  double shear_rate = 0;                        // G [1/s]
  Vec3 flow_direction = Vec3::UnitX();          // n_u (unit)
  Vec3 gradient_direction = Vec3::UnitZ();      // n_g (unit, ⟂ n_u)
  Vec3 origin = Vec3::Zero();                   // x₀ [m]
  double void_fraction = 1;                     // ε in [kLowestVoidFraction, 1]
  Vec3 pressure_gradient = Vec3::Zero();        // ∇p beyond hydrostatics [Pa/m]
  bool hydrostatic_pressure = true;             // ∇p includes ρ_f g

  FluidSample sample(const Vec3& x, const Vec3& gravity) const {
    FluidSample s;
    const double along = (x - origin).dot(gradient_direction);
    s.velocity = velocity + shear_rate * along * flow_direction;
    s.void_fraction = void_fraction;
    s.pressure_gradient = pressure_gradient;
    if (hydrostatic_pressure) s.pressure_gradient += density * gravity;
    s.density = density;
    s.viscosity = viscosity;
    s.vorticity = shear_rate * gradient_direction.cross(flow_direction);
    s.material_derivative = shear_rate * gradient_direction.dot(velocity) * flow_direction;
    return s;
  }
};

// Void fraction computed from the particles on a grid of cells (void_fraction_grid.hpp).
struct VoidFractionGridSettings {
  double cell_size = 0;  // requested cell edge [m] > 0 (rounded to fit the domain)
  double minimum = 0.2;  // eps_min in [kLowestVoidFraction, 1)
};

// Particle-fluid convection with a prescribed fluid temperature (heat on;
// dem/heat/convection.hpp).
enum class NusseltLaw { ranz_marshall, gunn };
struct FluidThermal {
  double temperature = 0;    // T_f [K]
  double heat_capacity = 0;  // c_p,f [J/(kg K)] > 0
  double conductivity = 0;   // k_f [W/(m K)] > 0
  NusseltLaw nusselt = NusseltLaw::ranz_marshall;
};

struct FluidSettings {
  PrescribedFluid field;
  // When set, eps comes from the particles (void_fraction_grid.hpp), not field.void_fraction.
  std::optional<VoidFractionGridSettings> computed_void_fraction;
  std::string drag_law = "schiller_naumann";  // a name from drag_law_names()
  std::vector<FluidForce> forces;             // validated by force_list_problem()
  VansModel model = VansModel::B;
  double virtual_mass_coefficient = kSphereVirtualMassCoefficient;
  std::string source;                         // "file:line" of the block, for messages
  // The keys that prescribe the fluid itself (velocity, shear, void_fraction,
  // pressure.gradient) as given, each with its "file:line": a coupled run solves the fluid
  // and refuses them.
  std::vector<std::pair<std::string, std::string>> prescribed_keys;
  std::optional<FluidThermal> thermal;        // `temperature:` given (heat on)
  // Coarse graining (docs/models/coarse-graining.md): each material's factor k, indexed by
  // material (Scene::coarse_grain_table); empty when every particle is a real one. A parcel's
  // drag is the real particle's (diameter d/k) at the parcel's slip and eps, times k^3.
  std::vector<double> coarse_grain;
};

}  // namespace grainflow
