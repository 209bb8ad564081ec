#include "dem/contact/restitution_mapping.hpp"

#include <cmath>
#include <stdexcept>

namespace grainflow {
namespace {

struct ScaledImpact {
  double restitution;
  double duration;
};

// RK4 on the scaled equation until the overlap returns to zero; the crossing is
// located by linear interpolation within the last step. h = 2e-5 gives the
// restitution to ~1e-9 (checked by halving h).
ScaledImpact integrate_scaled_impact(double b) {
  const double c = std::sqrt(5.0) * b;
  auto acc = [c](double x, double v) {
    const double xp = x > 0 ? x : 0;
    return -xp * std::sqrt(xp) - c * std::sqrt(std::sqrt(xp)) * v;
  };
  const double h = 2e-5;
  double x = 0, v = 1, t = 0;
  // Heavy damping makes the overlap creep back to zero without a rebound; past 50
  // scaled time units (~15 elastic contact durations) the restitution is 0 to ~1e-6.
  for (long k = 0; k < static_cast<long>(50 / h); ++k) {
    const double k1x = v, k1v = acc(x, v);
    const double k2x = v + 0.5 * h * k1v, k2v = acc(x + 0.5 * h * k1x, v + 0.5 * h * k1v);
    const double k3x = v + 0.5 * h * k2v, k3v = acc(x + 0.5 * h * k2x, v + 0.5 * h * k2v);
    const double k4x = v + h * k3v, k4v = acc(x + h * k3x, v + h * k3v);
    const double xn = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    const double vn = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    if (t > 0 && xn <= 0) {
      const double s = x / (x - xn);
      return {-(v + s * (vn - v)), t + s * h};
    }
    x = xn;
    v = vn;
    t += h;
  }
  return {0.0, t};
}

}  // namespace

double hertz_restitution(double b) { return integrate_scaled_impact(b).restitution; }

double hertz_scaled_contact_time(double b) { return integrate_scaled_impact(b).duration; }

double hertz_damping_for_restitution(double e) {
  if (!(e > 0 && e <= 1)) throw std::invalid_argument("restitution must lie in (0, 1]");
  if (e == 1) return 0;
  // hertz_restitution is monotone decreasing in b; bracket, then bisect.
  double lo = 0, hi = 0.25;
  while (hertz_restitution(hi) > e) hi *= 2;
  for (int it = 0; it < 60 && hi - lo > 1e-12 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (hertz_restitution(mid) > e ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace grainflow
