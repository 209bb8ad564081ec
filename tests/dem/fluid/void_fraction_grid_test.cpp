// Void fraction from particles on a grid (centre method). References: the solid
// volume placed in each cell by construction (eps = 1 - sum V_p / V_cell, exact to
// round-off 1e-15), and the bookkeeping of clamps (count and removed volume). The sum does not
// depend on the particles' order (so neither on how ranks split them): the same bits.
#include "dem/fluid/void_fraction_grid.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <numbers>
#include <random>
#include <vector>

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

// 200 particles (r 0.63-1.26 mm) in 8 cells of 5 mm, 38 to 96 % solid, stored in three orders:
// every cell's eps has the same bits (the volumes are summed exactly, so the split of the
// particles over ranks cannot change eps either), and each agrees with the sum of the volumes
// in long double. Summed in doubles, cells differed in the last bits between the orders.
TEST(VoidFractionGrid, TheSumDoesNotDependOnTheParticlesOrder) {
  VoidFractionGrid grid(cube(0.01, false), {0.005, 0.0});
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> at(0.0, 0.01), exponent(-2.9, -2.6);
  struct Bead {
    Vec3 x;
    double r;
  };
  std::vector<Bead> beads;
  for (int k = 0; k < 200; ++k)
    beads.push_back({Vec3(at(rng), at(rng), at(rng)), 0.5 * std::pow(10.0, exponent(rng))});
  const auto eps_of = [&](const std::vector<Bead>& list) {
    Particles p;
    for (std::size_t k = 0; k < list.size(); ++k)
      p.add(static_cast<long>(k) + 1, list[k].x, Vec3::Zero(), Vec3::Zero(), list[k].r, 0, 1000);
    grid.update(p, MPI_COMM_SELF);
    std::vector<double> eps;
    for (int c = 0; c < 8; ++c)
      eps.push_back(grid.at(Vec3(0.0025 + 0.005 * (c & 1), 0.0025 + 0.005 * ((c >> 1) & 1),
                                 0.0025 + 0.005 * (c >> 2))));
    return eps;
  };
  const std::vector<double> first = eps_of(beads);
  std::vector<Bead> shuffled = beads;
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  EXPECT_EQ(eps_of(shuffled), first);
  std::reverse(shuffled.begin(), shuffled.end());
  EXPECT_EQ(eps_of(shuffled), first);
  const double vc = 0.005 * 0.005 * 0.005;
  for (int c = 0; c < 8; ++c) {
    long double solid = 0;
    for (const Bead& b : beads) {
      const int cell = (b.x.x() >= 0.005) + 2 * (b.x.y() >= 0.005) + 4 * (b.x.z() >= 0.005);
      if (cell == c) solid += static_cast<long double>(sphere_volume(b.r));
    }
    EXPECT_NEAR(first[c], 1 - static_cast<double>(solid / vc), 1e-15) << "cell " << c;
  }
}

}  // namespace
}  // namespace grainflow
