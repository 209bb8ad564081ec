// The shared decomposition (coupling/shared_decomposition.hpp): the DEM's processor grid read
// off the bounding boxes of the fluid's processor meshes. References are the layouts
// themselves, written out by hand here:
//  - simple (2 1 1) on a unit cube: 2 x 1 x 1 grid, cut planes {0, 0.5, 1} along x;
//  - a 2 x 2 x 1 grid with non-uniform cuts (x at 0.3, y at 1.4 of a 1 x 2 x 0.5 box), the
//    boxes listed in two different rank orders: each rank's coordinates follow its box;
//  - layouts that are not a grid of boxes (what scotch or metis produce: a cut with a step,
//    a box spanning two grid boxes, two ranks on one box) and a mesh that is not the scene's
//    domain are refused with DecompositionMismatch, whose message names the methods that
//    work (simple, hierarchical) or both extents.
// Cut planes are compared exactly where they are copied from the boxes (no arithmetic) and
// to the 1e-13 the test puts between two boxes' copies of one plane.
#include "coupling/shared_decomposition.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

namespace grainflow::coupling {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

Box box(std::array<double, 3> lo, std::array<double, 3> hi) { return Box{lo, hi}; }

// The message of the DecompositionMismatch that processor_grid_from_boxes throws, or "" if
// it returns.
std::string refusal(const std::vector<Box>& boxes, const Box& domain) {
  try {
    processor_grid_from_boxes(boxes, 0, domain);
  } catch (const DecompositionMismatch& e) {
    return e.what();
  }
  return "";
}

const Box kUnitCube = box({0, 0, 0}, {1, 1, 1});

TEST(SharedDecomposition, TwoBoxesAlongX) {
  const std::vector<Box> boxes = {box({0, 0, 0}, {0.5, 1, 1}), box({0.5, 0, 0}, {1, 1, 1})};
  for (int rank = 0; rank < 2; ++rank) {
    const ProcessorGrid g = processor_grid_from_boxes(boxes, rank, kUnitCube);
    EXPECT_EQ(g.dims, (std::array<int, 3>{2, 1, 1}));
    EXPECT_EQ(g.cuts[0], (std::vector<double>{0, 0.5, 1}));
    EXPECT_EQ(g.cuts[1], (std::vector<double>{0, 1}));
    EXPECT_EQ(g.cuts[2], (std::vector<double>{0, 1}));
    EXPECT_EQ(g.coords, (std::array<int, 3>{rank, 0, 0}));
  }
}

TEST(SharedDecomposition, TwoByTwoWithNonUniformCuts) {
  // A 1 x 2 x 0.5 m box cut at x = 0.3 and y = 1.4, in OpenFOAM's `simple` order (x
  // fastest) and in a shuffled order.
  const Box domain = box({0, 0, 0}, {1, 2, 0.5});
  const Box b00 = box({0, 0, 0}, {0.3, 1.4, 0.5}), b10 = box({0.3, 0, 0}, {1, 1.4, 0.5});
  const Box b01 = box({0, 1.4, 0}, {0.3, 2, 0.5}), b11 = box({0.3, 1.4, 0}, {1, 2, 0.5});
  const std::vector<std::vector<Box>> orders = {{b00, b10, b01, b11}, {b11, b00, b01, b10}};
  const std::vector<std::vector<std::array<int, 3>>> coords = {
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}, {{1, 1, 0}, {0, 0, 0}, {0, 1, 0}, {1, 0, 0}}};
  for (std::size_t o = 0; o < orders.size(); ++o)
    for (int rank = 0; rank < 4; ++rank) {
      SCOPED_TRACE("order " + std::to_string(o) + ", rank " + std::to_string(rank));
      const ProcessorGrid g = processor_grid_from_boxes(orders[o], rank, domain);
      EXPECT_EQ(g.dims, (std::array<int, 3>{2, 2, 1}));
      EXPECT_EQ(g.cuts[0], (std::vector<double>{0, 0.3, 1}));
      EXPECT_EQ(g.cuts[1], (std::vector<double>{0, 1.4, 2}));
      EXPECT_EQ(g.cuts[2], (std::vector<double>{0, 0.5}));
      EXPECT_EQ(g.coords, coords[o][rank]);
    }
}

TEST(SharedDecomposition, PlanesWithinToleranceAreOnePlane) {
  // Points written by decomposePar can differ in the last digits between processors: a cut
  // at 0.5 and 0.5 + 1e-13 is one plane (tolerance 1e-9 of the domain), and the outer
  // planes are the domain's, however the boxes round.
  const std::vector<Box> boxes = {box({-1e-13, 0, 0}, {0.5, 1, 1}),
                                  box({0.5 + 1e-13, 0, 0}, {1 + 1e-13, 1, 1})};
  const ProcessorGrid g = processor_grid_from_boxes(boxes, 1, kUnitCube);
  EXPECT_EQ(g.dims, (std::array<int, 3>{2, 1, 1}));
  ASSERT_EQ(g.cuts[0].size(), 3u);
  EXPECT_EQ(g.cuts[0][0], 0.0);
  EXPECT_NEAR(g.cuts[0][1], 0.5, 2e-13);  // either box's value of the shared plane
  EXPECT_EQ(g.cuts[0][2], 1.0);
  EXPECT_EQ(g.coords, (std::array<int, 3>{1, 0, 0}));
}

TEST(SharedDecomposition, RefusesACutWithAStep) {
  // What scotch makes of a cube on 2 ranks: rank 1 holds x > 0.5 below z = 0.5 and
  // x > 0.375 above, so the bounding boxes overlap and imply 3 boxes along x.
  const std::vector<Box> boxes = {box({0, 0, 0}, {0.5, 1, 1}), box({0.375, 0, 0}, {1, 1, 1})};
  EXPECT_THAT(refusal(boxes, kUnitCube),
              AllOf(HasSubstr("do not form a grid of boxes"),
                    HasSubstr("which would cut the domain into 3 boxes, not 2"),
                    HasSubstr("`simple`"), HasSubstr("`hierarchical`"), HasSubstr("scotch")));
}

TEST(SharedDecomposition, RefusesABoxSpanningTwoGridBoxes) {
  // 4 ranks on a 2 x 2 grid of planes, but rank 0 spans the whole lower row.
  const std::vector<Box> boxes = {box({0, 0, 0}, {1, 0.5, 1}), box({0, 0.5, 0}, {0.5, 1, 1}),
                                  box({0.5, 0.5, 0}, {1, 1, 1}), box({0, 0, 0}, {0.5, 0.5, 1})};
  EXPECT_THAT(refusal(boxes, kUnitCube),
              AllOf(HasSubstr("processor 0's cells span [0, 1] x [0, 0.5] x [0, 1]"),
                    HasSubstr("not one box of the processor grid"), HasSubstr("`simple`"),
                    HasSubstr("`hierarchical`")));
}

TEST(SharedDecomposition, RefusesTwoRanksOnOneBox) {
  const std::vector<Box> boxes = {box({0, 0, 0}, {0.5, 0.5, 1}), box({0, 0, 0}, {0.5, 0.5, 1}),
                                  box({0.5, 0, 0}, {1, 1, 1}), box({0, 0.5, 0}, {0.5, 1, 1})};
  EXPECT_THAT(refusal(boxes, kUnitCube), AllOf(HasSubstr("processors overlap: processor 1"),
                                               HasSubstr("`simple`"), HasSubstr("`hierarchical`")));
}

TEST(SharedDecomposition, RefusesAMeshThatIsNotTheDomain) {
  // The mesh is 1 m long along y, the scene's domain 1.2 m: both extents in the message.
  const Box domain = box({0, 0, 0}, {1, 1.2, 1});
  const std::vector<Box> boxes = {box({0, 0, 0}, {0.5, 1, 1}), box({0.5, 0, 0}, {1, 1, 1})};
  EXPECT_THAT(refusal(boxes, domain), AllOf(HasSubstr("the fluid mesh spans [0, 1] m along y"),
                                            HasSubstr("the scene's domain is [0, 1.2] m"),
                                            HasSubstr("must be the same box")));
  // One box, shifted: the lower face does not match either.
  EXPECT_THAT(refusal({box({0.1, 0, 0}, {1, 1, 1})}, kUnitCube),
              HasSubstr("the fluid mesh spans [0.1, 1] m along x"));
}

}  // namespace
}  // namespace grainflow::coupling
