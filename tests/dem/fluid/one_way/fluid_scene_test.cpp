// The scene's `fluid:` block: a valid block is read into FluidSettings, and each kind of
// mistake is a SceneError at the offending line with the reason (model A/B refusals keep
// the wording of dem/fluid/vans_model.cpp).
#include <gtest/gtest.h>

#include <string>

#include "dem/scene/scene_parser.hpp"

namespace grainflow {
namespace {

const std::string kHead = R"(domain: {min: [0, 0, 0], max: [1, 1, 1]}
gravity: [0, 0, -9.81]
time: {step: 1e-5, end: 1}
materials:
  - {name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}
interaction_defaults: {restitution: 0.5}
contact: {normal: hertz}
)";  // 7 lines: `fluid:` is line 8

std::string error_of(const std::string& fluid) {
  try {
    parse_scene(kHead + fluid, "fluid.yaml");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "no error";
}

TEST(FluidScene, ReadsAValidBlock) {
  const Scene s = parse_scene(kHead + R"(fluid:
  density: 1.2
  viscosity: 1.8e-5
  velocity: [1, 0, 0]
  shear: {rate: 10, flow_direction: [1, 0, 0], gradient_direction: [0, 0, 2]}
  void_fraction: 0.9
  pressure: {hydrostatic: false, gradient: [-5, 0, 0]}
  drag: beetstra
  model: A
  forces: [drag, pressure_gradient, viscous, buoyancy, saffman_mei]
)",
                              "fluid.yaml");
  ASSERT_TRUE(s.fluid.has_value());
  const FluidSettings& f = *s.fluid;
  EXPECT_EQ(f.field.density, 1.2);
  EXPECT_EQ(f.field.gradient_direction, Vec3::UnitZ());
  EXPECT_EQ(f.field.void_fraction, 0.9);
  EXPECT_FALSE(f.field.hydrostatic_pressure);
  EXPECT_EQ(f.drag_law, "beetstra");
  EXPECT_EQ(f.model, VansModel::A);
  EXPECT_EQ(f.forces.size(), 5u);
  EXPECT_EQ(f.source, "fluid.yaml:9");
  // The sampled field: u = u₀ + G z x̂, ω = G ẑ × x̂ = G ŷ, ∇p has no hydrostatic part.
  const FluidSample at = f.field.sample(Vec3(0, 0, 0.5), s.gravity);
  EXPECT_EQ(at.velocity, Vec3(6, 0, 0));
  EXPECT_EQ(at.vorticity, Vec3(0, 10, 0));
  EXPECT_EQ(at.pressure_gradient, Vec3(-5, 0, 0));
}

TEST(FluidScene, UnknownDragLawListsAll) {
  const std::string e = error_of(
      "fluid: {density: 1000, viscosity: 1e-3, drag: difelice, model: B,\n"
      "        forces: [drag, pressure_gradient, viscous]}\n");
  EXPECT_NE(e.find("fluid.yaml:8:"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown drag law 'difelice'; allowed: schiller_naumann, di_felice, rong"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("did you mean 'di_felice'"), std::string::npos) << e;
}

TEST(FluidScene, ModelBWithoutPressureGradientIsRefusedAtTheForceList) {
  const std::string e = error_of(R"(fluid:
  density: 1000
  viscosity: 1e-3
  drag: wen_yu
  model: B
  forces: [drag, viscous]
)");
  EXPECT_NE(e.find("fluid.yaml:13:"), std::string::npos) << e;
  EXPECT_NE(e.find("model B without 'pressure_gradient'"), std::string::npos) << e;
}

TEST(FluidScene, BuoyancyWithHydrostaticPressureIsRefused) {
  const std::string e = error_of(R"(fluid:
  density: 1000
  viscosity: 1e-3
  drag: wen_yu
  model: A
  forces: [drag, pressure_gradient, viscous, buoyancy]
)");
  EXPECT_NE(e.find("fluid.yaml:13:"), std::string::npos) << e;
  EXPECT_NE(e.find("buoyancy would count it twice"), std::string::npos) << e;
}

TEST(FluidScene, RangeAndUnknownKeyErrors) {
  EXPECT_NE(error_of("fluid: {density: 1000, viscosity: 0, drag: ergun, model: A, forces: [drag]}\n")
                .find("fluid.viscosity: value 0 is out of range; it must be > 0"),
            std::string::npos);
  EXPECT_NE(error_of("fluid: {density: 1000, viscosity: 1, voidage: 0.5}\n")
                .find("unknown key 'voidage' in fluid"),
            std::string::npos);
  EXPECT_NE(error_of("fluid: {density: 1000, viscosity: 1, void_fraction: 0.1, drag: ergun, "
                     "model: A, forces: [drag, pressure_gradient, viscous]}\n")
                .find("fluid.void_fraction: value 0.1 is out of range; it must be in [0.2, 1]"),
            std::string::npos);
}

}  // namespace
}  // namespace grainflow
