// The domain rule for coarse-grained parcels (dem/engine/parcel_limits.hpp): a warning when
// the domain's narrowest side is under 10 parcel diameters. Reference: the rule itself, 10 d,
// and which side is named: a bounded side speaks of walls, a periodic side (no walls there)
// only of the bed's structures; of equally narrow sides the bounded one is named.
#include "dem/engine/parcel_limits.hpp"

#include <gtest/gtest.h>

namespace grainflow {
namespace {

std::vector<ParcelClass> parcels(double diameter) {
  ParcelClass c;
  c.name = "glass[k=2]";
  c.k = 2;
  c.parcels = 10;
  c.real = 80;
  c.largest_diameter = diameter;
  return {c};
}

TEST(ParcelDomainWarnings, TenParcelDiametersAcrossTheNarrowestSide) {
  const Vec3 box(0.06, 0.009, 0.24);
  EXPECT_TRUE(parcel_domain_warnings(parcels(0.0009), box, {false, false, false}).empty());
  EXPECT_TRUE(parcel_domain_warnings({}, box, {false, false, false}).empty());
  const auto walls = parcel_domain_warnings(parcels(0.0024), box, {false, false, false});
  ASSERT_EQ(walls.size(), 1u);
  EXPECT_EQ(walls[0].rfind("warning: the domain's narrowest side (0.009 m) is less than 10 "
                           "diameters of parcels 'glass[k=2]' (0.0024 m): walls and the bed's own "
                           "structures",
                           0),
            0u)
      << walls[0];
}

TEST(ParcelDomainWarnings, APeriodicSideHasNoWalls) {
  const auto periodic =
      parcel_domain_warnings(parcels(0.0024), Vec3(0.06, 0.009, 0.24), {false, true, false});
  ASSERT_EQ(periodic.size(), 1u);
  EXPECT_EQ(periodic[0].rfind("warning: the domain's narrowest side (0.009 m, periodic along y) "
                              "is less than 10 diameters of parcels 'glass[k=2]' (0.0024 m): the "
                              "bed's own structures (bubbles, shear bands)",
                              0),
            0u)
      << periodic[0];
  // Equally narrow sides, one bounded: the bounded one (its walls) is named.
  const auto tie =
      parcel_domain_warnings(parcels(0.0024), Vec3(0.009, 0.009, 0.24), {false, true, false});
  ASSERT_EQ(tie.size(), 1u);
  EXPECT_NE(tie[0].find("(0.009 m) is less"), std::string::npos) << tie[0];
  EXPECT_NE(tie[0].find("walls and"), std::string::npos) << tie[0];
}

}  // namespace
}  // namespace grainflow
