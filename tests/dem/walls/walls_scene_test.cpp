// The scene keys of mesh walls, wall motion and stream/snapshot insertion, and
// their errors (docs/scene-reference.md).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "dem/engine/simulation.hpp"
#include "dem/scene/scene_parser.hpp"
#include "tests/dem/walls/mesh_support.hpp"

namespace grainflow {
namespace {

using ::testing::HasSubstr;

const std::string kHead = R"(domain: {min: [-1, -1, -1], max: [1, 1, 1]}
time: {step: 1.0e-5, end: 0.01}
materials: [{name: glass, youngs_modulus: 1.0e7, poisson_ratio: 0.3, density: 2500}]
interaction_defaults: {restitution: 0.5, friction: 0.3}
contact: {normal: hertz}
)";

std::string label() {
  test::write_mesh(test::flat_grid(2, 0.1, 0, 0, 0), "scene_mesh.stl");
  return (std::filesystem::path(GRAINFLOW_BINARY_DIR) / "test_output" / "walls" / "scene.yaml")
      .string();
}

std::string error_of(const std::string& body) {
  try {
    parse_scene(kHead + body, label());
  } catch (const SceneError& e) {
    return e.what();
  }
  return "no error";
}

TEST(WallsScene, MeshWallWithPlacementConveyorAndMotion) {
  const Scene s = parse_scene(kHead + R"(walls:
  - type: mesh
    name: chute
    file: scene_mesh.stl
    scale: 2
    rotate: {axis: [0, 0, 1], angle: 90}
    translate: [0.1, 0, 0]
    surface_velocity: [0.2, 0, 0]
    material: glass
    motion: {velocity: [0, 0, 0.1], angular_velocity: 2, axis: [0, 1, 0], axis_point: [0, 0, 1]}
  - type: plane
    point: [0, 0, -0.5]
    normal: [0, 0, 1]
    material: glass
    motion: {velocity: [0, 0, 0.05]}
)", label());
  ASSERT_EQ(s.walls.size(), 2u);
  const Wall& m = s.walls[0];
  EXPECT_EQ(m.kind, Wall::Kind::mesh);
  EXPECT_THAT(m.mesh.file, HasSubstr("scene_mesh.stl"));
  EXPECT_EQ(m.mesh.scale, 2);
  EXPECT_NEAR(m.mesh.rotate_angle, std::numbers::pi / 2, 1e-15);
  EXPECT_EQ(m.mesh.surface_velocity, Vec3(0.2, 0, 0));
  EXPECT_EQ(m.motion.angular_velocity, 2);
  EXPECT_EQ(m.motion.axis, Vec3::UnitY());
  EXPECT_EQ(s.walls[1].motion.velocity, Vec3(0, 0, 0.05));
  // The mesh loads with its placement: (0.2, 0) -> scaled (0.4, 0) -> rotated (0, 0.4).
  Simulation sim(s, false);
  const TriangleMesh& mesh = sim.walls().mesh(sim.walls().walls()[0]);
  EXPECT_NEAR(mesh.hi()[1], 0.4, 1e-12);
  EXPECT_NEAR(mesh.lo()[0], 0.1 - 0.4, 1e-12);
}

TEST(WallsScene, StreamAndSnapshotInsertion) {
  const Scene s = parse_scene(kHead + R"(insert:
  - type: stream
    face: {rectangle: {centre: [0, 0, 0.5], normal: [0, 0, -1], u: [1, 0, 0.3], size: [0.2, 0.1]}}
    mass_rate: 0.5
    start: 0.001
    stop: 0.5
    material: glass
    radius: {distribution: constant, value: 0.002}
    velocity: [0, 0, -1]
)", label());
  const Insertion& i = s.insertions[0];
  EXPECT_EQ(i.kind, Insertion::Kind::stream);
  EXPECT_NEAR(i.face.u.dot(i.face.normal), 0, 1e-15);  // u projected into the face
  EXPECT_EQ(*i.mass_rate, 0.5);
  EXPECT_EQ(*i.stop, 0.5);
  EXPECT_THAT(error_of(R"(insert:
  - type: stream
    face: {disc: {centre: [0, 0, 0], normal: [0, 0, 1], radius: 0.1}}
    mass_rate: 1
    count_rate: 10
    material: glass
    radius: {distribution: constant, value: 0.002}
)"),
              HasSubstr("both 'mass_rate' and 'count_rate' are given"));
  EXPECT_THAT(error_of("insert: [{type: snapshot, file: missing.h5}]\n"),
              HasSubstr("snapshot file 'missing.h5' not found"));
}

TEST(WallsScene, Errors) {
  EXPECT_THAT(error_of("walls: [{type: mesh, file: nothere.stl, material: glass}]\n"),
              HasSubstr("STL file 'nothere.stl' not found"));
  EXPECT_THAT(error_of("walls: [{type: mesh, file: scene_mesh.stl, material: glass, scale: 0}]\n"),
              HasSubstr("out of range"));
  EXPECT_THAT(error_of("walls: [{type: meshh, file: scene_mesh.stl, material: glass}]\n"),
              HasSubstr("did you mean 'mesh'?"));
  // A broken STL is reported when the run is set up, naming the file and line.
  const std::string bad =
      (std::filesystem::path(GRAINFLOW_BINARY_DIR) / "test_output" / "walls" / "bad.stl").string();
  { std::ofstream(bad) << "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n"; }
  const Scene s = parse_scene(kHead + "walls: [{type: mesh, file: bad.stl, material: glass}]\n",
                              label());
  try {
    Simulation sim(s, false);
    FAIL() << "no error";
  } catch (const GeometryError& e) {  // bad input (grain: exit code 2), naming the wall too
    EXPECT_THAT(e.what(), HasSubstr("bad.stl:4: error: the file ends inside the facet begun at line 2"));
    EXPECT_THAT(e.what(), HasSubstr("(the mesh of wall 'wall0', "));
  }
}

// A closed mesh with particles on both sides: the fill placed 7 of 100 beads inside a solid
// cube obstacle, where they stayed trapped, without a word. encloses() against the box's own
// inequalities (the reference), on a grid of points that includes the box's faces' planes
// offset by a tenth of a cell; then the start-up warning with its counts, and none when every
// particle is on one side (a container).
TEST(WallsScene, ClosedMeshWithParticlesOnBothSidesIsWarnedOf) {
  const Vec3 lo(-0.2, -0.2, -0.2), hi(0.2, 0.2, 0.2);
  test::write_mesh(test::box(lo, hi), "closed_box.stl");
  const Scene s = parse_scene(kHead +
                                  "walls: [{type: mesh, name: block, file: closed_box.stl, "
                                  "material: glass}]\n",
                              label());
  WallSet walls(s);
  const TriangleMesh& m = walls.mesh(walls.walls()[0]);
  long checked = 0;
  for (double x = -0.31; x < 0.31; x += 0.05)
    for (double y = -0.29; y < 0.31; y += 0.07)
      for (double z = -0.33; z < 0.31; z += 0.06) {
        const Vec3 q(x, y, z);
        const bool in = (q.array() > lo.array()).all() && (q.array() < hi.array()).all();
        EXPECT_EQ(m.encloses(q), in) << q.transpose();
        ++checked;
      }
  EXPECT_GT(checked, 1000);
  std::vector<Vec3> centres = {Vec3(0, 0, 0), Vec3(0.5, 0.5, 0.5), Vec3(-0.5, 0, 0)};
  walls.check_closed_meshes(centres);
  ASSERT_EQ(walls.notes().size(), 2u);
  EXPECT_THAT(walls.notes()[1], HasSubstr("warning: wall 'block' is a closed surface, and 1 of "
                                          "the 3 particles start inside it, 2 outside"));
  WallSet container(s);
  container.check_closed_meshes({Vec3(0, 0, 0), Vec3(0.1, 0.1, 0.1)});
  EXPECT_EQ(container.notes().size(), 1u);  // the mesh's own line only
}

}  // namespace
}  // namespace grainflow
