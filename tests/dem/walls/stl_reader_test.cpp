// STL reading: format detection, placement, welding, counted repairs and errors
// that name the file and the line or triangle.
#include "dem/walls/stl_reader.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>

#include "dem/scene/scene_parser.hpp"
#include "dem/walls/wall_set.hpp"
#include "tests/dem/walls/mesh_support.hpp"

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

// --- Hostile and broken files (docs/reliability.md, "Hostile input") ---

std::string with_count(std::string b, std::uint32_t n) {
  std::memcpy(b.data() + 80, &n, 4);
  return b;
}

const std::vector<std::array<float, 9>> kSquare = {{0, 0, 0, 1, 0, 0, 1, 1, 0},
                                                   {0, 0, 0, 1, 1, 0, 0, 1, 0}};

// A header claiming 4e9 triangles (200 GB) in a 184-byte file: the count is only
// compared with the size, never used to allocate.
TEST(StlReader, HugeBinaryCountIsAnErrorWithoutAllocating) {
  const std::string b = with_count(binary_stl(kSquare, "x"), 4'000'000'000u);
  EXPECT_THAT(error_of(b), HasSubstr("mesh.stl: error: binary STL header declares 4000000000 "
                                     "triangles (200000000084 bytes) but the file has 184 bytes; "
                                     "the file is truncated"));
}

TEST(StlReader, BinaryCountBelowTheFileSizeIsAnError) {
  const std::string b = with_count(binary_stl(kSquare, "x"), 1);
  EXPECT_THAT(error_of(b), HasSubstr("declares 1 triangles (134 bytes) but the file has 184 bytes; "
                                     "bytes are left over after the declared triangles"));
}

// A binary file whose header starts with "solid" and whose count is wrong is reported
// as a binary file with a wrong count, not as ASCII text full of unreadable words.
TEST(StlReader, SolidHeaderWithWrongCountIsReportedAsBinary) {
  const std::string b = with_count(binary_stl(kSquare, "solid exported"), 3);
  EXPECT_THAT(error_of(b), HasSubstr("binary STL header declares 3 triangles (234 bytes) but the "
                                     "file has 184 bytes; the file is truncated or not an STL file "
                                     "(it starts with 'solid' but holds NUL or control bytes, so "
                                     "it is not an ASCII STL either)"));
}

TEST(StlReader, EmptyShortAndTruncatedFilesAreErrors) {
  EXPECT_THAT(error_of(""), HasSubstr("mesh.stl: error: not an STL file"));
  EXPECT_THAT(error_of(std::string(40, '\0')), HasSubstr("not an STL file"));
  // A binary file cut inside its header, and one cut inside its last triangle.
  const std::string b = binary_stl(kSquare, "x");
  EXPECT_THAT(error_of(b.substr(0, 83)), HasSubstr("not an STL file"));
  EXPECT_THAT(error_of(b.substr(0, 180)), HasSubstr("declares 2 triangles (184 bytes) but the file "
                                                    "has 180 bytes; the file is truncated"));
  EXPECT_THAT(error_of("solid only\n"), HasSubstr("the STL file holds no triangles"));
}

TEST(StlReader, InfiniteVerticesAreErrors) {
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_THAT(error_of(binary_stl({{0, 0, 0, 1, 0, 0, 1, 1, -inf}}, "x")),
              HasSubstr("binary triangle 1 of 1: vertex 3 has a non-finite coordinate"));
  std::string a = kTwoTriangles;
  a.replace(a.find("vertex 1 0 0"), 12, "vertex 1 inf 0");
  EXPECT_THAT(error_of(a), HasSubstr("mesh.stl:5: error: vertex coordinate 'inf' is not finite"));
  // A finite vertex that the placement's scale pushes beyond the double range.
  MeshTransform huge;
  huge.scale = 1e300;
  try {
    parse_stl(binary_stl({{0, 0, 0, 3e38f, 0, 0, 0, 3e38f, 0}}, "x"), "big.stl", huge);
    ADD_FAILURE() << "expected GeometryError";
  } catch (const GeometryError& e) {
    EXPECT_THAT(e.what(), HasSubstr("big.stl: error: the placement (scale 1e+300)"));
    EXPECT_THAT(e.what(), HasSubstr("moves a vertex to a non-finite position"));
  }
}

TEST(StlReader, DegenerateBinaryTrianglesAreCountedAndAllDegenerateIsAnError) {
  StlReport rep;
  const TriangleMesh m =
      parse_stl(binary_stl({kSquare[0], {0, 0, 0, 0, 0, 0, 1, 1, 0}, {0, 0, 0, 2, 0, 0, 4, 0, 0}},
                           "x"),
                "d.stl", {}, &rep);
  EXPECT_TRUE(rep.binary);
  EXPECT_EQ(rep.facets_read, 3);
  EXPECT_EQ(rep.degenerate_removed, 2);
  EXPECT_EQ(m.triangle_count(), 1u);
  EXPECT_THAT(error_of(binary_stl({{0, 0, 0, 0, 0, 0, 1, 1, 0}, {0, 0, 0, 1, 1, 1, 2, 2, 2}}, "x")),
              HasSubstr("all 2 triangles of the STL file are degenerate (zero area)"));
}

// The repair is reported where a user sees it: the run's report line for the wall.
TEST(StlReader, DegenerateRemovalIsReportedForTheWall) {
  const auto dir = std::filesystem::temp_directory_path() / "grainflow_stl_report";
  std::filesystem::create_directories(dir);
  std::ofstream((dir / "d.stl").string(), std::ios::binary)
      << binary_stl({kSquare[0], kSquare[1], {0, 0, 0, 0, 0, 0, 1, 1, 0}}, "x");
  const Scene scene = parse_scene(R"(domain: {min: [-1, -1, -1], max: [2, 2, 2]}
time: {step: 1.0e-5, end: 0.01}
materials: [{name: glass, youngs_modulus: 1.0e7, poisson_ratio: 0.3, density: 2500}]
interaction_defaults: {restitution: 0.5}
contact: {normal: hertz}
walls: [{type: mesh, name: floor, file: d.stl, material: glass}]
)",
                                  (dir / "scene.yaml").string());
  const WallSet walls(scene);
  ASSERT_EQ(walls.notes().size(), 1u);
  EXPECT_THAT(walls.notes()[0], HasSubstr("wall 'floor': 2 triangles, 4 vertices from binary STL"));
  EXPECT_THAT(walls.notes()[0], HasSubstr("(1 degenerate triangles removed)"));
}

// The near-miss seam of issue 18: a 4 x 4 flat grid (16 mm, 32 triangles, 25 vertices)
// whose right half has its own 5 vertices on the line x = 0, 1e-7 m off. Welded with the
// default tolerance (1e-5 of the 22.6 mm diagonal = 2.3e-7 m): 5 vertices welded, 25 left,
// and the 16 rim edges are the only open ones. With weld_tolerance 0: 30 vertices, the 4 + 4
// seam edges open too, and the seam is reported 1e-7 m wide. Reference: counted by hand.
TEST(StlReader, NearMissVerticesAreWeldedAndCounted) {
  const test::MeshData seam =
      test::split_at(test::flat_grid(4, 0.004, -0.008, -0.008, 0), 0.0, Vec3(0.6e-7, 0, 0.8e-7));
  const std::string path = test::write_mesh(seam, "seam_report.stl");
  StlReport rep;
  const TriangleMesh welded = read_stl(path, {}, &rep);
  EXPECT_EQ(welded.vertex_count(), 25u);
  EXPECT_EQ(welded.triangle_count(), 32u);
  EXPECT_EQ(rep.welded, 5);
  EXPECT_EQ(rep.open_edges, 16);
  EXPECT_EQ(rep.seam_gap, -1);
  EXPECT_NEAR(rep.weld_distance, 1e-5 * std::sqrt(2.0) * 0.016, 1e-12);
  // Placement scales the stated distance with the mesh.
  MeshTransform mm;
  mm.scale = 1000;
  StlReport scaled;
  read_stl(path, mm, &scaled);
  EXPECT_EQ(scaled.welded, 5);
  EXPECT_NEAR(scaled.weld_distance, 1000 * rep.weld_distance, 1e-9);

  StlReport open;
  const TriangleMesh apart = read_stl(path, {}, &open, 0.0);
  EXPECT_EQ(apart.vertex_count(), 30u);
  EXPECT_EQ(open.welded, 0);
  EXPECT_EQ(open.open_edges, 24);
  EXPECT_NEAR(open.seam_gap, 1e-7, 1e-12);
  EXPECT_NEAR(open.seam_at[0], 0, 1e-6);
}

// A strip of 3000 cells: its rim vertices two cells apart share no triangle and are closer
// than 1e-3 of the diagonal, but they are the rim's own, not a seam (no warning; there was one).
// Reference: the strip has no seam and no T-junction by construction.
TEST(StlReader, AFinelyDividedRimIsNoSeam) {
  test::MeshData m;
  const int n = 3000;
  const double h = 1e-3;
  for (int i = 0; i <= n; ++i) {
    m.v.emplace_back(i * h, 0, 0);
    m.v.emplace_back(i * h, h, 0);
  }
  for (int i = 0; i < n; ++i) {
    m.t.push_back({2 * i, 2 * i + 2, 2 * i + 3});
    m.t.push_back({2 * i, 2 * i + 3, 2 * i + 1});
  }
  StlReport rep;
  read_stl(test::write_mesh(m, "fine_strip.stl"), {}, &rep);
  EXPECT_EQ(rep.open_edges, 2 * n + 2);
  EXPECT_EQ(rep.seam_gap, -1) << rep.seam_gap;
  EXPECT_EQ(rep.t_gap, -1) << rep.t_gap;
  EXPECT_EQ(rep.t_junctions, 0);
}

// A T-junction missed by 1 um: two 20 mm squares meet along x = 0; the right one's middle
// vertex lies 1e-6 m off the left one's edge, beyond the weld distance (2.8e-7 m). Not joined,
// it is warned of with the distance (the helper measured a bounce of e = 0.362 on it instead of
// 0.498); the tolerance the warning names, followed, splits the edge there.
TEST(StlReader, ATJunctionMissedByMoreThanTheWeldDistanceIsWarnedOf) {
  const double L = 0.01, off = 1e-6;
  test::MeshData m;
  m.v = {Vec3(-L, -L, 0), Vec3(0, -L, 0), Vec3(0, L, 0),  Vec3(-L, L, 0),
         Vec3(L, -L, 0),  Vec3(L, L, 0),  Vec3(off, 0, 0)};
  m.t = {{0, 1, 2}, {0, 2, 3}, {1, 4, 6}, {4, 5, 6}, {5, 2, 6}};
  const std::string path = test::write_mesh(m, "t_near_miss.stl");
  StlReport rep;
  read_stl(path, {}, &rep);
  EXPECT_EQ(rep.t_junctions, 0);
  EXPECT_NEAR(rep.t_gap, off, 1e-12);
  EXPECT_NEAR(rep.t_gap_at[0], off, 1e-15);
  const Scene scene = parse_scene(R"(domain: {min: [-1, -1, -1], max: [2, 2, 2]}
time: {step: 1.0e-5, end: 0.01}
materials: [{name: glass, youngs_modulus: 1.0e7, poisson_ratio: 0.3, density: 2500}]
interaction_defaults: {restitution: 0.5}
contact: {normal: hertz}
walls: [{type: mesh, name: floor, file: ')" +
                                      path + R"(', material: glass}]
)",
                                  "t_near_miss.yaml");
  const WallSet walls(scene);
  ASSERT_EQ(walls.notes().size(), 2u);
  EXPECT_THAT(walls.notes()[1],
              HasSubstr("warning: wall 'floor' (" + path +
                        "): an open-edge vertex at (1e-06, 0, "
                        "0) lies 1e-06 m from another triangle's open edge: a T-junction left "
                        "open"));
  // The advice: weld_tolerance above the named ratio (3.54e-05): the edge is split there.
  const std::size_t at = walls.notes()[1].find("above ") + 6;
  const double advised = std::stod(walls.notes()[1].substr(at));
  EXPECT_NEAR(advised, off / (2 * L * std::sqrt(2.0)), 1e-9);
  StlReport closed;
  read_stl(path, {}, &closed, 1.01 * advised);
  EXPECT_EQ(closed.t_junctions, 1);
  EXPECT_EQ(closed.t_gap, -1);
  EXPECT_EQ(closed.open_edges, 6);  // the outer rim (9 with the junction open)
  EXPECT_EQ(rep.open_edges, 9);
}

// The wall's start-up note states the tolerance and the count, and a seam left open is a
// warning that names the tolerance that would close it.
TEST(StlReader, WeldingIsReportedForTheWall) {
  const test::MeshData seam =
      test::split_at(test::flat_grid(4, 0.004, -0.008, -0.008, 0), 0.0, Vec3(0.6e-7, 0, 0.8e-7));
  const std::string path = test::write_mesh(seam, "seam_note.stl");
  auto notes = [&](const std::string& extra) {
    const Scene scene = parse_scene(R"(domain: {min: [-1, -1, -1], max: [2, 2, 2]}
time: {step: 1.0e-5, end: 0.01}
materials: [{name: glass, youngs_modulus: 1.0e7, poisson_ratio: 0.3, density: 2500}]
interaction_defaults: {restitution: 0.5}
contact: {normal: hertz}
walls: [{type: mesh, name: plate, file: ')" +
                                        path + "', material: glass" + extra + R"(}]
)",
                                    "scene.yaml");
    return WallSet(scene).notes();
  };
  const auto welded = notes("");
  ASSERT_EQ(welded.size(), 1u);
  EXPECT_THAT(welded[0], HasSubstr("32 triangles, 25 vertices"));
  EXPECT_THAT(welded[0], HasSubstr("5 vertices welded (closer than 2.26274e-07 m = 1e-05 of "
                                   "the diagonal)"));
  EXPECT_THAT(welded[0], HasSubstr("16 open edges"));
  const auto open = notes(", weld_tolerance: 0");
  ASSERT_EQ(open.size(), 2u);
  EXPECT_THAT(open[0], HasSubstr("0 vertices welded"));
  EXPECT_THAT(open[1], HasSubstr("warning: wall 'plate'"));
  EXPECT_THAT(open[1], HasSubstr("1e-07 m apart"));
  EXPECT_THAT(open[1], HasSubstr("set `weld_tolerance` above 4.41942e-06"));
}

// A mesh whose triangles each span the whole bounding box (100 slanted triangles across
// a unit cube): with the 2^22-cell grid a small cell asks for, every triangle would be
// listed in all 4 million cells (4e8 entries, 3 GB). The number of (cell, triangle)
// entries is bounded by max(2 max_cells, 8 triangles) = 8 388 608, which here needs
// 100 (floor(1/h) + 1)^3 <= 8 388 608, floor(1/h) <= 42: cells h > 1/43; the step
// before (h / 1.25) did not fit, so h <= 1.25/43.
TEST(StlReader, SearchGridOfLargeSlantedTrianglesIsBounded) {
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
  for (int k = 0; k < 100; ++k) {
    const int b = static_cast<int>(v.size());
    v.insert(v.end(), {Vec3(0, 0, 0), Vec3(1, 1, 0.5 + 0.001 * k), Vec3(0.5, 1, 1)});
    t.push_back({b, b + 1, b + 2});
  }
  TriangleMesh m(v, t);
  m.build_grid(1e-3);
  EXPECT_GT(m.cell_size(), 1.0 / 43);
  EXPECT_LE(m.cell_size(), 1.25 / 43);  // enlarged in steps of 1.25 only as far as needed
  // The search is still exact: the same contacts as the brute-force reference.
  MeshTouch a[TriangleMesh::kMaxTouches], b[TriangleMesh::kMaxTouches];
  for (const Vec3& c : {Vec3(0.5, 0.6, 0.5), Vec3(0.2, 0.3, 0.1), Vec3(0.9, 0.95, 0.8)}) {
    const int n = m.touches(c, 0.05, a);
    ASSERT_EQ(n, m.touches_brute_force(c, 0.05, b));
    for (int i = 0; i < n; ++i) EXPECT_EQ(a[i].triangle, b[i].triangle);
  }
}

TEST(StlReader, AsciiVertexWithExtraNumbersAndBinaryGarbageAreClearErrors) {
  std::string four = kTwoTriangles;
  four.replace(four.find("vertex 1 0 0"), 12, "vertex 1 0 0 7");
  EXPECT_THAT(error_of(four), HasSubstr("mesh.stl:5: error: a vertex has three coordinates, but "
                                        "'7' follows the third"));
  // A long unreadable word is shown cut to 40 characters, control bytes as '?'.
  const std::string garbage = "solid x\n" + std::string(100, 'A') + "\n";
  EXPECT_THAT(error_of(garbage), HasSubstr("mesh.stl:2: error: unexpected '" +
                                           std::string(40, 'A') + "...' in an ASCII STL file"));
  EXPECT_THAT(error_of("solid x\nfa\x01" "cet\n"), HasSubstr("unexpected 'fa?cet'"));
}

// Exporters that write the keywords in capitals ("SOLID", "FACET NORMAL", "VERTEX"): the same
// mesh. The file was taken for binary and refused ("binary STL header declares 1444945952
// triangles").
TEST(StlReader, AsciiKeywordsInAnyCase) {
  std::string upper = kTwoTriangles;
  for (const char* word :
       {"solid", "facet", "normal", "outer", "loop", "vertex", "endloop", "endfacet", "endsolid"}) {
    std::string capital = word;
    for (char& c : capital) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    for (std::size_t at = upper.find(word); at != std::string::npos; at = upper.find(word, at))
      upper.replace(at, capital.size(), capital);
  }
  ASSERT_EQ(upper.find("vertex"), std::string::npos) << upper;
  StlReport rep;
  const TriangleMesh m = parse_stl(upper, "upper.stl", {}, &rep);
  EXPECT_FALSE(rep.binary);
  EXPECT_EQ(m.triangle_count(), 2u);
  EXPECT_EQ(m.vertex_count(), 4u);
}

// A static mesh whose triangles all miss the domain touches no particle: refused, naming the
// wall and the scale that a mesh in millimetres needs (a 1 m square 5 m above a 1 m domain; the
// square scaled to 12 m, 6 m below a 2 cm domain: the bottom face of a box in millimetres
// around it, whose bounding box holds the domain while no face reaches in). The square moving
// is accepted (it may come in).
TEST(StlReader, StaticMeshOutsideTheDomainIsRefused) {
  const auto dir = std::filesystem::temp_directory_path() / "grainflow_stl_outside";
  std::filesystem::create_directories(dir);
  std::ofstream((dir / "square.stl").string(), std::ios::binary) << kTwoTriangles;
  const auto scene = [&](const std::string& domain, const std::string& placement) {
    return parse_scene("domain: " + domain + R"(
time: {step: 1.0e-5, end: 0.01}
materials: [{name: glass, youngs_modulus: 1.0e7, poisson_ratio: 0.3, density: 2500}]
interaction_defaults: {restitution: 0.5}
contact: {normal: hertz}
walls: [{type: mesh, name: plate, file: square.stl, material: glass)" +
                           placement + "}]\n",
                       (dir / "scene.yaml").string());
  };
  const auto error = [&](const Scene& s) {
    try {
      const WallSet walls(s);
    } catch (const GeometryError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string far =
      error(scene("{min: [0, 0, -1], max: [1, 1, 0]}", ", translate: [0, 0, 5]"));
  EXPECT_THAT(far, HasSubstr("none of its triangles reaches into the domain: no particle can "
                             "touch it. An STL in millimetres needs `scale: 0.001`"));
  EXPECT_THAT(far, HasSubstr("(the mesh of wall 'plate', "));
  EXPECT_THAT(error(scene("{min: [0, 0, 0], max: [0.02, 0.02, 0.02]}",
                          ", scale: 12, translate: [-6, -6, -6]")),
              HasSubstr("none of its triangles reaches into the domain"));
  EXPECT_EQ(error(scene("{min: [0, 0, -1], max: [1, 1, 0]}",
                        ", translate: [0, 0, 5], "
                        "motion: {velocity: [0, 0, -1]}")),
            "no error");
  EXPECT_EQ(error(scene("{min: [0, 0, -1], max: [1, 1, 0]}", "")), "no error");
}

}  // namespace
}  // namespace grainflow
