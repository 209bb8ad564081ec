// Particle footprints for the void fraction (coupling/footprint.hpp), checked against exact
// geometry, not against the code's own output:
//  - every method: weights sum to 1 (1e-14, round-off of ~200 terms) and the first moment
//    is 0 (1e-15 r: the points are exact mirror pairs, so only summation round-off remains);
//  - divided: the weight above a plane z = h is the spherical-cap volume fraction
//    V_cap / V = (r - h)^2 (2r + h) / (4 r^3). When h is a lattice plane the parts above it
//    are exactly the sphere above it, so the only error is the 16^3 midpoint sampling of each
//    little cube: worst measured 4.1e-4 (n = 3), tolerance 5e-4. Between lattice planes a
//    whole layer of points jumps at once: at the default n = 5 the worst error over h is
//    0.148 (at h = 0, half the middle layer) and the RMS over h in (-r, r) is 0.056;
//  - divided: a centred cube of half-edge a < r / sqrt(3) lies inside the sphere, so it
//    holds (2a)^3 / V of the volume; exact when a is a lattice plane, up to the midpoint count
//    of the whole sphere that normalises the weights (relative error < 1e-3 on a 16n-point
//    grid, measured 9.7e-4 at n = 8): tolerance 2e-3 relative;
//  - smoothed: the second moment about the centre equals that of the truncated Gaussian,
//    <s^2> = int_0^R s^4 exp(-s^2 / 2 sigma^2) ds / int_0^R s^2 exp(...) ds (Simpson here,
//    error < 1e-10), within 1e-3 (measured 6e-5: the per-cube midpoint sums). The weight
//    above a lattice plane z = h equals the truncated Gaussian's, whose z-marginal is
//    exp(-z^2 / 2 sigma^2) - exp(-R^2 / 2 sigma^2) on [-R, R] (integrate the disc of radius
//    sqrt(R^2 - z^2)), so F(h) has a closed form in erf; tolerance 2e-4 (measured 3.5e-5).
#include "coupling/footprint.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

namespace grainflow::coupling {
namespace {

using Points = std::vector<FootprintPoint>;
constexpr double kPi = std::numbers::pi;

double weight_sum(const Points& p) {
  double s = 0;
  for (const auto& q : p) s += q.weight;
  return s;
}

double weight_above(const Points& p, double h, int axis = 2) {
  double s = 0;
  for (const auto& q : p)
    if (q.offset[axis] > h) s += q.weight;
  return s;
}

double norm(const FootprintPoint& q) {
  return std::sqrt(q.offset[0] * q.offset[0] + q.offset[1] * q.offset[1] +
                   q.offset[2] * q.offset[2]);
}

// Spherical cap above z = h over the sphere's volume: pi (r-h)^2 (2r+h) / 3 / (4 pi r^3 / 3).
double cap_fraction(double h, double r) {
  return (r - h) * (r - h) * (2 * r + h) / (4 * r * r * r);
}

struct Case {
  VoidFractionMethod method;
  int resolution;
  double smoothing;
};

std::vector<Case> all_cases() {
  std::vector<Case> c{{VoidFractionMethod::centre, 5, 2.0}};
  for (int n = 2; n <= 8; ++n) c.push_back({VoidFractionMethod::divided, n, 2.0});
  for (double s : {1.0, 1.5, 2.0}) c.push_back({VoidFractionMethod::smoothed, 5, s});
  return c;
}

TEST(Footprint, WeightsSumToOneAndFirstMomentVanishes) {
  const double r = 1.7e-3;
  for (const Case& c : all_cases()) {
    SCOPED_TRACE(std::string(void_fraction_method_name(c.method)) +
                 " n=" + std::to_string(c.resolution) + " s=" + std::to_string(c.smoothing));
    const Footprint f(c.method, c.resolution, c.smoothing);
    Points p;
    f.points(r, p);
    ASSERT_EQ(p.size(), f.size());
    EXPECT_NEAR(weight_sum(p), 1.0, 1e-14);
    for (int ax = 0; ax < 3; ++ax) {
      double m1 = 0;
      for (const auto& q : p) m1 += q.weight * q.offset[ax];
      EXPECT_NEAR(m1 / r, 0.0, 1e-15) << "axis " << ax;
    }
    for (const auto& q : p) EXPECT_GT(q.weight, 0.0);
  }
}

TEST(Footprint, CentreIsOnePointWithTheWholeVolume) {
  const Footprint f(VoidFractionMethod::centre);
  Points p;
  f.points(0.01, p);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].weight, 1.0);
  EXPECT_EQ(norm(p[0]), 0.0);
  EXPECT_EQ(f.support_radius(0.01), 0.01);
}

TEST(Footprint, OffsetsScaleWithRadiusWeightsDoNot) {
  for (VoidFractionMethod m :
       {VoidFractionMethod::centre, VoidFractionMethod::divided, VoidFractionMethod::smoothed}) {
    const Footprint f(m);
    Points a, b;
    f.points(1e-3, a);
    f.points(3e-3, b);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].weight, b[i].weight);
      for (int ax = 0; ax < 3; ++ax) EXPECT_NEAR(b[i].offset[ax], 3 * a[i].offset[ax], 1e-18);
    }
  }
}

TEST(Footprint, DefaultCosts) {
  // Points per particle (the per-particle cost of a void fraction pass).
  EXPECT_EQ(Footprint(VoidFractionMethod::centre).size(), 1u);
  EXPECT_EQ(Footprint(VoidFractionMethod::divided).size(), 117u);   // 5^3 minus 8 empty corners
  EXPECT_EQ(Footprint(VoidFractionMethod::smoothed).size(), 184u);  // 6^3 minus 32 empty
}

TEST(DividedFootprint, CapFractionExactAtLatticePlanes) {
  const double r = 2e-3;
  for (int n = 2; n <= 8; ++n) {
    const Footprint f(VoidFractionMethod::divided, n);
    Points p;
    f.points(r, p);
    for (int k = (n + 1) / 2; k < n; ++k) {  // planes at h = (2k - n) r / n >= 0
      const double h = (2.0 * k - n) / n * r;
      for (int ax = 0; ax < 3; ++ax)
        EXPECT_NEAR(weight_above(p, h, ax), cap_fraction(h, r), 5e-4)
            << "n = " << n << ", h / r = " << h / r << ", axis " << ax;
    }
  }
}

TEST(DividedFootprint, CapFractionAtArbitraryPlanesDefaultResolution) {
  const double r = 1.0;
  const Footprint f(VoidFractionMethod::divided);
  const Points& p = f.unit_points();
  // Measured errors at h / r = 0.1 .. 0.9: -0.073, +0.068, -0.052, +0.031, -0.007.
  for (double h : {0.1, 0.3, 0.5, 0.7, 0.9})
    EXPECT_NEAR(weight_above(p, h), cap_fraction(h, r), 0.08) << "h / r = " << h;
  // Dense scan of h over (-r, r): worst 0.148, RMS 0.056.
  double worst = 0, sq = 0;
  const int samples = 4000;
  for (int i = 0; i < samples; ++i) {
    const double h = -r + 2 * r * (i + 0.5) / samples;
    const double e = weight_above(p, h) - cap_fraction(h, r);
    worst = std::max(worst, std::fabs(e));
    sq += e * e;
  }
  EXPECT_LT(worst, 0.15);
  EXPECT_LT(std::sqrt(sq / samples), 0.06);
}

TEST(DividedFootprint, CentredCubeInsideSphere) {
  // (n, a / r) with a a lattice plane and a < 1 / sqrt(3).
  const std::vector<std::pair<int, double>> cubes{{5, 0.2}, {6, 1.0 / 3}, {8, 0.25}, {8, 0.5}};
  const double r = 1e-3, v_sphere = 4 * kPi * r * r * r / 3;
  for (const auto& [n, a_over_r] : cubes) {
    const double a = a_over_r * r;
    ASSERT_LT(a, r / std::sqrt(3.0));
    const Footprint f(VoidFractionMethod::divided, n);
    Points p;
    f.points(r, p);
    double inside = 0;
    for (const auto& q : p)
      if (std::fabs(q.offset[0]) < a && std::fabs(q.offset[1]) < a && std::fabs(q.offset[2]) < a)
        inside += q.weight;
    EXPECT_NEAR(inside / (8 * a * a * a / v_sphere), 1.0, 2e-3)
        << "n = " << n << ", a / r = " << a_over_r;
  }
}

TEST(Footprint, PointsLieWithinTheSupport) {
  const double r = 5e-4;
  for (const Case& c : all_cases()) {
    const Footprint f(c.method, c.resolution, c.smoothing);
    const double support = c.method == VoidFractionMethod::smoothed ? c.smoothing * r : r;
    EXPECT_DOUBLE_EQ(f.support_radius(r), support);
    Points p;
    f.points(r, p);
    for (const auto& q : p)
      EXPECT_LE(norm(q), support * (1 + 1e-14)) << void_fraction_method_name(c.method);
  }
}

// Truncated Gaussian, sigma = R / 3: <s^2> by composite Simpson on [0, R].
double truncated_gaussian_second_moment(double big_r) {
  const double sigma = big_r / 3;
  const int intervals = 2000;
  double num = 0, den = 0;
  for (int i = 0; i <= intervals; ++i) {
    const double s = big_r * i / intervals;
    const double w = (i == 0 || i == intervals) ? 1 : (i % 2 ? 4 : 2);
    const double g = std::exp(-s * s / (2 * sigma * sigma));
    num += w * s * s * s * s * g;
    den += w * s * s * g;
  }
  return num / den;
}

TEST(SmoothedFootprint, SecondMomentOfTruncatedGaussian) {
  const double r = 1e-3;
  for (double factor : {1.0, 1.5, 2.0}) {
    const Footprint f(VoidFractionMethod::smoothed, Footprint::kDefaultDividedResolution, factor);
    Points p;
    f.points(r, p);
    double m2 = 0;
    for (const auto& q : p) m2 += q.weight * norm(q) * norm(q);
    const double ref = truncated_gaussian_second_moment(factor * r);
    EXPECT_NEAR(m2 / ref, 1.0, 1e-3) << "smoothing_factor " << factor;
    // Sanity of the reference itself: below the untruncated 3 sigma^2 = R^2 / 3.
    EXPECT_LT(ref, (factor * r) * (factor * r) / 3);
  }
}

TEST(SmoothedFootprint, HalfSpaceFractionAtLatticePlanes) {
  const double r = 1e-3;
  for (double factor : {1.0, 2.0}) {
    const double big_r = factor * r, sigma = big_r / 3, c = sigma * std::sqrt(2.0);
    const double tail = std::exp(-big_r * big_r / (2 * sigma * sigma));
    // int_h^R [exp(-z^2 / 2 sigma^2) - tail] dz
    auto mass_above = [&](double h) {
      return sigma * std::sqrt(kPi / 2) * (std::erf(big_r / c) - std::erf(h / c)) -
             tail * (big_r - h);
    };
    const Footprint f(VoidFractionMethod::smoothed, Footprint::kDefaultDividedResolution, factor);
    Points p;
    f.points(r, p);
    // Lattice of 6 cubes across 2R: planes at 0, R/3, 2R/3.
    for (int k = 0; k < 3; ++k) {
      const double h = big_r * k / 3;
      EXPECT_NEAR(weight_above(p, h), mass_above(h) / mass_above(-big_r), 2e-4)
          << "h / R = " << k << "/3";
    }
  }
}

TEST(VoidFractionMethodName, ParsesAndRoundTrips) {
  for (const char* name : {"centre", "divided", "smoothed"})
    EXPECT_STREQ(void_fraction_method_name(parse_void_fraction_method(name)), name);
}

TEST(VoidFractionMethodName, UnknownNameListsValidNames) {
  for (const char* bad : {"center", "Divided", ""}) {
    try {
      parse_void_fraction_method(bad);
      FAIL() << "no error for \"" << bad << "\"";
    } catch (const std::invalid_argument& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find('"' + std::string(bad) + '"'), std::string::npos) << msg;
      for (const char* valid : {"centre", "divided", "smoothed"})
        EXPECT_NE(msg.find(valid), std::string::npos) << msg;
    }
  }
}

TEST(Footprint, RejectsParametersOutOfRange) {
  EXPECT_THROW(Footprint(VoidFractionMethod::divided, 1), std::invalid_argument);
  EXPECT_THROW(Footprint(VoidFractionMethod::divided, 33), std::invalid_argument);
  EXPECT_THROW(Footprint(VoidFractionMethod::smoothed, 5, 0.9), std::invalid_argument);
  EXPECT_THROW(Footprint(VoidFractionMethod::smoothed, 5, 2.1), std::invalid_argument);
  EXPECT_THROW(Footprint(VoidFractionMethod::smoothed, 5, std::nan("")), std::invalid_argument);
}

}  // namespace
}  // namespace grainflow::coupling
