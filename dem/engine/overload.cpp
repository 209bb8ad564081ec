#include "dem/engine/overload.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace grainflow {

double elastic_force(const ContactLoad& c, double d) {
  if (d <= 0) return 0;
  return c.hertz ? 4.0 / 3.0 * c.y_star * std::sqrt(c.r_star) * d * std::sqrt(d) : c.kn * d;
}

namespace {
double elastic_energy(const ContactLoad& c, double d) {
  if (d <= 0) return 0;
  return c.hertz ? 8.0 / 15.0 * c.y_star * std::sqrt(c.r_star) * d * d * std::sqrt(d)
                 : 0.5 * c.kn * d * d;
}

// The elastic energy the contact (and its series partner) hold now: the partner's from its
// own overlap, with its stiffness from λ (Hooke k₂ = k/λ; Hertz K₂ = K λ^{-3/2}).
double energy_now(const ContactLoad& c) {
  const double d0 = std::max(c.overlap, 0.0);
  double e = elastic_energy(c, d0);
  if (c.series > 0)
    e += elastic_energy(c, c.series_overlap) * (c.hertz ? std::pow(c.series, -1.5) : 1 / c.series);
  return e;
}

// The driver's travel towards the far body now: both overlaps (one for a single contact).
double travel_now(const ContactLoad& c) {
  return std::max(c.overlap, 0.0) + (c.series > 0 ? std::max(c.series_overlap, 0.0) : 0.0);
}
}  // namespace

double cohesion_force(const ContactLoad& c, double d) {
  if (c.cohesion <= 0 || d <= 0) return 0;
  if (c.wall) return c.cohesion * std::numbers::pi * (2 * c.r_i * d - d * d);
  // The overlap disc of two spheres at centre distance s = r_i + r_j - d (cohesion.hpp).
  const double s = c.r_i + c.r_j - d, ri = c.r_i, rj = c.r_j;
  const double a2 = -(s - ri - rj) * (s + ri - rj) * (s - ri + rj) * (s + ri + rj) / (4 * s * s);
  return c.cohesion * std::numbers::pi * std::max(a2, 0.0);
}

double stopping_overlap(const ContactLoad& c, double ks, double cs) {
  const double d0 = std::max(c.overlap, 0.0), top = c.r_small;
  if (d0 >= top) return kNoStop;
  const double kinetic = c.speed > 0 ? 0.5 * c.m_star * c.speed * c.speed : 0.0;
  // March the energy balance g(δ) = ks ΔE_el − kinetic − W Δδ − cs ∫F_c (trapezoid) up to
  // the smaller radius; the first root above δ₀ is where the approach ends (δ₀ itself when
  // at rest there and pushed out: g > 0 at once).
  constexpr int n = 20000;
  // A chain stores (1 + λ) E_el(δ) once its contacts carry one force, and the load works
  // over the driver's travel (1 + λ) δ (overload.hpp); its energy now is what each contact
  // holds at its own overlap.
  const double chain = 1 + std::max(c.series, 0.0);
  const double h = (top - d0) / n, e0 = energy_now(c), x0 = travel_now(c);
  const auto balance = [&](double d, double work_c) {
    return ks * (chain * elastic_energy(c, d) - e0) - kinetic - c.load * (chain * d - x0) - work_c;
  };
  double work_c = 0, f_prev = cs * cohesion_force(c, d0), g_prev = balance(d0, 0);
  for (int k = 1; k <= n; ++k) {
    const double d = d0 + k * h;
    const double f = cs * cohesion_force(c, d);
    work_c += 0.5 * h * (f + f_prev);
    f_prev = f;
    const double g = balance(d, work_c);
    if (g >= 0) return g_prev >= 0 ? d - h : d - h * g / (g - g_prev);  // linear between samples
    g_prev = g;
  }
  return kNoStop;
}

double equilibrium_overlap(const ContactLoad& c) {
  // The first δ where the spring carries the load and the cohesion: F_el − F_c ≥ W, found by
  // a march and a bisection on the bracketing interval.
  const auto net = [&](double d) { return elastic_force(c, d) - cohesion_force(c, d) - c.load; };
  constexpr int n = 2000;
  const double h = c.r_small / n;
  if (net(0) >= 0) return 0;
  for (int k = 1; k <= n; ++k) {
    double lo = (k - 1) * h, hi = k * h;
    if (net(hi) < 0) continue;
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      (net(mid) >= 0 ? hi : lo) = mid;
    }
    return hi;
  }
  return kNoStop;
}

ContactLoad at_first_touch(const ContactLoad& c) {
  ContactLoad t = c;
  const double d0 = std::max(c.overlap, 0.0);
  // ∫₀^δ₀ F_c by the trapezoid rule (F_c is smooth; 2000 intervals).
  constexpr int n = 2000;
  double work_c = 0;
  for (int k = 0; k < n; ++k)
    work_c += 0.5 * d0 / n * (cohesion_force(c, d0 * k / n) + cohesion_force(c, d0 * (k + 1) / n));
  const double v = std::max(c.speed, 0.0);
  const double e0 = 0.5 * c.m_star * v * v + energy_now(c) - c.load * travel_now(c) - work_c;
  t.overlap = 0;
  t.series_overlap = 0;
  t.speed = e0 > 0 ? std::sqrt(2 * e0 / c.m_star) : 0.0;
  return t;
}

double stiffness_factor_for(const ContactLoad& c, double target) {
  double lo = 1, hi = 1;
  while (!(stopping_overlap(c, hi) <= target)) {
    lo = hi;
    hi *= 4;
    if (hi > 1e12) return kNoStop;
  }
  if (hi == 1) return 1;
  for (int k = 0; k < 60; ++k) {
    const double mid = std::sqrt(lo * hi);
    (stopping_overlap(c, mid) <= target ? hi : lo) = mid;
  }
  return hi;
}

double cohesion_factor_for(const ContactLoad& c, double target) {
  if (!(stopping_overlap(c, 1, 0) <= target)) return -1;
  if (stopping_overlap(c, 1, 1) <= target) return 1;
  double lo = 0, hi = 1;
  for (int k = 0; k < 50; ++k) {
    const double mid = 0.5 * (lo + hi);
    (stopping_overlap(c, 1, mid) <= target ? lo : hi) = mid;
  }
  return lo;
}

}  // namespace grainflow
