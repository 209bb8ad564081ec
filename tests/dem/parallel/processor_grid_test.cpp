// The default processor grid (docs/parallel.md, "The default grid"), checked directly:
// choose_processor_grid against the cut areas worked out by hand for each box and rank
// count below (the area of a grid is (nx-1) Ly Lz + (ny-1) Lx Lz + (nz-1) Lx Ly), and
// balanced_cut_planes against the particle-count quantiles of coordinates chosen so that
// the even split is known exactly.
#include <gtest/gtest.h>

#include "dem/parallel/decomposition.hpp"

namespace grainflow {
namespace {

using Grid = std::array<int, 3>;

TEST(ProcessorGrid, LeastCutAreaOfTheDomain) {
  // A cube: every single cut has the same area; equal areas go to x.
  EXPECT_EQ(choose_processor_grid(2, Vec3(1, 1, 1)), (Grid{2, 1, 1}));
  // 8 ranks in a cube: 2 x 2 x 2 (area 3) beats 4 x 2 x 1 (4) and 8 x 1 x 1 (7).
  EXPECT_EQ(choose_processor_grid(8, Vec3(1, 1, 1)), (Grid{2, 2, 2}));
  // A tall box is cut across its height (area 1 against 10).
  EXPECT_EQ(choose_processor_grid(2, Vec3(1, 1, 10)), (Grid{1, 1, 2}));
  // 6 ranks in 3 x 2 x 1: 3 x 2 x 1 has area 2*2 + 1*3 = 7; the next, 2 x 3 x 1, has 8;
  // 6 x 1 x 1 and 3 x 1 x 2 have 10.
  EXPECT_EQ(choose_processor_grid(6, Vec3(3, 2, 1)), (Grid{3, 2, 1}));
  // A prime rank count has three candidates; 7 ranks along the long z.
  EXPECT_EQ(choose_processor_grid(7, Vec3(1, 1, 10)), (Grid{1, 1, 7}));
  // One rank.
  EXPECT_EQ(choose_processor_grid(1, Vec3(1, 2, 3)), (Grid{1, 1, 1}));
}

TEST(ProcessorGrid, TallColumnOnTwoRanksIsCutAlongItsHeight) {
  // Issue 18: a 4 x 4 x 40 mm column, interaction range 2.4 mm. 2 x 1 x 1 gives 2 mm thick
  // boxes (refused); 1 x 1 x 2 gives 20 mm.
  const Vec3 column(0.004, 0.004, 0.04);
  EXPECT_EQ(choose_processor_grid(2, column, 0.0024), (Grid{1, 1, 2}));
  // 4 ranks: only 1 x 1 x 4 has boxes thicker than 3 mm (10 mm; the others 2 mm).
  EXPECT_EQ(choose_processor_grid(4, column, 0.003), (Grid{1, 1, 4}));
}

TEST(ProcessorGrid, ThickEnoughBoxesBeatALeastArea) {
  // A column of particles (extent 0.5 x 0.5 x 4) in a 4 m cube, 8 ranks, boxes >= 1.5 m:
  // 1 x 1 x 8 cuts least (7 * 0.25 = 1.75) but its boxes are 0.5 m thick; of the grids
  // that fit only 2 x 2 x 2 (2 m boxes, area 2 + 2 + 0.25 = 4.25) is left.
  EXPECT_EQ(choose_processor_grid(8, Vec3(4, 4, 4), 1.5, Vec3(0.5, 0.5, 4)), (Grid{2, 2, 2}));
  // No grid fits (4 ranks in 4 x 1 x 1, boxes >= 1.5): the least area, 4 x 1 x 1 (3);
  // the caller then refuses the scene with its own message.
  EXPECT_EQ(choose_processor_grid(4, Vec3(4, 1, 1), 1.5), (Grid{4, 1, 1}));
}

TEST(ProcessorGrid, TheParticlesExtentChoosesTheCut) {
  // A settled bed 70 x 70 x 50 mm in a 70 x 70 x 280 mm domain, 2 ranks. The domain alone
  // says: cut z (70 x 70 against 70 x 280). Through the bed a cut along z is 70 x 70 =
  // 4900 mm^2, one along x or y 70 x 50 = 3500 mm^2: cut x.
  const Vec3 domain(0.07, 0.07, 0.28), bed(0.07, 0.07, 0.05);
  EXPECT_EQ(choose_processor_grid(2, domain), (Grid{1, 1, 2}));
  EXPECT_EQ(choose_processor_grid(2, domain, 0.0024, bed), (Grid{2, 1, 1}));
  // A wide, shallow layer (200 x 40 x 10) in a cube, 4 ranks: 4 x 1 x 1 cuts 3 * 400 =
  // 1200; 2 x 2 x 1 cuts 400 + 2000 = 2400.
  EXPECT_EQ(choose_processor_grid(4, Vec3(200, 200, 200), 1, Vec3(200, 40, 10)), (Grid{4, 1, 1}));
}

TEST(ProcessorGrid, CutPlanesSplitTheParticleCount) {
  // 100 coordinates 0.5, 1.5, ..., 99.5: the even split of 2 falls between 49.5 and 50.5.
  std::vector<double> x;
  for (int i = 0; i < 100; ++i) x.push_back(i + 0.5);
  EXPECT_EQ(balanced_cut_planes(x, 0, 100, 2, 1), (std::vector<double>{0, 50, 100}));
  EXPECT_EQ(balanced_cut_planes(x, 0, 100, 4, 1), (std::vector<double>{0, 25, 50, 75, 100}));
  // A bed in the lowest tenth of the domain, 2 ranks: the plane at its median, 5 ...
  std::vector<double> bed;
  for (int i = 0; i < 100; ++i) bed.push_back(0.1 * i + 0.05);
  EXPECT_NEAR(balanced_cut_planes(bed, 0, 100, 2, 1)[1], 5, 1e-12);
  // ... unless boxes must be at least 20 thick: then at 20 (the least move that fits).
  EXPECT_NEAR(balanced_cut_planes(bed, 0, 100, 2, 20)[1], 20, 1e-6);
  // Every coordinate at one point, 3 boxes of at least 3 in [0, 10]: planes at 3 and 6.
  const auto piled = balanced_cut_planes(std::vector<double>(50, 0.1), 0, 10, 3, 3);
  EXPECT_NEAR(piled[1], 3, 1e-6);
  EXPECT_NEAR(piled[2], 6, 1e-6);
  EXPECT_GE(piled[2] - piled[1], 3);
  EXPECT_GE(piled[3] - piled[2], 3);
  // No coordinates: uniform planes.
  EXPECT_EQ(balanced_cut_planes({}, 0, 9, 3, 1), (std::vector<double>{0, 3, 6, 9}));
}

}  // namespace
}  // namespace grainflow
