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
