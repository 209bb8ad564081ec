#pragma once
// The scene's `fluid:` block (one-way mode, docs/scene-reference.md): a prescribed fluid
// field and the fluid forces to apply. Validated here — drag-law name, force list against
// model A/B (dem/fluid/vans_model.hpp) — so errors point at file:line:column.
#include <optional>

#include "dem/fluid/prescribed_fluid.hpp"
#include "dem/scene/scene.hpp"
#include "dem/scene/yaml_reader.hpp"

namespace grainflow {

// `heat`: the scene's heat settings; the fluid's `temperature` (with heat_capacity,
// conductivity, convection) needs heat on. `domain`: a shear may not vary along a periodic
// axis.
FluidSettings parse_fluid_section(const scene_yaml::Field& f, const Vec3& gravity,
                                  const Domain& domain, const std::optional<HeatSettings>& heat);

}  // namespace grainflow
