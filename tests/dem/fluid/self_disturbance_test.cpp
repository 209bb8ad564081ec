// The self-induced velocity of a Gaussian-regularised force (dem/fluid/self_disturbance.hpp)
// against closed forms (Stokes, Brinkman), the Oseen asymptote, a direct quadrature of the
// Fourier integral it comes from, and the table against the quadrature.
#include "dem/fluid/self_disturbance.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace grainflow {
namespace {

constexpr double pi = std::numbers::pi;

// The Fourier integral itself, u'(0) mu sigma / F = (2 pi)^-2 int_0^inf ds int_-1^1 dc
// s^2 e^(-s^2/2) (1 - c^2) (s^2 + b) / ((s^2 + b)^2 + Re^2 s^2 c^2), by the midpoint rule in
// both variables: no closed form of the inner integral is used.
double direct(double re, double b) {
  const int ns = 4000, nc = 2000;
  const double smax = 12;
  double sum = 0;
  for (int i = 0; i < ns; ++i) {
    const double s = (i + 0.5) * smax / ns, s2 = s * s;
    double inner = 0;
    for (int j = 0; j < nc; ++j) {
      const double c = -1 + (j + 0.5) * 2.0 / nc;
      inner += (1 - c * c) * (s2 + b) / ((s2 + b) * (s2 + b) + re * re * s2 * c * c);
    }
    sum += s2 * std::exp(-0.5 * s2) * inner * (2.0 / nc);
  }
  return sum * (smax / ns) / (4 * pi * pi);
}

TEST(SelfDisturbance, StokesLimitIsTheRegularisedStokeslet) {
  // u'(0) = F / (6 pi mu a) with a = sigma sqrt(pi/2): phi = sqrt(pi/2) / (3 pi^2).
  EXPECT_NEAR(self_disturbance_factor(0, 0) / (std::sqrt(pi / 2) / (3 * pi * pi)), 1, 1e-13);
  EXPECT_NEAR(self_disturbance_factor(1e-6, 0) / self_disturbance_factor(0, 0), 1, 1e-5);
}

TEST(SelfDisturbance, BrinkmanScreeningHasItsClosedForm) {
  for (double b : {1e-6, 1e-3, 0.1, 1.0, 10.0, 100.0}) {
    const double exact = (std::sqrt(pi / 2) - pi / 2 * std::sqrt(b) * std::exp(b / 2) *
                                                  std::erfc(std::sqrt(b / 2))) /
                         (3 * pi * pi);
    EXPECT_NEAR(self_disturbance_factor(0, b) / exact, 1, 1e-11) << "b = " << b;
  }
}

TEST(SelfDisturbance, OseenLimitIsTheForceCarriedOffByAdvection) {
  // phi -> 1 / (4 pi Re_sigma): u'(0) = F / (4 pi rho W sigma^2), independent of viscosity.
  EXPECT_NEAR(self_disturbance_factor(1e4, 0) * 4 * pi * 1e4, 1, 2e-4);
  EXPECT_NEAR(self_disturbance_factor(1e4, 1.0) * 4 * pi * 1e4, 1, 5e-4);
  // Monotone: more advection or more screening, less disturbance.
  double last = self_disturbance_factor(0, 0);
  for (double re : {0.1, 1.0, 3.0, 10.0, 100.0}) {
    const double now = self_disturbance_factor(re, 0);
    EXPECT_LT(now, last);
    last = now;
  }
}

TEST(SelfDisturbance, InnerClosedFormAgreesWithTheDirectDoubleIntegral) {
  for (double re : {0.5, 3.0, 20.0})
    for (double b : {0.0, 2.0})
      EXPECT_NEAR(self_disturbance_factor(re, b) / direct(re, b), 1, 2e-4)
          << "Re_sigma " << re << ", b " << b;
}

TEST(SelfDisturbance, TableFollowsTheQuadrature) {
  const SelfDisturbanceTable& table = self_disturbance_table();
  std::mt19937 gen(11);
  std::uniform_real_distribution<double> log_re(-6, 4), log_b(-11, 6);
  double worst = 0;
  for (int k = 0; k < 3000; ++k) {
    const double re = std::pow(10.0, log_re(gen)), b = std::pow(10.0, log_b(gen));
    worst = std::max(worst, std::abs(table(re, b) / self_disturbance_factor(re, b) - 1));
  }
  EXPECT_LT(worst, 2e-4);
  // Past the table's upper ends: the quadrature itself.
  EXPECT_EQ(table(1e7, 1.0), self_disturbance_factor(1e7, 1.0));
}

// The lattice form (lattice_self_disturbance): its table against the quadrature of
// scripts/lattice_self_disturbance.py (a finer one than the table's: 24 Gauss points on 12
// graded panels per transverse axis, 64 along q_z) at points between the table's nodes, and
// its two closed-form limits. Tolerance 2e-3 at the nodes' limits (the table's quadrature
// agrees with the finer one to 2.5e-4; b = 0 is read at the table's lowest b, 1e-6, where
// the Brinkman term's sqrt(b) changes phi by about 1e-3); 6e-3 between nodes, the tricubic
// interpolation at 3 (Re_h), 1.5 (b) points per decade and steps of 1/8 in s/h (measured up
// to 4.8e-3; it changes a settling speed by k m times that, below 0.3 %).
TEST(SelfDisturbance, LatticeStokesLimitIsTwoThirdsOfWatsonsIntegral) {
  // A force in one cell read back from it: (2/3) W (the 2/3 is the projection's mean).
  EXPECT_NEAR(lattice_self_disturbance(0, 0, 0) / (2 * watson_integral / 3), 1, 2e-3);
  EXPECT_NEAR(lattice_self_disturbance(1e-5, 1e-9, 0) / (2 * watson_integral / 3), 1, 2e-3);
}

TEST(SelfDisturbance, LatticeOseenLimitIsTheForceCarriedThroughOneCell) {
  // u' = F / (2 rho W h^2): the momentum flux rho W h^2 u' through one cell's section carries
  // F downstream; the cell reads the mean of upstream (0) and downstream. Above the table's
  // end (Re_h = 1e4) by its log-log extrapolation.
  for (double re : {3e3, 1e4, 1e5, 1e6})
    EXPECT_NEAR(2 * re * lattice_self_disturbance(re, 0, 0), 1, 3e-3) << "Re_h " << re;
}

TEST(SelfDisturbance, LatticeTableFollowsTheQuadrature) {
  struct Case {
    double re, b, s, phi;
  };
  // scripts/lattice_self_disturbance.py, Quadrature(24, 64, 12).phi(re, b, s).
  for (const Case& c : {Case{0.37, 0.0, 0.07, 0.13630020083944536},
                        Case{5.3, 0.02, 0.11, 0.05021511008694206},
                        Case{42.0, 0.0, 0.19, 0.007293548842465539},
                        Case{260.0, 3.0, 0.3, 0.0009458418154526701},
                        Case{0.05, 50.0, 0.45, 0.0026446387912598037}})
    EXPECT_NEAR(lattice_self_disturbance(c.re, c.b, c.s) / c.phi, 1, 6e-3)
        << "Re_h " << c.re << ", b " << c.b << ", s/h " << c.s;
}

TEST(SelfDisturbance, LatticeMobilityIsContinuousWhereTheFootprintOutgrowsTheCell) {
  // For s > h/2 twice the footprint's spread takes the place of the cell size.
  const double h = 1e-3, rho = 1000, mu = 0.01, w = 0.02, beta = 50;
  const double below = lattice_self_mobility(h, 0.5 * h * (1 - 1e-9), w, rho, mu, beta);
  const double above = lattice_self_mobility(h, 0.5 * h * (1 + 1e-9), w, rho, mu, beta);
  EXPECT_NEAR(above / below, 1, 1e-6);
}

TEST(SelfDisturbance, UndisturbedFactorSolvesTheFixedPoint) {
  bool limited = true;
  // Constant k and m: 1 / (1 - k m).
  const double f = undisturbed_factor(
      2.0, [](double) { return 3.0; }, [](double) { return 0.1; }, 0.8, limited);
  EXPECT_NEAR(f, 1 / (1 - 0.3), 1e-12);
  EXPECT_FALSE(limited);
  // A slip-dependent k: the result satisfies w = w_seen / (1 - k(w) m).
  const auto k = [](double w) { return 1 + 0.5 * std::sqrt(w); };
  const double m = 0.3, w_seen = 0.7;
  const double g = undisturbed_factor(w_seen, k, [m](double) { return m; }, 0.8, limited);
  EXPECT_NEAR(g, 1 / (1 - k(w_seen * g) * m), 1e-11);
  // Beyond the limit: held at 1 / (1 - 0.8) and reported.
  const double h = undisturbed_factor(
      1.0, [](double) { return 10.0; }, [](double) { return 0.1; }, 0.8, limited);
  EXPECT_NEAR(h, 5, 1e-12);
  EXPECT_TRUE(limited);
}

}  // namespace
}  // namespace grainflow
