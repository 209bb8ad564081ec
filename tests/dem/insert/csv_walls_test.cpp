// Particles given by a file (CSV) against walls, the domain and each other (issue 17 items
// 2 and 8). A particle inside a wall (an overlap above time.max_overlap of its radius, the
// most a run allows, or its centre on the wall's far side) is refused at insertion with the
// wall's name and the file's line: planes, cylinders of both sides and meshes. A particle
// that touches a wall within that allowance, or two spheres that touch to the round-off of
// their 17-digit coordinates, are accepted. References: the geometry of each case (overlaps
// computed by hand in the comments).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "dem/insert/insertion.hpp"
#include "dem/io/output_directory.hpp"
#include "dem/io/snapshot_writer.hpp"
#include "dem/walls/wall_set.hpp"
#include "tests/dem/support/test_scene.hpp"
#include "tests/dem/walls/mesh_support.hpp"

namespace grainflow {
namespace {

using ::testing::HasSubstr;

class CsvAgainstWalls : public ::testing::Test {
 protected:
  CsvAgainstWalls() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           ("grainflow_csv_walls." + std::string(info->name()));
    std::filesystem::create_directories(dir_);
    scene_ = test::one_material_scene(1e7, 0.3, 2500, 0.5);
    scene_.domain.lo = Vec3(0, 0, 0);
    scene_.domain.hi = Vec3(0.01, 0.01, 0.01);
  }
  // The error inserting `rows` (after the header x,y,z,radius) gives, or "no error"; walls
  // as loaded by WallSet (meshes included).
  std::string error_of(const std::string& rows) {
    const std::string file = (dir_ / "p.csv").string();
    std::ofstream(file) << "x,y,z,radius\n" << rows;
    Scene s = scene_;
    Insertion ins;
    ins.kind = Insertion::Kind::csv;
    ins.csv_file = file;
    ins.source = "scene.yaml:7";
    s.insertions.push_back(ins);
    const WallSet walls(s);
    Particles p;
    GlobalId next = 1;
    try {
      insert_particles(s, p, next, &walls);
    } catch (const InsertionError& e) {
      return e.what();
    }
    return "no error";
  }
  std::string at(int line) const {
    return (dir_ / "p.csv").string() + ":" + std::to_string(line) + ": error: ";
  }
  std::filesystem::path dir_;
  Scene scene_;
};

Wall rod(const std::string& name, bool inside, double radius) {
  Wall w;
  w.kind = Wall::Kind::cylinder;
  w.name = name;
  w.cylinder.axis_point = Vec3(0.005, 0.005, 0);
  w.cylinder.axis = Vec3::UnitZ();
  w.cylinder.radius = radius;
  w.cylinder.inside = inside;
  return w;
}

TEST_F(CsvAgainstWalls, SphereOnTheAxisOfARodIsRefused) {
  scene_.walls.push_back(rod("rod", false, 0.5e-3));
  // Centre on the axis: overlap r + R = 1.5 mm, 150 % of r, centre inside the rod.
  EXPECT_THAT(error_of("0.005,0.005,0.005,0.001\n"),
              HasSubstr(at(2) + "the particle at (0.005, 0.005, 0.005) with radius 0.001 lies "
                                "inside wall 'rod': it overlaps it by 0.0015 m, 150 % of its "
                                "radius (its centre is on the wall's far side); at insertion a "
                                "particle may overlap a wall by at most time.max_overlap = 25 %"));
  // 0.7 mm off the axis, outside the rod: overlap r - 0.2 mm = 0.8 mm, 80 %.
  EXPECT_THAT(error_of("0.0057,0.005,0.005,0.001\n"),
              HasSubstr("inside wall 'rod': it overlaps it by 0.0008 m, 80 % of its radius;"));
  // 1.3 mm off: overlap 0.2 mm = 20 %, within time.max_overlap: a settled bed's contact.
  EXPECT_EQ(error_of("0.0063,0.005,0.005,0.001\n"), "no error");
}

TEST_F(CsvAgainstWalls, OutsideAContainerAndBeyondAPlaneAreRefused) {
  scene_.walls.push_back(rod("drum", true, 0.003));
  // The second row's centre is 3.5 mm off the axis, outside the 3 mm drum: overlap
  // r + 0.5 mm = 1.5 mm.
  EXPECT_THAT(error_of("0.005,0.005,0.005,0.001\n0.0085,0.005,0.005,0.001\n"),
              HasSubstr(at(3) + "the particle at (0.0085, 0.005, 0.005) with radius 0.001 lies "
                                "inside wall 'drum': it overlaps it by 0.0015 m, 150 %"));
  scene_.walls.clear();
  Wall floor = test::plane(Vec3(0, 0, 0.002), Vec3::UnitZ());
  floor.name = "floor";
  scene_.walls.push_back(floor);
  // Centre 0.5 mm below the floor: overlap 1.5 mm.
  EXPECT_THAT(error_of("0.005,0.005,0.0015,0.001\n"),
              HasSubstr("inside wall 'floor': it overlaps it by 0.0015 m, 150 % of its radius "
                        "(its centre is on the wall's far side)"));
  // Resting on it with 10 % overlap: accepted.
  EXPECT_EQ(error_of("0.005,0.005,0.0029,0.001\n"), "no error");
}

TEST_F(CsvAgainstWalls, ThroughAMeshIsRefused) {
  // A flat mesh at z = 5 mm over the whole domain; a sphere 0.2 mm above it overlaps it by
  // 0.8 mm (80 %).
  scene_.walls.push_back(test::mesh_wall(
      test::write_mesh(test::flat_grid(2, 0.005, 0, 0, 0.005), "csv_walls_sheet.stl"), "sheet"));
  EXPECT_THAT(error_of("0.003,0.003,0.0052,0.001\n"),
              HasSubstr(at(2) + "the particle at (0.003, 0.003, 0.0052) with radius 0.001 lies "
                                "inside wall 'sheet': it overlaps it by 0.0008 m, 80 %"));
  EXPECT_EQ(error_of("0.003,0.003,0.0059,0.001\n"), "no error");  // 10 %
}

// Two spheres that touch, written with 17 digits (x = 0.001918 and 0.001918 + 0.002 =
// 0.003918, r = 0.001): the distance of their centres computed in double falls short of
// r1 + r2 by the round-off of the coordinates, 4.3e-19 m (checked in Python: (b - a)^2 <
// 0.002^2): no overlap. A real overlap of 1e-12 m is still refused.
TEST_F(CsvAgainstWalls, TouchingSpheresWithSeventeenDigitsAreAccepted) {
  char rows[256];
  std::snprintf(rows, sizeof rows, "%.17g,0.005,0.005,0.001\n%.17g,0.005,0.005,0.001\n", 0.001918,
                0.001918 + 0.002);
  EXPECT_EQ(error_of(rows), "no error");
  EXPECT_EQ(error_of("0.007,0.005,0.005,0.001\n0.008999999999,0.005,0.005,0.001\n")
                .find(at(3) + "the particle at (0.008999999999, 0.005, 0.005) with radius 0.001 "
                              "overlaps an earlier particle at (0.007, 0.005, 0.005)"),
            0u);
}

// x = 0.009000000000000001 with r = 0.001 reaches 1.7e-18 m (one unit in the last place of
// 0.01) past the domain's 0.01: the round-off of a sphere that touches the side, accepted as
// for touching spheres. So is a sphere touching the side of a domain far from the origin
// (CAD coordinates): z = 2.00005 with r = 0.00055 on a floor at 1.9995, where z - r in double
// is 1.9994999999999998 (checked in Python). A real excess, 1e-14 m, is refused: the message
// shows every digit that differs, and the excess.
TEST_F(CsvAgainstWalls, DomainExcessIsShownWithItsDigits) {
  EXPECT_EQ(error_of("0.009000000000000001,0.005,0.005,0.001\n"), "no error");
  EXPECT_THAT(
      error_of("0.00900000000001,0.005,0.005,0.001\n"),
      HasSubstr(at(2) + "the particle at (0.00900000000001, 0.005, 0.005) with radius "
                        "0.001 is outside the domain: it spans x from 0.008000000000009999 "
                        "to 0.010000000000010001, beyond the domain's 0 to 0.01 by 1e-14 m"));
  scene_.domain.lo = Vec3(0, 0, 1.9995);
  scene_.domain.hi = Vec3(0.01, 0.01, 2.01);
  EXPECT_EQ(error_of("0.005,0.005,2.00005,0.00055\n"), "no error");
  EXPECT_THAT(error_of("0.005,0.005,2.0000499,0.00055\n"), HasSubstr("is outside the domain"));
}

// The same rule for a snapshot: a particle of a snapshot with its centre on a rod's axis is
// refused with its id and the wall's name; 1.3 mm off the axis (20 % overlap) it is accepted.
TEST(SnapshotAgainstWalls, ParticleOnTheAxisOfARodIsRefused) {
  const std::filesystem::path dir =
      std::filesystem::path(GRAINFLOW_BINARY_DIR) / "test_output" / "snapshot_against_walls";
  std::filesystem::remove_all(dir);
  prepare_output_directory(dir.string());
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5);
  s.walls.push_back(rod("rod", false, 0.5e-3));
  Particles p;
  p.add(7, Vec3(0.0063, 0.005, 0.005), Vec3::Zero(), Vec3::Zero(), 0.001, 0, 2500);
  p.add(8, Vec3(0.005, 0.005, 0.02), Vec3::Zero(), Vec3::Zero(), 0.001, 0, 2500);
  SnapshotWriter w(MPI_COMM_WORLD, dir.string());
  Insertion ins;
  ins.kind = Insertion::Kind::snapshot;
  ins.snapshot_file = w.write(p, 0.5, 10);
  ins.source = "scene.yaml:9";
  s.insertions.push_back(ins);
  const WallSet walls(s);
  Particles q;
  GlobalId next = 1;
  try {
    insert_particles(s, q, next, &walls);
    ADD_FAILURE() << "accepted a particle on the rod's axis";
  } catch (const InsertionError& e) {
    EXPECT_THAT(e.what(), HasSubstr("scene.yaml:9: error: particle id 8 of snapshot '" +
                                    s.insertions[0].snapshot_file +
                                    "' lies inside wall 'rod': it overlaps it by 0.0015 m, 150 %"));
  }
  p.x[1] = Vec3(0.5, 0.5, 0.5);  // far from the rod (infinite along z)
  s.insertions[0].snapshot_file = w.write(p, 0.6, 11);
  Particles ok;
  next = 1;
  insert_particles(s, ok, next, &walls);
  EXPECT_EQ(ok.size(), 2u);
}

}  // namespace
}  // namespace grainflow
