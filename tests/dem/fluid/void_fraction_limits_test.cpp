// The one-way void-fraction grid's limits (issue 17 items 5 and 7).
// - Memory: a grid beyond kMaxVoidFractionCells = 2^26 cells is refused before allocation,
//   with the cells, the bytes and the smallest cell_size that fits; a grid of exactly 2^26
//   cells is accepted. Reference: the cell counts by hand (round(L / cell) per axis).
// - The clamp report prints the removed volume with significant digits: one cell of 8e-9
//   m^3 with 7 spheres of r = 0.6 mm (solid fraction 0.792) clamped to eps_min = 0.4 loses
//   (0.4 - (1 - 7 V_p / V_c)) V_c = 1.533e-09 m^3 per update (std::to_string printed 0.000000).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "dem/engine/force_term.hpp"
#include "dem/fluid/fluid_forces.hpp"
#include "dem/fluid/void_fraction_grid.hpp"

namespace grainflow {
namespace {

using ::testing::HasSubstr;

Domain box(const Vec3& hi) {
  Domain d;
  d.lo = Vec3::Zero();
  d.hi = hi;
  return d;
}

TEST(VoidFractionGridLimits, GridBeyondTheCellLimitIsRefusedBeforeAllocation) {
  // 2 m cube, 2 mm cells: 1000^3 = 1e9 cells, 16 GB (the reproduction of issue 17).
  const Domain huge = box(Vec3::Constant(2));
  const VoidFractionGridSettings fine{0.002, 0.2};
  const std::string why = void_fraction_grid_too_large(huge, fine);
  EXPECT_EQ(why,
            "cell_size 0.002 m over the domain's 2 x 2 x 2 m gives 1000 x 1000 x 1000 = 1e+09 "
            "cells, 16 GB on every rank; the limit is 67108864 cells (1.074 GB). Use cell_size "
            ">= 0.00493 m (the grid covers the whole domain), or a smaller domain");
  EXPECT_THROW(VoidFractionGrid(huge, fine), std::length_error);
  // The proposed cell size fits: round(2 / 0.00493) = 406 per axis, 406^3 = 66 923 416.
  EXPECT_EQ(void_fraction_grid_too_large(huge, {0.00493, 0.2}), "");
  // Exactly 2^26 = 4096 x 4096 x 4 cells of 1 mm: accepted; one more row of cells: refused.
  EXPECT_EQ(void_fraction_grid_too_large(box(Vec3(4.096, 4.096, 0.004)), {0.001, 0.2}), "");
  EXPECT_THAT(void_fraction_grid_too_large(box(Vec3(4.097, 4.096, 0.004)), {0.001, 0.2}),
              HasSubstr("gives 4097 x 4096 x 4 = 6.713e+07 cells"));
}

TEST(VoidFractionGridLimits, ClampReportHasSignificantDigits) {
  FluidSettings s;
  s.field.density = 1000;
  s.field.viscosity = 1e-3;
  s.computed_void_fraction = VoidFractionGridSettings{0.002, 0.4};  // one cell of 8e-9 m^3
  s.forces = {FluidForce::drag, FluidForce::pressure_gradient, FluidForce::viscous};
  const auto term = make_fluid_forces(s, Vec3::Zero(), box(Vec3::Constant(0.002)), MPI_COMM_SELF);
  Particles p;
  const double r = 6e-4;
  for (int k = 0; k < 7; ++k)
    p.add(k + 1, Vec3::Constant(0.001), Vec3::Zero(), Vec3::Zero(), r, 0, 2500);
  ImplicitDrag drag;
  drag.coefficient.assign(p.size(), 0.0);
  drag.fluid_velocity.assign(p.size(), Vec3::Zero());
  term->add(p, 0, drag);
  const double removed = (0.4 - (1 - 7 * sphere_volume(r) / 8e-9)) * 8e-9;
  ASSERT_NEAR(removed, 1.533e-9, 5e-13);
  EXPECT_THAT(term->report(), HasSubstr("void fraction: 1 x 1 x 1 cells; clamped to the minimum 1 "
                                        "times (cell-steps), removing 1.533e-09 m^3"));
}

}  // namespace
}  // namespace grainflow
