#include "dem/scene/fluid_section.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "dem/core/number_format.hpp"
#include "dem/fluid/drag_law.hpp"

namespace grainflow {

using namespace scene_yaml;

namespace {

// A linear shear varies along its gradient direction; across a periodic side along it the
// fluid velocity would jump by G times the period (a sheared periodic box needs Lees-Edwards
// boundaries), and a particle would see the jump only when its centre is next wrapped, at a
// neighbour rebuild: the answer depended on the skin.
void parse_shear(const Field& f, PrescribedFluid& field, const Domain& domain) {
  const Map m = f.map({"rate", "flow_direction", "gradient_direction", "origin"});
  field.shear_rate = m.number("rate", kAny);
  field.flow_direction = m.direction("flow_direction");
  field.gradient_direction = m.direction("gradient_direction");
  field.origin = m.vec3_or("origin", Vec3::Zero());
  if (std::abs(field.flow_direction.dot(field.gradient_direction)) > 1e-12)
    m.get("gradient_direction")
        .fail("is not perpendicular to flow_direction; a linear shear u = G ((x − x₀)·n_g) n_u "
              "needs n_g ⟂ n_u (e.g. flow_direction [1, 0, 0], gradient_direction [0, 0, 1])");
  constexpr const char* axis[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    const double along = field.gradient_direction[a];
    if (!domain.periodic[a] || std::abs(along) < 1e-12 || field.shear_rate == 0) continue;
    const double jump = std::abs(field.shear_rate * along) * (domain.hi[a] - domain.lo[a]);
    m.get("gradient_direction")
        .fail_at_key(std::string("has the component ") + significant(along) + " along " + axis[a] +
                     ", and " + axis[a] +
                     " is periodic (domain.periodic): the sheared fluid velocity would jump by " +
                     significant(jump) +
                     " m/s at the periodic sides (a sheared periodic box "
                     "needs Lees-Edwards boundaries, which grainflow does not have); make " +
                     axis[a] + " bounded, or choose a gradient_direction along a bounded axis");
  }
}

std::vector<FluidForce> parse_forces(const Field& f) {
  std::vector<FluidForce> out;
  for (const Field& item : f.non_empty_items("list at least drag, pressure_gradient, viscous"))
    out.push_back(item.choice<FluidForce>(
        "fluid force", {{"drag", FluidForce::drag},
                        {"pressure_gradient", FluidForce::pressure_gradient},
                        {"viscous", FluidForce::viscous},
                        {"buoyancy", FluidForce::buoyancy},
                        {"virtual_mass", FluidForce::virtual_mass},
                        {"saffman_mei", FluidForce::saffman_mei},
                        {"magnus", FluidForce::magnus},
                        {"rotational_drag", FluidForce::rotational_drag}}));
  return out;
}

// The prescribed fluid temperature and what convection needs (heat on): `temperature`,
// `heat_capacity`, `conductivity` (for the Prandtl number), `convection` (Nusselt law).
std::optional<FluidThermal> parse_thermal(const Map& m, const std::optional<HeatSettings>& heat) {
  const std::optional<Field> t = m.find("temperature");
  if (!t) {
    for (const char* key : {"heat_capacity", "conductivity", "convection"})
      if (const auto k = m.find(key))
        k->fail_at_key(std::string("`") + key +
                       "` is a convection setting, which needs the fluid's `temperature: <K>`; "
                       "add it, or remove this key");
    return std::nullopt;
  }
  if (!heat)
    t->fail_at_key("a fluid temperature is given, but heat transfer is off; add a top-level "
                   "`heat: {}` block to switch it on, or remove this key");
  FluidThermal th;
  th.temperature = t->number(kPositive);
  th.heat_capacity = m.get("heat_capacity", "add the fluid's `heat_capacity: <J/(kg K)>` (the "
                                            "Prandtl number of convection needs it)")
                         .number(kPositive);
  th.conductivity = m.get("conductivity", "add the fluid's `conductivity: <W/(m K)>` (Nusselt "
                                          "number and Prandtl number need it)")
                        .number(kPositive);
  if (const auto c = m.find("convection"))
    th.nusselt = c->choice<NusseltLaw>(
        "convection (Nusselt) law",
        {{"ranz_marshall", NusseltLaw::ranz_marshall}, {"gunn", NusseltLaw::gunn}});
  return th;
}

}  // namespace

FluidSettings parse_fluid_section(const Field& f, const Vec3& gravity, const Domain& domain,
                                  const std::optional<HeatSettings>& heat) {
  const Map m = f.map({"density", "viscosity", "velocity", "shear", "void_fraction", "pressure",
                       "drag", "forces", "model", "virtual_mass_coefficient", "temperature",
                       "heat_capacity", "conductivity", "convection"});
  FluidSettings s;
  s.source = f.source().label + ":" + std::to_string(f.line());
  PrescribedFluid& field = s.field;
  field.density = m.number("density", kPositive);
  field.viscosity = m.number("viscosity", kPositive);
  field.velocity = m.vec3_or("velocity", Vec3::Zero());
  if (const auto shear = m.find("shear")) parse_shear(*shear, field, domain);
  if (const auto vf = m.find("void_fraction"); vf && vf->node().IsMap()) {
    // Computed from the particles on a grid: {cell_size: <m>, minimum: <eps_min>}.
    const Map g = vf->map({"cell_size", "minimum"});
    VoidFractionGridSettings grid;
    grid.cell_size = g.number("cell_size", kPositive);
    grid.minimum = g.number_or("minimum", 0.2, Range{kLowestVoidFraction, 1, true, false});
    s.computed_void_fraction = grid;
  } else {
    field.void_fraction =
        m.number_or("void_fraction", 1.0, Range{kLowestVoidFraction, 1, true, true});
  }
  if (const auto p = m.find("pressure")) {
    const Map pm = p->map({"hydrostatic", "gradient"});
    if (const auto h = pm.find("hydrostatic")) field.hydrostatic_pressure = h->boolean();
    field.pressure_gradient = pm.vec3_or("gradient", Vec3::Zero());
    if (const auto g = pm.find("gradient"))
      s.prescribed_keys.emplace_back("pressure.gradient",
                                     g->source().label + ":" + std::to_string(g->line()));
  }
  for (const char* key : {"velocity", "shear", "void_fraction"})
    if (const auto k = m.find(key))
      s.prescribed_keys.emplace_back(key, k->source().label + ":" + std::to_string(k->line()));

  const Field drag = m.get("drag", "add `drag: <law>` (e.g. schiller_naumann)");
  const std::vector<std::string> names = drag_law_names();
  s.drag_law = drag.text();
  if (std::find(names.begin(), names.end(), s.drag_law) == names.end())
    drag.fail("unknown drag law '" + s.drag_law + "'; allowed: " + join(names) +
              suggestion(s.drag_law, names));

  s.model = m.get("model",
                  "add `model: A` or `model: B` (the VANS form; docs/models/fluid-forces.md, "
                  "\"Model A and model B\")")
                .choice<VansModel>("VANS model", {{"A", VansModel::A}, {"B", VansModel::B}});
  const Field forces = m.get("forces", "add `forces: [drag, pressure_gradient, viscous]`");
  s.forces = parse_forces(forces);
  if (const auto problem = force_list_problem(
          s.forces, {s.model, field.hydrostatic_pressure, gravity.norm() > 0}))
    forces.fail(*problem);
  s.virtual_mass_coefficient = m.number_or("virtual_mass_coefficient",
                                           kSphereVirtualMassCoefficient, kNonNegative);
  if (const auto c = m.find("virtual_mass_coefficient");
      c && std::find(s.forces.begin(), s.forces.end(), FluidForce::virtual_mass) == s.forces.end())
    c->fail_at_key(
        "has no effect without `virtual_mass` in fluid.forces; add virtual_mass to "
        "the list, or remove this key");
  s.thermal = parse_thermal(m, heat);
  return s;
}

}  // namespace grainflow
