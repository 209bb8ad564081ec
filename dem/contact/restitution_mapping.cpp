#include "dem/contact/restitution_mapping.hpp"

#include <cmath>
#include <stdexcept>

#include "dem/core/lanes.hpp"

namespace grainflow {
namespace {

struct ScaledImpact {
  double restitution;
  double duration;
};

constexpr double kStep = 2e-5;  // h of the scaled time

// One RK4 step of x'' = -x^{3/2} - c x^{1/4} x' from (x, v) to (xn, vn), for V = double or
// lanes of it (dem/core/lanes.hpp: the same IEEE operations in each lane, so the same bits).
template <class V>
[[gnu::always_inline]] inline void rk4_step(const V& c, const V& x, const V& v, V& xn, V& vn) {
  const auto acc = [&c](const V& xx, const V& vv) {
    const V xp = select(xx > 0.0, xx, V{});
    return -xp * lane_sqrt(xp) - c * lane_sqrt(lane_sqrt(xp)) * vv;
  };
  const double h = kStep;
  const V k1x = v, k1v = acc(x, v);
  const V k2x = v + 0.5 * h * k1v, k2v = acc(x + 0.5 * h * k1x, v + 0.5 * h * k1v);
  const V k3x = v + 0.5 * h * k2v, k3v = acc(x + 0.5 * h * k2x, v + 0.5 * h * k2v);
  const V k4x = v + h * k3v, k4v = acc(x + h * k3x, v + h * k3v);
  xn = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
  vn = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
}

// RK4 on the scaled equation until the overlap returns to zero; the crossing is
// located by linear interpolation within the last step. h = 2e-5 gives the
// restitution to ~1e-9 (checked by halving h). Heavy damping makes the overlap creep back to
// zero without a rebound; past 50 scaled time units (~15 elastic contact durations) the
// restitution is 0 to ~1e-6.
constexpr long kMaxSteps = static_cast<long>(50 / kStep);
ScaledImpact integrate_scaled_impact(double b) {
  const double c = std::sqrt(5.0) * b;
  double x = 0, v = 1, t = 0;
  for (long k = 0; k < kMaxSteps; ++k) {
    double xn, vn;
    rk4_step(c, x, v, xn, vn);
    if (t > 0 && xn <= 0) {
      const double s = x / (x - xn);
      return {-(v + s * (vn - v)), t + s * kStep};
    }
    x = xn;
    v = vn;
    t += kStep;
  }
  return {0.0, t};
}

// The restitution at kChains values of b at once: integrate_scaled_impact in the lanes of
// Lanes2x2, so the same bits. An RK4 stage waits on two square roots in a row; four lanes in
// two SSE2 chains take about the time of one. A lane's result is taken at its own crossing.
constexpr int kChains = 4;
void scaled_restitutions(const double (&b)[kChains], double (&restitution)[kChains]) {
  using V = Lanes2x2;
  V c, x{}, v;
  for (int l = 0; l < kChains; ++l) {
    c.part[l / 2][l % 2] = std::sqrt(5.0) * b[l];
    v.part[l / 2][l % 2] = 1.0;
    restitution[l] = 0.0;
  }
  bool done[kChains] = {};
  int left = kChains;
  double t = 0;  // the same in every lane
  for (long k = 0; k < kMaxSteps && left > 0; ++k) {
    V xn, vn;
    rk4_step(c, x, v, xn, vn);
    if (t > 0)
      for (int l = 0; l < kChains; ++l)
        if (!done[l] && xn[l] <= 0) {
          const double xl = x[l], vl = v[l];
          const double s = xl / (xl - xn[l]);
          restitution[l] = -(vl + s * (vn[l] - vl));
          done[l] = true;
          --left;
        }
    x = xn;  // a lane past its crossing goes on, unread
    v = vn;
    t += kStep;
  }
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
  // Two halvings per round: the midpoint and the two quarter points are evaluated at once
  // (scaled_restitutions), and the quarter point on the side the midpoint's test keeps is the
  // next midpoint, the same expression 0.5 (lo + hi) of the same bounds. So the halvings, and
  // the b returned, are those of one halving per evaluation, to the bit (RestitutionMapping
  // test): 0.17 instead of 0.26 s for e = 0.5, paid at start-up for each restitution.
  for (int it = 0; it < 60 && hi - lo > 1e-12 * hi;) {
    const double mid = 0.5 * (lo + hi);
    const double b[kChains] = {mid, 0.5 * (lo + mid), 0.5 * (mid + hi), mid};
    double r[kChains];
    scaled_restitutions(b, r);
    const bool above = r[0] > e;
    (above ? lo : hi) = mid;
    if (!(++it < 60 && hi - lo > 1e-12 * hi)) break;
    (r[above ? 2 : 1] > e ? lo : hi) = b[above ? 2 : 1];
    ++it;
  }
  return 0.5 * (lo + hi);
}

}  // namespace grainflow
