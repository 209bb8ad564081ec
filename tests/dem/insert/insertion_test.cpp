// Fill-a-region insertion and CSV insertion.
// References: the requested count / volume fraction (exact bookkeeping), geometric
// containment and pairwise non-overlap checked by brute force, and the moments of
// the size distributions (sample mean within 4 standard errors of the exact mean:
// a false failure rate below 1e-4).
#include "dem/insert/insertion.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <regex>

#include "dem/scene/scene_parser.hpp"
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

// A region as wide as the bead in the scene's decimals, 0.0115 - 0.0085 = 0.003 m for a
// 3 mm bead, is narrower in doubles (by 4e-19 m): the scene's check refused it ("0.003 m
// across, less than 0.003 m") and the sampler found no place. Both allow 1e-9 of the
// diameter: the bead is placed at the region's middle across, within the region to round-off.
TEST(FillInsertion, ARegionAsWideAsTheParticleUpToRoundOff) {
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5);
  Insertion ins = box_fill(Vec3(0.0085, 0.0235, 0), Vec3(0.0115, 0.0265, 0.0030000599999999997));
  ASSERT_LT(ins.region.hi[0] - ins.region.lo[0], 0.003);
  ins.count = 1;
  ins.radius.kind = SizeDistribution::Kind::constant;
  ins.radius.min = ins.radius.max = ins.radius.value = 0.0015;
  s.insertions.push_back(ins);
  Particles p;
  GlobalId next = 1;
  insert_particles(s, p, next);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NEAR(p.x[0][0], 0.01, 1e-15);
  EXPECT_NEAR(p.x[0][1], 0.025, 1e-15);
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

// A dense fill keeps the distribution: each radius drawn waits for a place, so that large
// particles (which find room less often) are not passed over for small ones. 32 % solids of a
// 50/50 mixture of 0.4 and 0.6 mm beads in a 1 cm cube (drawing a radius at every attempt
// gave 79 % small ones), and 33 % solids of uniform 0.4-0.6 mm.
TEST(FillInsertion, DenseFillsKeepTheSizeDistribution) {
  {
    Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5);
    Insertion ins = box_fill(Vec3(0, 0, 0), Vec3(0.01, 0.01, 0.01));
    ins.count = 550;
    ins.radius.kind = SizeDistribution::Kind::discrete;
    ins.radius.values = {4e-4, 6e-4};
    ins.radius.weights = {0.5, 0.5};
    s.insertions.push_back(ins);
    Particles p;
    GlobalId next = 1;
    insert_particles(s, p, next);
    ASSERT_EQ(p.size(), 550u);
    expect_no_overlaps(p);
    double small = 0, volume = 0;
    for (double r : p.radius) {
      small += (r == 4e-4) / 550.0;
      volume += sphere_volume(r);
    }
    EXPECT_GT(volume / 1e-6, 0.3);
    EXPECT_NEAR(small, 0.5, 4 * std::sqrt(0.5 * 0.5 / 550));
  }
  {
    Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5);
    Insertion ins = box_fill(Vec3(0, 0, 0), Vec3(0.01, 0.01, 0.01));
    ins.count = 600;
    ins.radius.kind = SizeDistribution::Kind::uniform;
    ins.radius.min = 4e-4;
    ins.radius.max = 6e-4;
    s.insertions.push_back(ins);
    Particles p;
    GlobalId next = 1;
    insert_particles(s, p, next);
    ASSERT_EQ(p.size(), 600u);
    expect_no_overlaps(p);
    double mean = 0, volume = 0;
    for (double r : p.radius) {
      mean += r / 600.0;
      volume += sphere_volume(r);
    }
    EXPECT_GT(volume / 1e-6, 0.3);
    EXPECT_NEAR(mean, 5e-4, 4 * 2e-4 / std::sqrt(12.0) / std::sqrt(600.0));
  }
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

// A window narrow against the standard deviation: a normal draw falls in [0.97, 1.01] mm with
// probability 0.02 % for sigma = 0.1 m, and after 1000 misses the sampler had returned the
// mean (in the probe's [0.9, 1.1] mm with sigma 0.1 m, 46 % of the radii were exactly 1 mm).
// The truncated normal's mean and standard deviation, closed forms (Johnson, Kotz &
// Balakrishnan 1994, Continuous Univariate Distributions 1, sec. 10.1), must come out for
// every sigma, and no radius may repeat.
TEST(FillInsertion, TruncatedNormalInANarrowWindowIsExact) {
  auto phi = [](double z) { return std::exp(-z * z / 2) / std::sqrt(2 * std::numbers::pi); };
  auto Phi = [](double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); };
  for (const double sigma : {1e-1, 1e-3, 1e-4, 3e-5, 1e-5}) {
    SizeDistribution d;
    d.kind = SizeDistribution::Kind::normal;
    d.mean = 1e-3;
    d.stddev = sigma;
    d.min = 9.7e-4;
    d.max = 1.01e-3;
    const double a = (d.min - d.mean) / sigma, b = (d.max - d.mean) / sigma;
    const double z = Phi(b) - Phi(a);
    const double mean = d.mean + sigma * (phi(a) - phi(b)) / z;
    const double sd =
        sigma * std::sqrt(1 + (a * phi(a) - b * phi(b)) / z - std::pow((phi(a) - phi(b)) / z, 2));
    std::mt19937_64 rng(11);
    const int n = 40000;
    std::vector<double> r(n);
    double sum = 0, sum2 = 0;
    for (double& x : r) {
      x = sample_radius(d, rng);
      ASSERT_GE(x, d.min);
      ASSERT_LE(x, d.max);
      sum += x;
      sum2 += x * x;
    }
    const double m = sum / n, s = std::sqrt(sum2 / n - m * m);
    std::sort(r.begin(), r.end());
    const long repeats = std::adjacent_find(r.begin(), r.end()) == r.end() ? 0 : 1;
    std::printf(
        "[ measured ] sigma %.0e: P(window) %.4f, mean %.6e (closed form %.6e), sd %.4e "
        "(%.4e)\n",
        sigma, z, m, mean, s, sd);
    EXPECT_NEAR(m, mean, 4 * sd / std::sqrt(n));
    EXPECT_NEAR(s, sd, 0.02 * sd);
    EXPECT_EQ(repeats, 0);
  }
}

// A fill by volume fraction has the attempt budget of the particles it draws, 2000 each, as a
// fill by count: a 2 cm box at 0.335 solids of 0.5 mm spheres (5119 of them, below random
// sequential addition's saturation near 0.38) had a flat 4e6 attempts and was refused at
// 0.331, while `count: 5119` placed them all; a larger box, as the refusal advised, reached
// less (0.269 at 0.3 in an 8 cm box).
TEST(FillInsertion, AVolumeFractionFillHasTheBudgetOfItsParticles) {
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5);
  Insertion ins = box_fill(Vec3(0, 0, 0), Vec3(0.02, 0.02, 0.02));
  ins.volume_fraction = 0.335;
  ins.radius.kind = SizeDistribution::Kind::constant;
  ins.radius.value = 5e-4;
  s.insertions.push_back(ins);
  Particles p;
  GlobalId next = 1;
  insert_particles(s, p, next);
  // ceil(0.335 * (0.02)^3 / (4/3 pi (5e-4)^3)) = 5119 spheres, the first volume at or above.
  const double n = 0.335 * 8e-6 / sphere_volume(5e-4);
  EXPECT_EQ(p.size(), static_cast<std::size_t>(std::ceil(n)));
  double v = 0;
  for (double r : p.radius) v += sphere_volume(r);
  EXPECT_GE(v / 8e-6, 0.335);
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
  EXPECT_EQ(p.omega[0], Vec3::Zero());  // no wx,wy,wz columns: no spin

  // wx,wy,wz give each particle its spin, read as written (rad/s).
  const auto spinning = (dir / "spin.csv").string();
  std::ofstream(spinning) << "x,y,z,radius,wz,wx,wy\n0,0,0,0.001,-30.5,10,20\n";
  s.insertions[0].csv_file = spinning;
  Particles ps;
  insert_particles(s, ps, next);
  ASSERT_EQ(ps.size(), 1u);
  EXPECT_EQ(ps.omega[0], Vec3(10, 20, -30.5));
  EXPECT_EQ(ps.v[0], Vec3::Zero());

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

// Broken particle files (docs/reliability.md, "Hostile input"): each is an error naming
// the file, the line and what is wrong; nothing is skipped or clamped silently.
class BrokenCsv : public ::testing::Test {
 protected:
  // The error inserting a CSV file with `text` gives (or "no error"), in the scene of
  // one_material_scene: domain [-1, 1]^3, one material 'm'.
  // `parcels`: the scene also has the parcel class 'm[k=2]' (as a fill with coarse_grain 2 makes).
  std::string error_of(const std::string& text, bool periodic = false, bool parcels = false) {
    // One directory per test: CTest runs the tests of this suite in parallel.
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    const auto dir = std::filesystem::temp_directory_path() /
                     ("grainflow_broken_csv." + std::string(info->name()));
    std::filesystem::create_directories(dir);
    file_ = (dir / "p.csv").string();
    std::ofstream(file_) << text;
    Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5);
    if (periodic) s.domain.periodic = {true, true, true};
    if (parcels) {
      Material parcel = s.materials[0];
      parcel.name = "m[k=2]";
      parcel.coarse_grain = 2;
      parcel.real_material = 0;
      s.materials.push_back(parcel);
    }
    Insertion ins;
    ins.kind = Insertion::Kind::csv;
    ins.csv_file = file_;
    ins.source = "scene.yaml:7";
    s.insertions.push_back(ins);
    Particles p;
    GlobalId next = 1;
    try {
      insert_particles(s, p, next);
    } catch (const InsertionError& e) {
      EXPECT_THAT(e.what(), ::testing::HasSubstr("(particle file of the insertion at scene.yaml:7)"));
      return e.what();
    }
    return "no error";
  }
  std::string at(int line) const { return file_ + ":" + std::to_string(line) + ": error: "; }
  std::string file_;
};

using ::testing::HasSubstr;

TEST_F(BrokenCsv, EmptyOrHeaderOnly) {
  EXPECT_THAT(error_of(""), HasSubstr("p.csv: error: the file is empty (no header line); its first "
                                      "line must name the columns: x,y,z,radius (required)"));
  EXPECT_THAT(error_of("# only a comment\n\n"), HasSubstr("the file is empty (no header line)"));
  EXPECT_THAT(error_of("x,y,z,radius\n"),
              HasSubstr(at(1) + "the file has a header but no particle rows"));
}

TEST_F(BrokenCsv, MissingUnknownRepeatedAndPartialColumns) {
  EXPECT_THAT(error_of("x,y,radius\n0,0,0.1\n"),
              HasSubstr(at(1) + "header lacks column 'z'; columns: x,y,z,radius (required), "
                                "vx,vy,vz, wx,wy,wz, material, T (optional; T needs heat on)"));
  // A misspelt column would otherwise be ignored with its values.
  EXPECT_THAT(error_of("x,y,z,radius,vX,vy,vz\n0,0,0,0.1,1,0,0\n"),
              HasSubstr(at(1) + "unknown column 'vX' in the header; allowed columns: x,y,z,radius"));
  EXPECT_THAT(error_of("x,y,z,radius,x\n0,0,0,0.1,0.5\n"),
              HasSubstr(at(1) + "column 'x' appears twice in the header"));
  EXPECT_THAT(error_of("x,y,z,radius,vz\n0,0,0,0.1,-1\n"),
              HasSubstr(at(1) + "the header has only 1 of the velocity columns vx,vy,vz; give all "
                                "three or none"));
  EXPECT_THAT(error_of("x,y,z,radius,wx,wz\n0,0,0,0.1,1,2\n"),
              HasSubstr(at(1) + "the header has only 2 of the angular velocity columns wx,wy,wz; "
                                "give all three or none"));
  EXPECT_THAT(error_of("x,y,z,radius\n0,0,0,0.1\n0.5,0.5\n"),
              HasSubstr(at(3) + "expected 4 columns, found 2"));
  EXPECT_THAT(error_of("x,y,z,radius\n0,0,0,0.1,7\n"), HasSubstr(at(2) + "expected 4 columns, found 5"));
  // A trailing comma makes one more (empty) cell: a row "…,0.1," has five cells, not four
  // (it was read as four and accepted), and a row whose last value is missing reads "empty".
  EXPECT_THAT(error_of("x,y,z,radius\n0,0,0,0.1,\n"),
              HasSubstr(at(2) + "expected 4 columns, found 5"));
  EXPECT_THAT(error_of("x,y,z,radius\n0,0,0,\n"), HasSubstr(at(2) + "column 'radius' is empty"));
  EXPECT_THAT(
      error_of("x,y,z,radius,\n0,0,0,0.1,\n"),
      HasSubstr(at(1) + "column 5 of the header has no name (two commas in a row, or one at "
                        "the end of the line)"));
}

TEST_F(BrokenCsv, NonNumericAndNonFiniteValues) {
  EXPECT_THAT(error_of("x,y,z,radius\n0,abc,0,0.1\n"),
              HasSubstr(at(2) + "column 'y' is not a finite number: 'abc'"));
  EXPECT_THAT(error_of("x,y,z,radius\n0,0,0.5m,0.1\n"),
              HasSubstr(at(2) + "column 'z' is not a finite number: '0.5m'"));
  EXPECT_THAT(error_of("x,y,z,radius\n0,0,,0.1\n"),
              HasSubstr(at(2) + "column 'z' is empty; give a number"));
  EXPECT_THAT(error_of("x,y,z,radius\nnan,0,0,0.1\n"),
              HasSubstr(at(2) + "column 'x' is not a finite number: 'nan'"));
  EXPECT_THAT(error_of("x,y,z,radius\n0,0,0,1e999\n"),  // overflows to inf
              HasSubstr(at(2) + "column 'radius' is not a finite number: '1e999'"));
  EXPECT_THAT(error_of("x,y,z,radius\n0,0,0,-0.1\n"), HasSubstr(at(2) + "radius must be > 0, got -0.1"));
  EXPECT_THAT(error_of("x,y,z,radius,material\n0,0,0,0.1,glas\n"),
              HasSubstr(at(2) + "unknown material 'glas'; known materials: m"));
  // A parcel class is not a material a file names (its rows became parcels of k = 2, undocumented).
  EXPECT_THAT(error_of("x,y,z,radius,material\n0,0,0,0.1,m[k=2]\n", false, true),
              HasSubstr(at(2) + "unknown material 'm[k=2]'; known materials: m (a parcel class of "
                                "`coarse_grain`, which a csv file cannot insert"));
  EXPECT_EQ(error_of("x,y,z,radius,material\n0,0,0,0.1,m\n", false, true), "no error");
}

TEST_F(BrokenCsv, OutsideTheDomainAndOverlapping) {
  EXPECT_THAT(error_of("x,y,z,radius\n0,0,0,0.1\n0,0.95,0,0.1\n"),
              HasSubstr(at(3) + "the particle at (0, 0.95, 0) with radius 0.1 is outside the "
                                "domain: it spans y from 0.85 to 1.05, beyond the domain's -1 to 1"));
  EXPECT_THAT(error_of("x,y,z,radius\n0,0,5,0.1\n", true),
              HasSubstr(at(2) + "the particle at (0, 0, 5) with radius 0.1 is outside the domain: "
                                "its centre z = 5 is outside the periodic range [-1, 1)"));
  EXPECT_THAT(error_of("x,y,z,radius\n0,0,0,0.1\n0.15,0,0,0.1\n"),
              HasSubstr(at(3) + "the particle at (0.15, 0, 0) with radius 0.1 overlaps an earlier "
                                "particle at (0, 0, 0) with radius 0.1"));
  // Across a periodic boundary: x = 0.95 and x = -0.95 are 0.1 apart.
  EXPECT_THAT(error_of("x,y,z,radius\n0.95,0,0,0.1\n-0.95,0,0,0.1\n", true),
              HasSubstr(at(3) + "the particle at (-0.95, 0, 0) with radius 0.1 overlaps an earlier "
                                "particle at (0.95, 0, 0)"));
  // A radius far beyond the search grid's cells (the grid edge is 2/50 here): checked
  // against every earlier particle instead of visiting ~(2e6)^3 cells.
  EXPECT_THAT(error_of("x,y,z,radius\n0,0,0,0.01\n0.5,0.5,0.5,4e4\n", true),
              HasSubstr(at(3) + "the particle at (0.5, 0.5, 0.5) with radius 40000 overlaps an "
                                "earlier particle at (0, 0, 0) with radius 0.01"));
}

// Two fills of equal regions without a `seed`: each entry's default seed is its own (1 + its
// index), so the second bed is not the first one shifted, as it was when both drew from seed
// 1 (largest difference 8.7e-19 m, the probe). With one seed given to both, it is, which shows
// what the comparison sees.
TEST(FillInsertion, FillsWithoutASeedDrawIndependentLayouts) {
  const auto layouts = [](const std::string& seed) {
    const std::string fill =
        "    count: 30\n    material: glass\n    radius: {distribution: uniform, min: 3e-4, "
        "max: 5e-4}\n" +
        seed;
    const Scene s = parse_scene(
        "domain: {min: [0, 0, 0], max: [0.01, 0.01, 0.02]}\n"
        "time: {step: 1e-6, end: 1e-5}\n"
        "materials: [{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}]\n"
        "interaction_defaults: {restitution: 0.5}\n"
        "contact: {normal: hertz}\n"
        "insert:\n"
        "  - type: fill\n    region: {box: {min: [0, 0, 0], max: [0.01, 0.01, 0.01]}}\n" +
            fill +
            "  - type: fill\n    region: {box: {min: [0, 0, 0.01], max: [0.01, 0.01, 0.02]}}\n" +
            fill,
        "<test>");
    Particles p;
    GlobalId next = 1;
    insert_particles(s, p, next);
    EXPECT_EQ(p.size(), 60u);
    double largest = 0;  // between bead k of the first bed and bead k of the second, shifted
    for (std::size_t k = 0; k < 30; ++k)
      largest = std::max({largest, (p.x[k + 30] - Vec3(0, 0, 0.01) - p.x[k]).norm(),
                          std::abs(p.radius[k + 30] - p.radius[k])});
    return std::make_pair(largest, s.insertions[1].seed);
  };
  const auto [by_default, second_seed] = layouts("");
  const auto [same_seed, given] = layouts("    seed: 5\n");
  std::printf(
      "[ measured ] largest difference between the beds: default seeds (1, %u) %.3g m, "
      "both seed %u %.3g m\n",
      second_seed, by_default, given, same_seed);
  EXPECT_EQ(second_seed, 2u);
  EXPECT_GT(by_default, 1e-4);
  EXPECT_LT(same_seed, 1e-15);
}

// A volume fraction is reached by the last particle drawn, which overshoots it: one 4 mm bead
// is 0.268 of a 1 cm box, where 0.01 was asked. The fill reports what it placed; a large fill,
// within 5 % of what it asked, says nothing.
TEST(FillInsertion, AVolumeFractionOvershotByItsLastParticleIsReported) {
  const auto notes_of = [](double box, double fraction, double radius) {
    Scene s = test::one_material_scene(1e7, 0.3, 2000, 0.5);
    Insertion ins = box_fill(Vec3(0, 0, 0), Vec3(box, box, box));
    ins.volume_fraction = fraction;
    ins.radius.kind = SizeDistribution::Kind::constant;
    ins.radius.value = radius;
    ins.source = "tiny.yaml:8";
    s.insertions.push_back(ins);
    Particles p;
    GlobalId next = 1;
    std::vector<std::string> notes;
    insert_particles(s, p, next, nullptr, &notes);
    double volume = 0;
    for (double r : p.radius) volume += sphere_volume(r);
    std::printf("[ measured ] %.3g asked, %.4f placed (%zu particles)\n", fraction,
                volume / (box * box * box), p.size());
    return notes;
  };
  const std::vector<std::string> tiny = notes_of(0.01, 0.01, 4e-3);
  ASSERT_EQ(tiny.size(), 1u);
  const double one = sphere_volume(4e-3) / 1e-6;  // 0.26808
  EXPECT_THAT(tiny[0], HasSubstr("tiny.yaml:8: the fill placed 1 particle, a volume fraction of "
                                 "0.2681 of its region, where volume_fraction asks 0.01"));
  EXPECT_NEAR(one, 0.2681, 5e-5);
  EXPECT_TRUE(notes_of(0.02, 0.2, 5e-4).empty());
}

// The InsertionError that inserting the scene's particles throws ("no error" if none).
std::string insertion_error(const Scene& s) {
  try {
    Particles p;
    GlobalId next = 1;
    insert_particles(s, p, next, nullptr, nullptr);
  } catch (const InsertionError& e) {
    return e.what();
  }
  return "no error";
}

// A box region around a drum (a cylinder wall of radius 6 mm in a 20 mm box): the walls leave
// the particles pi R^2 / (20 mm)^2 = 0.2827 of the region's volume, and `volume_fraction`
// counts the whole region, so 0.05 asked stood as 0.18 in the drum, without a word. The note
// gives the share left (to the sampling's 1 %) and the solid fraction there (the placed volume
// over the share, checked against the particles' volume over the drum's);
// a fill that cannot be placed says how much volume_fraction is of the space left, and its
// advice, rerun, fits. A fill into a region earlier particles hold 0.3 of says so.
TEST(FillInsertion, AVolumeFractionOfARegionWallsMostlyTakeIsSaidInTheSpaceLeft) {
  const auto scene = [](double fraction, const std::string& extra) {
    return parse_scene(
        "domain: {min: [0, 0, 0], max: [0.02, 0.02, 0.02]}\n"
        "time: {step: 1e-6, end: 1e-6}\n"
        "materials: [{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}]\n"
        "interaction_defaults: {restitution: 0.9, friction: 0.5}\n"
        "contact: {normal: hertz}\n"
        "walls:\n"
        "  - {type: cylinder, name: drum, axis_point: [0.01, 0.01, 0], axis: [0, 0, 1], "
        "radius: 0.006, material: glass}\n"
        "insert:\n" +
            extra +
            "  - {type: fill, region: {box: {min: [0, 0, 0], max: [0.02, 0.02, 0.02]}}, "
            "volume_fraction: " +
            std::to_string(fraction) + ", material: glass, radius: 5e-4}\n",
        "drum.yaml");
  };
  const double left = std::numbers::pi * 0.006 * 0.006 / (0.02 * 0.02);  // the drum's share
  {
    const Scene s = scene(0.05, "");
    Particles p;
    GlobalId next = 1;
    std::vector<std::string> notes;
    insert_particles(s, p, next, nullptr, &notes);
    ASSERT_EQ(notes.size(), 1u);
    double volume = 0;
    for (double ri : p.radius) volume += sphere_volume(ri);
    const double reached = volume / 8e-6;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(notes[0], m,
                                  std::regex("leave about ([0-9.]+) % of the fill's "
                                             "region.*so its [0-9.]+ is about "
                                             "([0-9.]+) solid fraction")))
        << notes[0];
    const double said = std::stod(m[1]) / 100, there = std::stod(m[2]);
    std::printf(
        "[ measured ] %s\n[ measured ] share left %.4f (closed form %.4f); %.4f placed, "
        "%.3f in the space left (said %.3f)\n",
        notes[0].c_str(), said, left, reached, reached / left, there);
    EXPECT_NEAR(said, left, 0.01);             // the share left, sampled
    EXPECT_NEAR(there, reached / said, 1e-3);  // printed to 3 digits
    EXPECT_NEAR(there, reached / left, 0.03 * reached / left);
    // In the drum itself: the particles' volume over the drum's (their centres all inside).
    double in_drum = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      EXPECT_LE(std::hypot(p.x[i][0] - 0.01, p.x[i][1] - 0.01), 0.006 - p.radius[i] + 1e-12);
      in_drum += sphere_volume(p.radius[i]);
    }
    const double drum = std::numbers::pi * 0.006 * 0.006 * 0.02;
    std::printf("[ measured ] solid fraction in the drum %.3f\n", in_drum / drum);
    EXPECT_GT(in_drum / drum, 0.17);  // 0.05 of the region: 3.5 times that in the drum
    EXPECT_NEAR(there, in_drum / drum, 0.03 * in_drum / drum);  // what the note says it is
  }
  const std::string error = insertion_error(scene(0.115, ""));
  std::printf("[ measured ] %s\n", error.c_str());
  EXPECT_THAT(error, HasSubstr("`volume_fraction` counts the whole region, so 0.115 of it is"));
  std::smatch fits;
  ASSERT_TRUE(std::regex_search(error, fits, std::regex("a `volume_fraction` of ([0-9.]+) fits")));
  EXPECT_EQ(insertion_error(scene(std::stod(fits[1]), "")), "no error") << fits[1];
  // Earlier particles: a first fill of 0.06 in the same region, then 0.1 more.
  const std::string crowded = insertion_error(
      scene(0.1,
            "  - {type: fill, region: {box: {min: [0, 0, 0], max: [0.02, 0.02, 0.02]}}, "
            "volume_fraction: 0.06, material: glass, radius: 5e-4}\n"));
  std::printf("[ measured ] %s\n", crowded.c_str());
  EXPECT_THAT(crowded, HasSubstr("earlier insertions already fill 0.06"));
}

// A normal distribution is drawn cut to [min, max]; with mean 2 mm, stddev 2 mm and the
// default bounds (mean/10, mean + 3 stddev) the radii drawn average 2.64 mm, and a note says
// so. Reference: the cut distribution's mean and standard deviation by quadrature of the
// normal density over [min, max] (independent of the note's closed form), and the mean of
// 20 000 radii a fill draws (within 4 standard errors). Bounds at mean +- 3 stddev: no note.
TEST(FillInsertion, ANormalDistributionCutFarFromSymmetricSaysItsMean) {
  const auto scene = [](const std::string& radius) {
    return parse_scene(
        "domain: {min: [0, 0, 0], max: [1, 1, 1]}\n"
        "time: {step: 1e-6, end: 1e-6}\n"
        "materials: [{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}]\n"
        "interaction_defaults: {restitution: 0.9, friction: 0.5}\n"
        "contact: {normal: hertz}\n"
        "insert:\n"
        "  - {type: fill, region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}, count: 20000, "
        "material: glass, radius: " +
            radius + "}\n",
        "normal.yaml");
  };
  const Scene s = scene("{distribution: normal, mean: 2e-3, stddev: 2e-3}");
  ASSERT_EQ(s.notes.size(), 1u);
  const double lo = 2e-4, hi = 8e-3, mu = 2e-3, sigma = 2e-3;
  double w = 0, m1 = 0, m2 = 0;
  const int n = 200000;
  for (int k = 0; k < n; ++k) {  // midpoint rule
    const double x = lo + (hi - lo) * (k + 0.5) / n;
    const double f = std::exp(-0.5 * (x - mu) * (x - mu) / (sigma * sigma));
    w += f;
    m1 += f * x;
    m2 += f * x * x;
  }
  const double mean = m1 / w, sd = std::sqrt(m2 / w - mean * mean);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(s.notes[0], m,
                                std::regex("have mean ([0-9.e-]+) m .* standard deviation "
                                           "([0-9.e-]+) m")))
      << s.notes[0];
  Particles p;
  GlobalId next = 1;
  insert_particles(s, p, next, nullptr, nullptr);
  double sum = 0;
  for (double r : p.radius) sum += r;
  const double sample = sum / static_cast<double>(p.size());
  std::printf(
      "[ measured ] %s\n[ measured ] quadrature: mean %.6g sd %.6g; note %s %s; 20000 "
      "radii drawn: mean %.6g\n",
      s.notes[0].c_str(), mean, sd, m[1].str().c_str(), m[2].str().c_str(), sample);
  EXPECT_THAT(s.notes[0], HasSubstr("normal.yaml:7:"));
  EXPECT_NEAR(std::stod(m[1]), mean, 5e-4 * mean);  // printed to 4 digits
  EXPECT_NEAR(std::stod(m[2]), sd, 5e-4 * sd);
  EXPECT_NEAR(sample, mean, 4 * sd / std::sqrt(20000.0));
  EXPECT_TRUE(scene("{distribution: normal, mean: 2e-3, stddev: 2e-4}").notes.empty());
}

// A fill larger than memory can hold (1e11 particles of 0.1 um, a volume fraction of 0.2 of
// 0.1 um radii in a 2 cm box: 3.8e14) died in std::bad_alloc (or, for the volume fraction,
// grew its radius list until the machine ran out of memory). Refused before anything is
// drawn, naming the count and the memory.
TEST(FillInsertion, AFillLargerThanMemoryIsRefusedBeforeItIsDrawn) {
  const auto error_of = [](const std::string& amount) {
    const Scene s = parse_scene(
        "domain: {min: [0, 0, 0], max: [0.02, 0.02, 0.02]}\n"
        "time: {step: 1e-6, end: 1e-6}\n"
        "materials: [{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}]\n"
        "interaction_defaults: {restitution: 0.9, friction: 0.5}\n"
        "contact: {normal: hertz}\n"
        "insert:\n"
        "  - {type: fill, region: {box: {min: [0, 0, 0], max: [0.02, 0.02, 0.02]}}, " +
            amount + ", material: glass, radius: 1e-7}\n",
        "huge.yaml");
    return insertion_error(s);
  };
  const std::string by_count = error_of("count: 1e11"),
                    by_fraction = error_of("volume_fraction: 0.2");
  std::printf("[ measured ] %s\n[ measured ] %s\n", by_count.c_str(), by_fraction.c_str());
  EXPECT_THAT(by_count, HasSubstr("huge.yaml:7: error: this fill would insert 1e+11 particles"));
  EXPECT_THAT(by_count, HasSubstr("`count` counts parcels, so with `coarse_grain: k`"));
  // 0.2 x 8e-6 m^3 / (4/3 pi 1e-21 m^3) = 3.82e14
  EXPECT_THAT(by_fraction, HasSubstr("this fill would insert about 3.82e+14 particles"));
}

}  // namespace
}  // namespace grainflow
