// Model A / model B force-list checks (DESIGN.md §4, Zhou et al. 2010): each refusal and
// its reason, and which forces the exchange term carries.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "dem/fluid/vans_model.hpp"

namespace grainflow {
namespace {

using F = FluidForce;

std::string problem(const std::vector<F>& forces, VansModel m, bool hydrostatic = true,
                    bool gravity = true) {
  return force_list_problem(forces, {m, hydrostatic, gravity}).value_or("ok");
}

TEST(VansModel, AcceptsConsistentLists) {
  const std::vector<F> base = {F::drag, F::pressure_gradient, F::viscous};
  EXPECT_EQ(problem(base, VansModel::A), "ok");
  EXPECT_EQ(problem(base, VansModel::B), "ok");
  EXPECT_EQ(problem({F::drag, F::pressure_gradient, F::viscous, F::buoyancy, F::virtual_mass,
                     F::saffman_mei, F::magnus, F::rotational_drag},
                    VansModel::B, /*hydrostatic=*/false),
            "ok");
  EXPECT_EQ(problem(base, VansModel::A, false, /*gravity=*/false), "ok");
}

TEST(VansModel, RefusesMissingPressureGradientWithModelSpecificReason) {
  EXPECT_NE(problem({F::drag, F::viscous}, VansModel::A)
                .find("model A without 'pressure_gradient': the fluid momentum carries only ε∇p"),
            std::string::npos);
  EXPECT_NE(problem({F::drag, F::viscous}, VansModel::B)
                .find("model B without 'pressure_gradient': the fluid momentum carries the full ∇p"),
            std::string::npos);
}

TEST(VansModel, RefusesMissingViscous) {
  EXPECT_NE(problem({F::drag, F::pressure_gradient}, VansModel::A)
                .find("model A without 'viscous': the fluid momentum carries only ε∇·τ"),
            std::string::npos);
  EXPECT_NE(problem({F::drag, F::pressure_gradient}, VansModel::B).find("model B without 'viscous'"),
            std::string::npos);
}

TEST(VansModel, RefusesDoubleOrMissingBuoyancy) {
  const std::vector<F> with = {F::drag, F::pressure_gradient, F::viscous, F::buoyancy};
  EXPECT_NE(problem(with, VansModel::B, /*hydrostatic=*/true).find("would count it twice"),
            std::string::npos);
  EXPECT_NE(problem({F::drag, F::pressure_gradient, F::viscous}, VansModel::A, false)
                .find("the particles would miss ρ_f V_p g; add buoyancy"),
            std::string::npos);
}

TEST(VansModel, RefusesDuplicatesAndMissingDrag) {
  EXPECT_EQ(problem({F::drag, F::pressure_gradient, F::viscous, F::drag}, VansModel::B),
            "'drag' is listed twice; list each force once");
  EXPECT_EQ(problem({F::pressure_gradient, F::viscous}, VansModel::B),
            "the force list has no 'drag'; every fluid coupling needs it");
  EXPECT_THROW(check_force_list({F::pressure_gradient}, {}), std::invalid_argument);
}

TEST(VansModel, ExchangeCarriesPressureAndViscousOnlyInModelB) {
  for (F f : {F::pressure_gradient, F::viscous, F::buoyancy}) {
    EXPECT_FALSE(carried_by_exchange(f, VansModel::A)) << fluid_force_name(f);
    EXPECT_TRUE(carried_by_exchange(f, VansModel::B)) << fluid_force_name(f);
  }
  for (F f : {F::drag, F::virtual_mass, F::saffman_mei, F::magnus})
    EXPECT_TRUE(carried_by_exchange(f, VansModel::A) && carried_by_exchange(f, VansModel::B));
}

}  // namespace
}  // namespace grainflow
