// Void fraction from particles on a grid (centre method). References: the solid
// volume placed in each cell by construction (eps = 1 - sum V_p / V_cell, exact to
// round-off 1e-15), and the bookkeeping of clamps (count and removed volume).
#include <gtest/gtest.h>

#include <numbers>

#include "dem/fluid/void_fraction_grid.hpp"

namespace grainflow {
namespace {

Domain cube(double l, bool periodic) {
  Domain d;
  d.lo = Vec3::Zero();
  d.hi = Vec3::Constant(l);
  d.periodic = {periodic, periodic, periodic};
  return d;
}

TEST(VoidFractionGrid, CentreMethodPutsEachVolumeInItsCell) {
  VoidFractionGrid grid(cube(0.01, false), {0.005, 0.2});
  ASSERT_EQ(grid.cells(), (std::array<int, 3>{2, 2, 2}));
  Particles p;
  const double r = 5e-4;
  for (int k = 0; k < 3; ++k) p.add(k + 1, Vec3(0.001 + 0.001 * k, 0.002, 0.002), Vec3::Zero(), Vec3::Zero(), r, 0, 1000);
  p.add(4, Vec3(0.009, 0.009, 0.009), Vec3::Zero(), Vec3::Zero(), 2 * r, 0, 1000);
  grid.update(p, MPI_COMM_SELF);
  const double vc = 0.005 * 0.005 * 0.005;
  EXPECT_NEAR(grid.at(Vec3(0.002, 0.002, 0.002)), 1 - 3 * sphere_volume(r) / vc, 1e-15);
  EXPECT_NEAR(grid.at(Vec3(0.008, 0.008, 0.008)), 1 - sphere_volume(2 * r) / vc, 1e-15);
  EXPECT_EQ(grid.at(Vec3(0.008, 0.002, 0.002)), 1.0);
  EXPECT_EQ(grid.clamped_cells_total(), 0);
}

TEST(VoidFractionGrid, ClampsAreCountedWithTheVolumeTheyRemove) {
  VoidFractionGrid grid(cube(0.002, false), {0.002, 0.4});  // one cell of 8e-9 m^3
  Particles p;
  const double r = 6e-4;  // each 9.05e-10 m^3: 7 of them fill 79 % of the cell
  for (int k = 0; k < 7; ++k) p.add(k + 1, Vec3::Constant(0.001), Vec3::Zero(), Vec3::Zero(), r, 0, 1000);
  grid.update(p, MPI_COMM_SELF);
  const double eps = 1 - 7 * sphere_volume(r) / 8e-9;
  ASSERT_LT(eps, 0.4);
  EXPECT_EQ(grid.at(Vec3::Constant(0.001)), 0.4);
  EXPECT_EQ(grid.clamped_cells_total(), 1);
  EXPECT_NEAR(grid.clamped_volume_total(), (0.4 - eps) * 8e-9, 1e-22);
}

TEST(VoidFractionGrid, PeriodicSidesWrap) {
  VoidFractionGrid grid(cube(0.01, true), {0.005, 0.2});
  Particles p;
  // Just past the upper x side (not yet wrapped between two rebuilds): belongs to x-cell 0.
  p.add(1, Vec3(0.0101, 0.001, 0.001), Vec3::Zero(), Vec3::Zero(), 5e-4, 0, 1000);
  grid.update(p, MPI_COMM_SELF);
  EXPECT_LT(grid.at(Vec3(0.001, 0.001, 0.001)), 1.0);
  EXPECT_EQ(grid.at(Vec3(0.009, 0.001, 0.001)), 1.0);
}

}  // namespace
}  // namespace grainflow
