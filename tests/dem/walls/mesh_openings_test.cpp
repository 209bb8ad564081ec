// The openings of open meshes (dem/walls/mesh_openings.hpp) and the coarse-graining warning
// built on them (dem/engine/parcel_limits.hpp). References: the widths of the holes the tests
// build, in closed form (the largest circle inside a regular N-gon of circumradius r:
// 2 r cos(pi/N); inside a rectangle or a slit of constant width: that width), and the rule
// itself (10 parcel diameters).
#include "dem/walls/mesh_openings.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>

#include "dem/engine/parcel_limits.hpp"
#include "dem/scene/scene_parser.hpp"
#include "tests/dem/walls/mesh_support.hpp"

namespace grainflow {
namespace {

using ::testing::HasSubstr;

// A ring between radii r0 and r1 at height z (N segments), centred on (cx, cy), normals up;
// r0 = 0 closes it into a disc. With dz, the outer circle is raised by dz: a hopper's cone.
test::MeshData ring(double r0, double r1, int n, double z, double dz = 0, double cx = 0,
                    double cy = 0) {
  test::MeshData m;
  for (int j = 0; j < n; ++j) {
    const double a = 2 * std::numbers::pi * j / n;
    m.v.emplace_back(cx + r0 * std::cos(a), cy + r0 * std::sin(a), z);
    m.v.emplace_back(cx + r1 * std::cos(a), cy + r1 * std::sin(a), z + dz);
  }
  for (int j = 0; j < n; ++j) {
    const int a = 2 * j, b = 2 * ((j + 1) % n), c = b + 1, d = a + 1;
    m.t.push_back({a, b, c});
    m.t.push_back({a, c, d});
  }
  return m;
}

// A w x h plate with a rectangular slot sx x sy in its middle (eight triangles around it).
test::MeshData slotted_plate(double w, double h, double sx, double sy) {
  test::MeshData m;
  const double xs[4] = {0, (w - sx) / 2, (w + sx) / 2, w},
               ys[4] = {0, (h - sy) / 2, (h + sy) / 2, h};
  for (double y : ys)
    for (double x : xs) m.v.emplace_back(x, y, 0);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      if (i == 1 && j == 1) continue;  // the slot
      const int a = 4 * j + i, b = a + 1, c = a + 5, d = a + 4;
      m.t.push_back({a, b, c});
      m.t.push_back({a, c, d});
    }
  return m;
}

TEST(MeshOpenings, AnAnnulusHasItsHoleNotItsRim) {
  const int n = 72;
  const double r0 = 0.018;
  const test::MeshData m = ring(r0, 0.038, n, 0);
  const std::vector<MeshOpening> o = mesh_openings(TriangleMesh(m.v, m.t));
  ASSERT_EQ(o.size(), 1u);
  const double exact = 2 * r0 * std::cos(std::numbers::pi / n);
  EXPECT_NEAR(o[0].width / exact, 1, 1e-9) << o[0].width;
  EXPECT_NEAR(o[0].perimeter, 2 * n * r0 * std::sin(std::numbers::pi / n), 1e-12);
  EXPECT_LT(o[0].centre.norm(), 1e-12);
  // Every other triangle turned the other way (an STL need not be oriented): the same hole.
  test::MeshData flipped = m;
  for (std::size_t t = 0; t < flipped.t.size(); t += 2) std::swap(flipped.t[t][1], flipped.t[t][2]);
  const std::vector<MeshOpening> f = mesh_openings(TriangleMesh(flipped.v, flipped.t));
  ASSERT_EQ(f.size(), 1u);
  EXPECT_NEAR(f[0].width / exact, 1, 1e-9);
}

TEST(MeshOpenings, ASlotIsAsWideAsItsShorterSide) {
  const test::MeshData m = slotted_plate(0.1, 0.08, 0.04, 0.01);
  const std::vector<MeshOpening> o = mesh_openings(TriangleMesh(m.v, m.t));
  ASSERT_EQ(o.size(), 1u);
  EXPECT_NEAR(o[0].width, 0.01, 1e-11);
  EXPECT_NEAR(o[0].perimeter, 0.1, 1e-12);
}

TEST(MeshOpenings, PlatesAndClosedSurfacesHaveNone) {
  const test::MeshData plate = test::flat_grid(4, 0.01, 0, 0, 0);
  EXPECT_TRUE(mesh_openings(TriangleMesh(plate.v, plate.t)).empty());
  const test::MeshData box = test::box(Vec3(0, 0, 0), Vec3(1, 1, 1));
  EXPECT_TRUE(mesh_openings(TriangleMesh(box.v, box.t)).empty());
}

// A 0.1 m floor and, in the same file, a separate 0.03 m plate standing on it (a baffle, no
// hole anywhere): each part's rim is its own outline, so there is no opening. (The baffle's
// outline had been taken for a hole 0.03 m wide.)
TEST(MeshOpenings, ASeparatePartIsNotAnOpening) {
  test::MeshData m = test::flat_grid(10, 0.01, 0, 0, 0);
  const int base = static_cast<int>(m.v.size());
  for (const double z : {0.03, 0.06})
    for (const double y : {0.035, 0.065}) m.v.emplace_back(0.05, y, z);
  m.t.push_back({base, base + 1, base + 3});
  m.t.push_back({base, base + 3, base + 2});
  EXPECT_TRUE(mesh_openings(TriangleMesh(m.v, m.t)).empty());
}

// A 0.1 m plate of 5 mm cells with a serpentine slit one cell wide and 73 cells long: its loop
// (0.74 m) is longer than the plate's rim (0.40 m), but lies inside the rim's hull. The slit
// is the opening: the largest circle in it sits in a bend, touching the two outer sides and the
// inner corner, of diameter 2 (2 - sqrt 2) w = 1.17 w for the width w = 5 mm. (Taken as the rim
// by its length, it had gone unwarned.)
TEST(MeshOpenings, ALongSlitIsAsWideAsItIsAcross) {
  const int n = 20;
  const double h = 0.005;
  std::vector<std::vector<bool>> slit(n, std::vector<bool>(n, false));  // [row][column]
  for (const int row : {2, 6, 10, 14})
    for (int c = 2; c <= 17; ++c) slit[row][c] = true;
  for (int r = 3; r <= 5; ++r) slit[r][17] = true;
  for (int r = 7; r <= 9; ++r) slit[r][2] = true;
  for (int r = 11; r <= 13; ++r) slit[r][17] = true;
  const test::MeshData grid = test::flat_grid(n, h, 0, 0, 0);
  test::MeshData m;
  m.v = grid.v;
  for (std::size_t t = 0; t < grid.t.size(); ++t) {
    const int cell = static_cast<int>(t / 2);  // flat_grid: two triangles per cell, row by row
    if (!slit[cell / n][cell % n]) m.t.push_back(grid.t[t]);
  }
  const std::vector<MeshOpening> o = mesh_openings(TriangleMesh(m.v, m.t));
  ASSERT_EQ(o.size(), 1u);
  EXPECT_GT(o[0].perimeter, 0.7);
  EXPECT_NEAR(o[0].width / (2 * (2 - std::sqrt(2.0)) * h), 1, 1e-9);
}

TEST(MeshOpenings, AConicalHopperHasItsOrificeNotItsTop) {
  const int n = 48;
  const double r0 = 0.005;
  const test::MeshData m = ring(r0, 0.04, n, 0, 0.05);
  const std::vector<MeshOpening> o = mesh_openings(TriangleMesh(m.v, m.t));
  ASSERT_EQ(o.size(), 1u);
  EXPECT_NEAR(o[0].width / (2 * r0 * std::cos(std::numbers::pi / n)), 1, 1e-9);
  EXPECT_NEAR(o[0].centre[2], 0, 1e-15);
}

// The warning at start-up: the hopper benchmark's floor (an annulus, orifice 36 mm as a 72-gon,
// 35.97 mm across its flats) under parcels of 6 mm (k = 3 of 2 mm beads): 5.99 parcel
// diameters, warned of; under parcels of 3.5 mm (10.3 diameters): not. The orifice of a
// conical hopper below the domain is not one particles reach.
TEST(ParcelOpeningWarnings, AnOrificeOfFewParcelDiametersIsNamed) {
  test::write_mesh(ring(0.018, 0.038, 72, 0), "orifice_floor.stl");
  const std::string head = R"(time: {step: 1.0e-5, end: 0.01}
materials: [{name: glass, youngs_modulus: 1.0e7, poisson_ratio: 0.3, density: 2500}]
interaction_defaults: {restitution: 0.5, friction: 0.3}
contact: {normal: hertz}
walls: [{type: mesh, name: floor, file: orifice_floor.stl, material: glass}]
)";
  const std::string label =
      (std::filesystem::path(GRAINFLOW_BINARY_DIR) / "test_output" / "walls" / "hopper.yaml")
          .string();
  const Scene s =
      parse_scene("domain: {min: [-0.04, -0.04, -0.05], max: [0.04, 0.04, 0.1]}\n" + head, label);
  const WallSet walls(s);
  const auto parcels = [](double d) {
    ParcelClass c;
    c.name = "glass[k=3]";
    c.k = 3;
    c.parcels = 10;
    c.real = 270;
    c.largest_diameter = d;
    return std::vector<ParcelClass>{c};
  };
  const std::vector<std::string> w = parcel_opening_warnings(parcels(0.006), walls, s.domain);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_THAT(w[0], HasSubstr("warning: wall 'floor' has an opening 0.03597 m wide around (0, "
                              "0, 0) m: 5.99 diameters of parcels 'glass[k=3]' (0.006 m), "
                              "fewer than 10;"));
  EXPECT_TRUE(parcel_opening_warnings(parcels(0.0035), walls, s.domain).empty());
  EXPECT_TRUE(parcel_opening_warnings({}, walls, s.domain).empty());
  // A conical hopper, orifice at z = 0, in a domain from z = 0.01: out of reach; from z = 0: named.
  test::write_mesh(ring(0.018, 0.038, 72, 0, 0.05), "orifice_cone.stl");
  std::string cone = head;
  cone.replace(cone.find("orifice_floor"), 13, "orifice_cone");
  for (const double z0 : {0.01, 0.0}) {
    const Scene s2 = parse_scene("domain: {min: [-0.04, -0.04, " + std::to_string(z0) +
                                     "], max: [0.04, 0.04, 0.1]}\n" + cone,
                                 label);
    EXPECT_EQ(parcel_opening_warnings(parcels(0.006), WallSet(s2), s2.domain).size(),
              z0 > 0 ? 0u : 1u)
        << z0;
  }
}

}  // namespace
}  // namespace grainflow
