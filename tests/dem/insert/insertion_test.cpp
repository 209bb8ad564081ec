// Fill-a-region insertion and CSV insertion.
// References: the requested count / volume fraction (exact bookkeeping), geometric
// containment and pairwise non-overlap checked by brute force, and the moments of
// the size distributions (sample mean within 4 standard errors of the exact mean:
// a false failure rate below 1e-4).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "dem/insert/insertion.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

Insertion box_fill(const Vec3& lo, const Vec3& hi) {
  Insertion ins;
  ins.kind = Insertion::Kind::fill;
  ins.region.kind = Region::Kind::box;
  ins.region.lo = lo;
  ins.region.hi = hi;
  ins.source = "test.yaml:10";
  return ins;
}

void expect_no_overlaps(const Particles& p) {
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j)
      ASSERT_GE((p.x[i] - p.x[j]).norm(), p.radius[i] + p.radius[j]) << i << " " << j;
}

TEST(FillInsertion, CountInBoxWithoutOverlap) {
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5);
  Insertion ins = box_fill(Vec3(0, 0, 0), Vec3(0.02, 0.02, 0.04));
  ins.count = 600;
  ins.radius.kind = SizeDistribution::Kind::uniform;
  ins.radius.min = 5e-4;
  ins.radius.max = 1e-3;
  s.insertions.push_back(ins);
  Particles p;
  GlobalId next = 1;
  insert_particles(s, p, next);
  ASSERT_EQ(p.size(), 600u);
  EXPECT_EQ(next, 601);
  expect_no_overlaps(p);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(p.x[i][a] - p.radius[i], ins.region.lo[a]);
      EXPECT_LE(p.x[i][a] + p.radius[i], ins.region.hi[a]);
    }
  // Uniform radii on [a, b]: mean (a+b)/2, sd (b-a)/sqrt(12).
  double mean = 0;
  for (double r : p.radius) mean += r / p.size();
  EXPECT_NEAR(mean, 7.5e-4, 4 * 5e-4 / std::sqrt(12.0) / std::sqrt(600.0));
}

TEST(FillInsertion, VolumeFractionInCylinder) {
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5);
  Insertion ins;
  ins.kind = Insertion::Kind::fill;
  ins.region.kind = Region::Kind::cylinder;
  ins.region.base = Vec3(0.1, 0, 0);
  ins.region.axis = Vec3::UnitZ();
  ins.region.radius = 0.02;
  ins.region.height = 0.03;
  ins.volume_fraction = 0.25;
  ins.radius.kind = SizeDistribution::Kind::constant;
  ins.radius.value = 1e-3;
  s.insertions.push_back(ins);
  Particles p;
  GlobalId next = 1;
  insert_particles(s, p, next);
  const double v_region = std::numbers::pi * 0.02 * 0.02 * 0.03;
  const double v_one = sphere_volume(1e-3);
  double v = 0;
  for (double r : p.radius) v += sphere_volume(r);
  // Stops at the first particle that reaches the target.
  EXPECT_GE(v / v_region, 0.25);
  EXPECT_LT(v / v_region, 0.25 + v_one / v_region);
  expect_no_overlaps(p);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3 rel = p.x[i] - ins.region.base;
    EXPECT_LE(std::hypot(rel[0], rel[1]) + 1e-3, 0.02 + 1e-15);
    EXPECT_GE(rel[2] - 1e-3, -1e-15);
    EXPECT_LE(rel[2] + 1e-3, 0.03 + 1e-15);
  }
}

TEST(FillInsertion, DiscreteMixtureNumberFractions) {
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5);
  Insertion ins = box_fill(Vec3(0, 0, 0), Vec3(0.05, 0.05, 0.05));
  ins.count = 2000;
  ins.radius.kind = SizeDistribution::Kind::discrete;
  ins.radius.values = {5e-4, 1e-3};
  ins.radius.weights = {0.7, 0.3};
  s.insertions.push_back(ins);
  Particles p;
  GlobalId next = 1;
  insert_particles(s, p, next);
  ASSERT_EQ(p.size(), 2000u);
  double small = 0;
  for (double r : p.radius) small += (r == 5e-4) / 2000.0;
  EXPECT_NEAR(small, 0.7, 4 * std::sqrt(0.7 * 0.3 / 2000));
}

TEST(FillInsertion, TruncatedNormalStaysInBounds) {
  std::mt19937_64 rng(5);
  SizeDistribution d;
  d.kind = SizeDistribution::Kind::normal;
  d.mean = 1e-3;
  d.stddev = 2e-4;
  d.min = 8e-4;
  d.max = 1.3e-3;
  double mean = 0;
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    const double r = sample_radius(d, rng);
    ASSERT_GE(r, d.min);
    ASSERT_LE(r, d.max);
    mean += r / n;
  }
  // Mean of a normal truncated to [mu - s, mu + 1.5 s]:
  // mu + s (phi(-1) - phi(1.5)) / (Phi(1.5) - Phi(-1)).
  auto phi = [](double z) { return std::exp(-z * z / 2) / std::sqrt(2 * std::numbers::pi); };
  auto Phi = [](double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); };
  const double expected = 1e-3 + 2e-4 * (phi(-1) - phi(1.5)) / (Phi(1.5) - Phi(-1));
  EXPECT_NEAR(mean, expected, 4 * 2e-4 / std::sqrt(n));
}

TEST(FillInsertion, ImpossibleRequestIsAClearError) {
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5);
  Insertion ins = box_fill(Vec3(0, 0, 0), Vec3(0.004, 0.004, 0.004));
  ins.count = 100;  // 100 spheres of r = 1 mm cannot fit in a 4 mm cube
  ins.radius.value = 1e-3;
  s.insertions.push_back(ins);
  Particles p;
  GlobalId next = 1;
  try {
    insert_particles(s, p, next);
    FAIL() << "expected InsertionError";
  } catch (const InsertionError& e) {
    EXPECT_NE(std::string(e.what()).find("test.yaml:10"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("could place only"), std::string::npos) << e.what();
  }
}

TEST(CsvInsertion, ReadsColumnsAndReportsBadRows) {
  const auto dir = std::filesystem::temp_directory_path() / "grainflow_csv_test";
  std::filesystem::create_directories(dir);
  const auto good = (dir / "good.csv").string();
  std::ofstream(good) << "# a comment\nx,y,z,radius,vx,vy,vz\n0,0,0,0.001,1,2,3\n0.01,0,0,0.002,0,0,0\n";
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5);
  Insertion ins;
  ins.kind = Insertion::Kind::csv;
  ins.csv_file = good;
  ins.source = "scene.yaml:4";
  s.insertions.push_back(ins);
  Particles p;
  GlobalId next = 1;
  insert_particles(s, p, next);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p.v[0], Vec3(1, 2, 3));
  EXPECT_EQ(p.radius[1], 0.002);

  const auto bad = (dir / "bad.csv").string();
  std::ofstream(bad) << "x,y,z,radius\n0,0,0,0.001\n0.0015,0,0,0.001\n";
  s.insertions[0].csv_file = bad;
  Particles q;
  try {
    insert_particles(s, q, next);
    FAIL() << "expected InsertionError";
  } catch (const InsertionError& e) {
    EXPECT_NE(std::string(e.what()).find(bad + ":3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("overlaps"), std::string::npos) << e.what();
  }
  const auto nocol = (dir / "nocol.csv").string();
  std::ofstream(nocol) << "x,y,radius\n0,0,0.001\n";
  s.insertions[0].csv_file = nocol;
  try {
    insert_particles(s, q, next);
    FAIL() << "expected InsertionError";
  } catch (const InsertionError& e) {
    EXPECT_NE(std::string(e.what()).find("lacks column 'z'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace grainflow
