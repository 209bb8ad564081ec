// STL reading: format detection, placement, welding, counted repairs and errors
// that name the file and the line or triangle.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <numbers>

#include "dem/walls/stl_reader.hpp"

namespace grainflow {
namespace {

using ::testing::HasSubstr;

const char* kTwoTriangles = R"(solid square
  facet normal 0 0 1
    outer loop
      vertex 0 0 0
      vertex 1 0 0
      vertex 1 1 0
    endloop
  endfacet
  facet normal 0 0 1
    outer loop
      vertex 0 0 0
      vertex 1 1 0
      vertex 0 1 0
    endloop
  endfacet
endsolid square
)";

std::string binary_stl(const std::vector<std::array<float, 9>>& tris, const std::string& header) {
  std::string b(80, ' ');
  b.replace(0, header.size(), header);
  const auto n = static_cast<std::uint32_t>(tris.size());
  b.append(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : tris) {
    const float normal[3] = {0, 0, 1};
    b.append(reinterpret_cast<const char*>(normal), 12);
    b.append(reinterpret_cast<const char*>(t.data()), 36);
    b.append(2, '\0');
  }
  return b;
}

std::string error_of(const std::string& bytes) {
  try {
    parse_stl(bytes, "mesh.stl");
  } catch (const GeometryError& e) {
    return e.what();
  }
  return "no error";
}

TEST(StlReader, AsciiWeldsSharedVertices) {
  StlReport rep;
  const TriangleMesh m = parse_stl(kTwoTriangles, "square.stl", {}, &rep);
  EXPECT_FALSE(rep.binary);
  EXPECT_EQ(rep.facets_read, 2);
  EXPECT_EQ(m.triangle_count(), 2u);
  EXPECT_EQ(m.vertex_count(), 4u);  // 6 corners, 2 shared
}

// Many exporters start binary headers with "solid": the size decides.
TEST(StlReader, BinaryStartingWithSolidIsBinary) {
  const std::string b =
      binary_stl({{0, 0, 0, 1, 0, 0, 1, 1, 0}, {0, 0, 0, 1, 1, 0, 0, 1, 0}}, "solid exported");
  StlReport rep;
  const TriangleMesh m = parse_stl(b, "bin.stl", {}, &rep);
  EXPECT_TRUE(rep.binary);
  EXPECT_EQ(m.triangle_count(), 2u);
  EXPECT_EQ(m.vertex_count(), 4u);
}

TEST(StlReader, PlacementScalesRotatesThenTranslates) {
  MeshTransform t;
  t.scale = 2;
  t.rotation_axis = Vec3::UnitZ();
  t.rotation_angle = std::numbers::pi / 2;
  t.translation = Vec3(10, 0, 0);
  const TriangleMesh m = parse_stl(kTwoTriangles, "square.stl", t);
  // (1, 0, 0) -> scaled (2, 0, 0) -> rotated (0, 2, 0) -> translated (10, 2, 0).
  EXPECT_NEAR((m.vertices()[1] - Vec3(10, 2, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR(m.lo()[0], 8, 1e-12);
  EXPECT_NEAR(m.hi()[0], 10, 1e-12);
}

TEST(StlReader, DegenerateTrianglesAreRemovedAndCounted) {
  std::string text = kTwoTriangles;
  const std::string extra = R"(  facet normal 0 0 0
    outer loop
      vertex 0 0 0
      vertex 0 0 0
      vertex 1 1 0
    endloop
  endfacet
  facet normal 0 0 0
    outer loop
      vertex 0 0 0
      vertex 0.5 0.5 0
      vertex 1 1 0
    endloop
  endfacet
)";
  text.insert(text.find("endsolid"), extra);
  StlReport rep;
  const TriangleMesh m = parse_stl(text, "d.stl", {}, &rep);
  EXPECT_EQ(rep.facets_read, 4);
  EXPECT_EQ(rep.degenerate_removed, 2);  // repeated vertex; collinear vertices
  EXPECT_EQ(m.triangle_count(), 2u);
}

TEST(StlReader, BinaryCountMismatchIsAnError) {
  std::string b = binary_stl({{0, 0, 0, 1, 0, 0, 1, 1, 0}, {0, 0, 0, 1, 1, 0, 0, 1, 0}}, "x");
  b.resize(b.size() - 10);
  EXPECT_THAT(error_of(b), HasSubstr("mesh.stl: error: binary STL header declares 2 triangles"));
}

TEST(StlReader, NanVertexNamesTheTriangle) {
  const float nan = std::nanf("");
  const std::string b = binary_stl({{0, 0, 0, 1, 0, 0, 1, 1, 0}, {0, 0, 0, nan, 1, 0, 0, 1, 0}}, "x");
  EXPECT_THAT(error_of(b), HasSubstr("binary triangle 2 of 2: vertex 2 has a non-finite"));
  std::string a = kTwoTriangles;
  a.replace(a.find("vertex 1 1 0"), 12, "vertex nan 1 0");
  EXPECT_THAT(error_of(a), HasSubstr("mesh.stl:6: error: vertex coordinate 'nan' is not finite"));
}

TEST(StlReader, BrokenAsciiFacetsAreErrorsWithLines) {
  std::string four = kTwoTriangles;
  four.insert(four.find("    endloop"), "      vertex 2 2 0\n");
  EXPECT_THAT(error_of(four), HasSubstr("mesh.stl:2: error: facet 1 has 4 vertices"));
  std::string bad_number = kTwoTriangles;
  bad_number.replace(bad_number.find("vertex 1 0 0"), 12, "vertex 1 x 0");
  EXPECT_THAT(error_of(bad_number), HasSubstr("mesh.stl:5: error: coordinate 'x' is not a number"));
  const std::string text = kTwoTriangles;
  const std::string truncated = text.substr(0, text.find("    endloop", 200));
  EXPECT_THAT(error_of(truncated), HasSubstr("ends inside the facet begun at line 9"));
  EXPECT_THAT(error_of("hello"), HasSubstr("not an STL file"));
  EXPECT_THAT(error_of("solid empty\nendsolid empty\n"), HasSubstr("holds no triangles"));
}

}  // namespace
}  // namespace grainflow
