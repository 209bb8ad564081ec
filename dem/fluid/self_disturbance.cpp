#include "dem/fluid/self_disturbance.hpp"

#include "dem/fluid/lattice_self_disturbance_cellpoint_table.hpp"
#include "dem/fluid/lattice_self_disturbance_smoothed_table.hpp"
#include "dem/fluid/lattice_self_disturbance_table.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace grainflow {

namespace {

constexpr double pi = 3.14159265358979323846;

// g(A) = 2 A (1 + A^2) atan(1/A) - 2 A^2 = A^2 [int_-1^1 (1 - c^2) / (A^2 + c^2) dc]; for
// large A its series 4/3 - 4/(15 A^2) + 4/(35 A^4) - ..., whose terms are
// (-1)^k 4 / ((2k + 1)(2k + 3)) A^(-2k), avoids the cancellation of the closed form.
double g(double a) {
  if (a > 8) {
    const double x = 1 / (a * a);
    double sum = 0, p = 1;
    for (int k = 0; k < 14; ++k) {
      sum += (k % 2 ? -4.0 : 4.0) / ((2 * k + 1) * (2 * k + 3)) * p;
      p *= x;
    }
    return sum;
  }
  return 2 * a * (1 + a * a) * std::atan(1 / a) - 2 * a * a;
}

// 24-point Gauss-Legendre nodes and weights on [-1, 1] (positive half; symmetric).
constexpr std::array<double, 12> gl_x = {
    0.0640568928626056260850430826247450, 0.1911188674736163091586398207570696,
    0.3150426796961633743867932913198103, 0.4337935076260451384870842319133497,
    0.5454214713888395356583756172183723, 0.6480936519369755692524957869107476,
    0.7401241915785543642438281030999785, 0.8200019859739029219539498726697453,
    0.8864155270044010342131543419821968, 0.9382745520027327585236490017087215,
    0.9747285559713094981983919930081691, 0.9951872199970213601799974097007368};
constexpr std::array<double, 12> gl_w = {
    0.1279381953467521569740561652246954, 0.1258374563468282961213753825111837,
    0.1216704729278033912044631534762625, 0.1155056680537256013533444839067836,
    0.1074442701159656347825773424466062, 0.0976186521041138882698806644642472,
    0.0861901615319532759171852029837427, 0.0733464814110803057340336152531166,
    0.0592985849154367807463677585001085, 0.0442774388174198061686027482113382,
    0.0285313886289336631813078159518782, 0.0123412297999871995468056670700372};

}  // namespace

double self_disturbance_factor(double re_sigma, double screening) {
  // The integrand s^2 e^(-s^2/2) g(A) / (s^2 + b): smooth, negligible beyond s = 12; a kink
  // of scale min(Re, sqrt b) near s = 0 when Re or b is large is resolved by panels that
  // grow geometrically from s = 1e-4.
  const auto f = [&](double s) {
    const double s2 = s * s;
    const double a = re_sigma > 0 ? (s2 + screening) / (re_sigma * s) : INFINITY;
    const double ga = std::isinf(a) ? 4.0 / 3.0 : g(a);
    return s2 * std::exp(-0.5 * s2) * ga / (s2 + screening);
  };
  double sum = 0, lo = 0, hi = 1e-4;
  while (lo < 12) {
    const double c = 0.5 * (hi + lo), h = 0.5 * (hi - lo);
    for (std::size_t k = 0; k < gl_x.size(); ++k)
      sum += h * gl_w[k] * (f(c - h * gl_x[k]) + f(c + h * gl_x[k]));
    lo = hi;
    hi = std::min(12.0, hi < 0.25 ? 2 * hi : hi + 0.5);
  }
  return sum / (4 * pi * pi);
}

namespace {
constexpr double re_lo = -5, re_hi = 6, b_lo = -10, b_hi = 8, per_decade = 8;
}

SelfDisturbanceTable::SelfDisturbanceTable()
    : nr_(static_cast<int>((re_hi - re_lo) * per_decade) + 1),
      nb_(static_cast<int>((b_hi - b_lo) * per_decade) + 1) {
  log_phi_.resize(static_cast<std::size_t>(nr_) * nb_);
  for (int i = 0; i < nr_; ++i)
    for (int j = 0; j < nb_; ++j)
      log_phi_[static_cast<std::size_t>(i) * nb_ + j] =
          std::log(self_disturbance_factor(std::pow(10.0, re_lo + i / per_decade),
                                           std::pow(10.0, b_lo + j / per_decade)));
}

double SelfDisturbanceTable::operator()(double re_sigma, double screening) const {
  // Beyond the upper ends (Re_sigma > 1e6 or b > 1e8, far outside fluidised and packed
  // beds): the quadrature itself. Below the lower ends phi is flat: within 1e-5 of its
  // value at Re_sigma = 1e-5 (the Oseen term is linear in Re) and at b = 1e-10 (the Brinkman
  // term grows as sqrt(b)).
  double lr = std::log10(std::max(re_sigma, 1e-300));
  double lb = std::log10(std::max(screening, 1e-300));
  if (lr > re_hi || lb > b_hi) return self_disturbance_factor(re_sigma, screening);
  lr = std::max(lr, re_lo);
  lb = std::max(lb, b_lo);
  const double x = (lr - re_lo) * per_decade, y = (lb - b_lo) * per_decade;
  const int i = std::min(static_cast<int>(x), nr_ - 2), j = std::min(static_cast<int>(y), nb_ - 2);
  const double tx = x - i, ty = y - j;
  // Catmull-Rom weights; at the table's edges the missing neighbour is extrapolated linearly.
  const auto w = [](double t) {
    return std::array<double, 4>{0.5 * (-t + 2 * t * t - t * t * t), 0.5 * (2 - 5 * t * t + 3 * t * t * t),
                                 0.5 * (t + 4 * t * t - 3 * t * t * t), 0.5 * (-t * t + t * t * t)};
  };
  const auto value = [&](int a, int c) {
    // Linear extrapolation one point past an edge.
    const auto col = [&](int aa) {
      if (c < 0) return 2 * at(aa, 0) - at(aa, 1);
      if (c >= nb_) return 2 * at(aa, nb_ - 1) - at(aa, nb_ - 2);
      return at(aa, c);
    };
    if (a < 0) return 2 * col(0) - col(1);
    if (a >= nr_) return 2 * col(nr_ - 1) - col(nr_ - 2);
    return col(a);
  };
  const auto wx = w(tx), wy = w(ty);
  double lp = 0;
  for (int a = 0; a < 4; ++a)
    for (int c = 0; c < 4; ++c) lp += wx[a] * wy[c] * value(i - 1 + a, j - 1 + c);
  return std::exp(lp);
}

namespace {

// The tricubic interpolation's points and weights at (Re_h, b, s/h), shared by the tables.
struct LatticeStencil {
  std::array<int, 4> ix, iy, iz;
  std::array<double, 4> wx, wy, wz;
};

LatticeStencil lattice_stencil(double re_h, double screening, double spread_over_h) {
  namespace t = lattice_table;
  // Fractional indices along the three axes; outside the table the end cells are used (held
  // below Re_h and b, extrapolated linearly above: there the Catmull-Rom weights at t > 1
  // reduce to the linear continuation of the last interval).
  const double x = (std::log10(std::max(re_h, 1e-300)) - t::log_re_lo) * t::log_re_per_decade;
  const double y = (std::log10(std::max(screening, 1e-300)) - t::log_b_lo) * t::log_b_per_decade;
  const double z = (std::min(std::max(spread_over_h, 0.0), 0.5) - t::spread_lo) * t::spread_per_unit;
  const auto split = [](double u, int n, bool hold_low, int& i, double& f) {
    if (u < 0 && hold_low) u = 0;
    i = std::clamp(static_cast<int>(std::floor(u)), 0, n - 2);
    f = u - i;
  };
  int i, j, k;
  double fx, fy, fz;
  split(x, t::n_re, true, i, fx);
  split(y, t::n_b, true, j, fy);
  split(z, t::n_spread, true, k, fz);
  // Outside [0, 1] in a coordinate (extrapolation above the table): linear in that one.
  const auto weights = [](double f, int m, int n, std::array<int, 4>& idx, std::array<double, 4>& w) {
    if (f > 1 || f < 0) {
      idx = {m, m + 1, m + 1, m + 1};
      w = {1 - f, f, 0, 0};
      return;
    }
    // Catmull-Rom; a missing neighbour at an edge is the linear extrapolation of the two
    // nearest, folded into the weights.
    std::array<double, 4> c = {0.5 * (-f + 2 * f * f - f * f * f), 0.5 * (2 - 5 * f * f + 3 * f * f * f),
                               0.5 * (f + 4 * f * f - 3 * f * f * f), 0.5 * (-f * f + f * f * f)};
    idx = {m - 1, m, m + 1, m + 2};
    w = c;
    if (m - 1 < 0) {  // v(-1) = 2 v(0) - v(1)
      idx[0] = m;
      w[1] += 2 * c[0];
      w[2] -= c[0];
      w[0] = 0;
    }
    if (m + 2 > n - 1) {  // v(n) = 2 v(n-1) - v(n-2)
      idx[3] = m + 1;
      w[2] += 2 * c[3];
      w[1] -= c[3];
      w[3] = 0;
    }
  };
  LatticeStencil st;
  weights(fx, i, t::n_re, st.ix, st.wx);
  weights(fy, j, t::n_b, st.iy, st.wy);
  weights(fz, k, t::n_spread, st.iz, st.wz);
  return st;
}

// Calls f(weight, index) for each point of the stencil with a non-zero weight, the index into
// a [spread][re][b] table.
template <class F>
void for_stencil(const LatticeStencil& st, F&& f) {
  namespace t = lattice_table;
  for (int c = 0; c < 4; ++c) {
    if (st.wz[c] == 0) continue;
    for (int a = 0; a < 4; ++a) {
      if (st.wx[a] == 0) continue;
      for (int e = 0; e < 4; ++e) {
        if (st.wy[e] == 0) continue;
        f(st.wz[c] * st.wx[a] * st.wy[e],
          (static_cast<std::size_t>(st.iz[c]) * t::n_re + st.ix[a]) * t::n_b + st.iy[e]);
      }
    }
  }
}

// The N tables' values at the stencil from S slices ks[] of the diffusionBandwidth tables
// ([smooth][spread][re][b]); a slice -1: the tables without averaging. One pass over the
// stencil for all S; lattice_interpolate is the one slice -1.
template <std::size_t N, std::size_t S>
std::array<std::array<double, N>, S> slice_values(const LatticeStencil& st, const std::array<int, S>& ks,
                                                  const std::array<const double*, N>& plain,
                                                  const std::array<const double*, N>& smoothed) {
  namespace t = lattice_table;
  constexpr std::size_t slice = static_cast<std::size_t>(t::n_spread) * t::n_re * t::n_b;
  std::array<std::array<const double*, N>, S> logs;
  for (std::size_t k = 0; k < S; ++k)
    for (std::size_t m = 0; m < N; ++m)
      logs[k][m] = ks[k] < 0 ? plain[m] : smoothed[m] + static_cast<std::size_t>(ks[k]) * slice;
  std::array<std::array<double, N>, S> lp{};
  for_stencil(st, [&](double w, std::size_t at) {
    for (std::size_t k = 0; k < S; ++k)
      for (std::size_t m = 0; m < N; ++m) lp[k][m] += w * logs[k][m][at];
  });
  for (auto& row : lp)
    for (double& v : row) v = std::exp(v);
  return lp;
}

// Interpolates the tables `logs` (each [spread][re][b] in log) on one stencil: out[m] the
// value of table m.
template <std::size_t N>
std::array<double, N> lattice_interpolate(const LatticeStencil& st,
                                          const std::array<const double*, N>& logs) {
  return slice_values<N, 1>(st, {-1}, logs, logs)[0];
}

// The N tables at sigma/h = g of diffusionBandwidth's averaging, 0 <= g <= 2.25.
//   u = 6 g^2 <= 6: the averaging does floor(u) full steps and one of the rest, so within
//     [j, j + 1] the tables are quadratics in u, interpolated exactly from u = j, j + 1/2, j + 1
//     (slices 2j - 1, 2j, 2j + 1; u = 0 is the table without averaging);
//   1 < g <= 2.25: Catmull-Rom in log over g = 0.75 (from u = 3.375), 1, 1.25, ..., 2.5.
template <std::size_t N>
std::array<double, N> smoothed_values(const LatticeStencil& st, double g,
                                      const std::array<const double*, N>& plain,
                                      const std::array<const double*, N>& smoothed) {
  namespace t = lattice_table;
  static_assert(t::smooth_u_lo == 0.5 && t::smooth_u_per_unit == 2 && t::n_smooth_u == 12);
  static_assert(t::smooth_sigma_lo == 1.25 && t::smooth_sigma_per_unit == 4 && t::n_smooth_sigma == 6);
  const auto at_u = [&](double u) {
    const int j = std::min(static_cast<int>(u), 5);
    const double f = u - j;
    const auto v = slice_values<N, 3>(st, {2 * j - 1, 2 * j, 2 * j + 1}, plain, smoothed);
    const double l0 = (2 * f - 1) * (f - 1), l1 = 4 * f * (1 - f), l2 = f * (2 * f - 1);
    std::array<double, N> out;
    for (std::size_t m = 0; m < N; ++m) out[m] = l0 * v[0][m] + l1 * v[1][m] + l2 * v[2][m];
    return out;
  };
  const double u = 6 * g * g;
  if (u <= 6) return at_u(u);
  // Nodes n = 0..7 at g = 0.75 + n / 4: n = 0 from u = 3.375, n = 1 the slice u = 6, n >= 2
  // the slices 12 + (n - 2).
  const double x = (std::min(g, 2.25) - 0.75) * 4;
  const int i = std::clamp(static_cast<int>(x), 1, 5);
  const double f = x - i;
  const std::array<double, 4> w = {0.5 * (-f + 2 * f * f - f * f * f), 0.5 * (2 - 5 * f * f + 3 * f * f * f),
                                   0.5 * (f + 4 * f * f - 3 * f * f * f), 0.5 * (-f * f + f * f * f)};
  const auto slice_of = [](int n) { return n == 1 ? 11 : 12 + (n - 2); };
  std::array<std::array<double, N>, 4> v;
  if (i == 1) {
    v[0] = at_u(3.375);
    const auto rest = slice_values<N, 3>(st, {slice_of(1), slice_of(2), slice_of(3)}, plain, smoothed);
    for (int a = 1; a < 4; ++a) v[a] = rest[a - 1];
  } else {
    v = slice_values<N, 4>(st, {slice_of(i - 1), slice_of(i), slice_of(i + 1), slice_of(i + 2)}, plain,
                           smoothed);
  }
  std::array<double, N> lp{};
  for (int a = 0; a < 4; ++a)
    for (std::size_t m = 0; m < N; ++m) lp[m] += w[a] * std::log(v[a][m]);
  for (double& value : lp) value = std::exp(value);
  return lp;
}

// Beyond sigma/h = 2.25 the lattice has stopped mattering but for a few per cent: the
// continuous Gaussian form (self_disturbance_factor) for the deposit-read kernel's standard
// deviation sigma_t = sqrt(2 g^2 + 1/6 + 2 s^2) (D twice, the cell's box, the footprint's
// spread; cell units), times the lattice's ratio to it at g = 2.25 raised to (2.25/g)^2 (the
// lattice's excess falls as 1/g^2: 1.9 % at g = 2, 8 % at 1). The factor that multiplies
// the tables' values at g = 2.25.
double continuous_beyond(double re_h, double screening, double spread_over_h, double g,
                         double lattice_at_end) {
  const auto cont = [&](double gg) {
    const double st = std::sqrt(2 * gg * gg + 1.0 / 6 + 2 * spread_over_h * spread_over_h);
    return self_disturbance_table()(re_h * st, screening * st * st) / st;
  };
  const double end = cont(2.25);
  const double ratio = lattice_at_end / end;
  return cont(g) / end * std::pow(ratio, (2.25 / g) * (2.25 / g) - 1);
}

}  // namespace

double lattice_self_disturbance(double re_h, double screening, double spread_over_h,
                                double smoothing_over_h) {
  const LatticeStencil st = lattice_stencil(re_h, screening, spread_over_h);
  const std::array<const double*, 1> plain = {lattice_table::log_phi};
  if (smoothing_over_h <= 0) return lattice_interpolate<1>(st, plain)[0];
  const std::array<const double*, 1> smoothed = {lattice_table::log_phi_smoothed};
  const double phi = smoothed_values<1>(st, smoothing_over_h, plain, smoothed)[0];
  if (smoothing_over_h <= 2.25) return phi;
  return phi * continuous_beyond(re_h, screening, std::min(std::max(spread_over_h, 0.0), 0.5),
                                 smoothing_over_h, phi);
}

namespace {

// The six transverse tables at the stencil, without averaging (g = 0) or with the averaging's
// sigma/h = g, as the symmetric T[i][j].
std::array<std::array<double, 3>, 3> transverse_tables(const LatticeStencil& st, double g) {
  namespace t = lattice_table;
  const std::array<const double*, 6> plain = {t::log_t00, t::log_t01, t::log_t02,
                                              t::log_t11, t::log_t12, t::log_t22};
  const std::array<const double*, 6> smoothed = {t::log_t00_smoothed, t::log_t01_smoothed,
                                                 t::log_t02_smoothed, t::log_t11_smoothed,
                                                 t::log_t12_smoothed, t::log_t22_smoothed};
  const std::array<double, 6> v =
      g > 0 ? smoothed_values<6>(st, g, plain, smoothed) : lattice_interpolate<6>(st, plain);
  return {{{v[0], v[1], v[2]}, {v[1], v[3], v[4]}, {v[2], v[4], v[5]}}};
}

// Beyond sigma/h = 2.25 (transverse_tables holds the values at 2.25 there): the factor that
// continues them by the continuous form (continuous_beyond, joined at the place-averaged
// table's value).
double transverse_beyond(const LatticeStencil& st, double re_h, double screening,
                         double spread_over_h, double g) {
  namespace t = lattice_table;
  const double average = smoothed_values<1>(st, 2.25, {t::log_phi}, {t::log_phi_smoothed})[0];
  return continuous_beyond(re_h, screening, std::min(std::max(spread_over_h, 0.0), 0.5), g, average);
}

}  // namespace

double lattice_self_disturbance(double re_h, double screening, double spread_over_h,
                                const std::array<double, 3>& ax, const std::array<double, 3>& ay,
                                double smoothing_over_h) {
  const LatticeStencil st = lattice_stencil(re_h, screening, spread_over_h);
  const auto tt = transverse_tables(st, smoothing_over_h);
  double phi = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) phi += ax[i] * ay[j] * tt[i][j];
  // The integral is positive; a sum that cancels to within the tables' interpolation error
  // (weights split over cells -1 and +1 with none between) is held at zero.
  phi = std::max(phi, 0.0);
  if (smoothing_over_h <= 2.25) return phi;
  return phi * transverse_beyond(st, re_h, screening, spread_over_h, smoothing_over_h);
}

namespace {

// sum of w * table over the stencil (one [spread][re][b] table, no exponential).
double stencil_sum(const LatticeStencil& st, const double* table) {
  double v = 0;
  for_stencil(st, [&](double w, std::size_t at) { v += w * table[at]; });
  return v;
}

}  // namespace

namespace {

// The cellPoint weights of a point at y (|y_a| <= 1/2, cell units from its cell's centre) on
// the cells at offsets (-1..1)^3, each face's two triangulations averaged: f(offset, weight).
// The tetrahedron (centre, face triangle) of the face the largest |y_a| points to: the
// centre's weight 1 - t (t = 2 |y_a|), each triangle corner's t times its barycentric weight
// on the face, a corner's value the mean of its eight cells.
template <class F>
void cell_point_kernel(const std::array<double, 3>& y, F&& f) {
  int a = 0;
  for (int d = 1; d < 3; ++d)
    if (std::abs(y[d]) > std::abs(y[a])) a = d;
  const double t = 2 * std::abs(y[a]);
  f(std::array<int, 3>{0, 0, 0}, 1 - t);
  if (t == 0) return;
  const int sig = y[a] > 0 ? 1 : -1;
  const int b = (a + 1) % 3, c = (a + 2) % 3;
  const double u = 2 * y[b] / t, v = 2 * y[c] / t;
  for (int diagonal = 0; diagonal < 2; ++diagonal) {
    // The triangle of the split along (-,-)..(+,+) holding (uu, v); the other diagonal is
    // that split mirrored in u.
    const double uu = diagonal ? -u : u;
    struct Corner {
      int su, sv;
      double w;
    };
    const std::array<Corner, 3> tri =
        uu >= v ? std::array<Corner, 3>{{{-1, -1, (1 - uu) / 2}, {1, -1, (uu - v) / 2}, {1, 1, (1 + v) / 2}}}
                : std::array<Corner, 3>{{{-1, -1, (1 - v) / 2}, {-1, 1, (v - uu) / 2}, {1, 1, (1 + uu) / 2}}};
    for (const Corner& k : tri) {
      const int su = diagonal ? -k.su : k.su;
      const double share = t * k.w / 16;
      for (int oa = 0; oa < 2; ++oa)
        for (int ob = 0; ob < 2; ++ob)
          for (int oc = 0; oc < 2; ++oc) {
            std::array<int, 3> o{};
            o[a] = oa * sig;
            o[b] = ob * su;
            o[c] = oc * k.sv;
            f(o, share);
          }
    }
  }
}

}  // namespace

CellPointPassage cell_point_passage(double place_a, double place_b) {
  // Along the passage (y_z from -1/2 to 1/2) every weight is linear between the places where
  // the tetrahedron changes (|y_z| = |place_a|, |place_b|, 0): Simpson's rule on each piece is
  // exact for the weights and for their second moments (cubic).
  std::array<double, 7> cuts = {-0.5, 0.5, 0, place_a, -place_a, place_b, -place_b};
  for (double& c : cuts) c = std::clamp(c, -0.5, 0.5);
  std::sort(cuts.begin(), cuts.end());
  CellPointPassage out{};
  double total = 0, moment = 0;
  const auto add = [&](double yz, double weight) {
    cell_point_kernel({place_a, place_b, yz}, [&](const std::array<int, 3>& o, double w) {
      if (w == 0) return;
      out.rho[o[0] + 1][o[1] + 1] += weight * w;
      total += weight * w;
      moment += weight * w * (o[2] - yz) * (o[2] - yz);
    });
  };
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double lo = cuts[k], hi = cuts[k + 1], len = hi - lo;
    if (len <= 0) continue;
    add(lo, len / 6);
    add(0.5 * (lo + hi), 4 * len / 6);
    add(hi, len / 6);
  }
  out.variance = moment / total;
  return out;
}

CellPointRead cell_point_read(double place_a, double place_b, const std::array<double, 3>& da,
                              const std::array<double, 3>& db, double spread_over_h) {
  const CellPointPassage p =
      cell_point_passage(std::clamp(place_a, -0.5, 0.5), std::clamp(place_b, -0.5, 0.5));
  CellPointRead r{};
  // The cosine series of deposit and read-back across the motion: the weight of
  // cos(a q_a) cos(c q_b).
  for (int ja = -1; ja <= 1; ++ja)
    for (int jb = -1; jb <= 1; ++jb) {
      const double deposit = da[ja + 1] * db[jb + 1];
      if (deposit == 0) continue;
      for (int ra = -1; ra <= 1; ++ra)
        for (int rb = -1; rb <= 1; ++rb)
          r.cosines[std::abs(ra - ja)][std::abs(rb - jb)] += deposit * p.rho[ra + 1][rb + 1];
    }
  // Along the motion: the cell tables' deposit and read-back (a cell each, each widened by
  // the spread s_e) with the variance of the cellPoint pair, 1/12 + s^2 (the deposit) plus
  // the stencil's.
  const double s2 = spread_over_h * spread_over_h;
  r.spread_over_h = std::sqrt(std::max(0.0, 0.5 * (s2 + p.variance - 1.0 / 12)));
  return r;
}

double lattice_self_disturbance_cellpoint(double re_h, double screening, const CellPointRead& r,
                                          double smoothing_over_h) {
  const LatticeStencil st = lattice_stencil(re_h, screening, r.spread_over_h);
  const auto tt = transverse_tables(st, smoothing_over_h);
  // cos(a q) in the basis f_0, f_1, f_2 of the tables: 1 = f_0, cos q = 2 f_1 - f_0,
  // cos 2q = 8 f_2 - 8 f_1 + f_0; the integral with cos(a q_a) cos(c q_b) is
  // sum_ij basis[a][i] basis[c][j] T_ij.
  constexpr double basis[3][3] = {{1, 0, 0}, {-1, 2, 0}, {1, -8, 8}};
  double phi = 0;
  for (int a = 0; a < 3; ++a)
    for (int c = 0; c < 3; ++c) {
      if (r.cosines[a][c] == 0) continue;
      double e = 0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) e += basis[a][i] * basis[c][j] * tt[i][j];
      phi += r.cosines[a][c] * e;
    }
  phi = std::max(phi, 0.0);
  if (smoothing_over_h <= 2.25) return phi;
  return phi * transverse_beyond(st, re_h, screening, r.spread_over_h, smoothing_over_h);
}

double lattice_self_disturbance_cellpoint(double re_h, double screening, double spread_over_h,
                                          double place_a, double place_b,
                                          std::array<double, 3> da, std::array<double, 3> db,
                                          double smoothing_over_h) {
  namespace t = lattice_table;
  if (smoothing_over_h > 0)
    return lattice_self_disturbance_cellpoint(
        re_h, screening, cell_point_read(place_a, place_b, da, db, spread_over_h), smoothing_over_h);
  static_assert(t::cp_n_places == 15 && t::cp_place_per_unit == 8);
  // The cube's symmetries: a place on the negative side mirrors the marginals; the table
  // holds place_a >= place_b.
  if (place_a < 0) {
    place_a = -place_a;
    std::swap(da[0], da[2]);
  }
  if (place_b < 0) {
    place_b = -place_b;
    std::swap(db[0], db[2]);
  }
  place_a = std::min(place_a, 0.5);
  place_b = std::min(place_b, 0.5);
  if (place_a < place_b) {
    std::swap(place_a, place_b);
    std::swap(da, db);
  }
  const LatticeStencil st = lattice_stencil(re_h, screening, spread_over_h);
  // The ratios tend to constants past the table's upper ends: held there.
  static const double top = std::pow(10.0, t::log_re_lo + (t::n_re - 1) / t::log_re_per_decade);
  static const double top_b = std::pow(10.0, t::log_b_lo + (t::n_b - 1) / t::log_b_per_decade);
  const LatticeStencil held =
      lattice_stencil(std::min(re_h, top), std::min(screening, top_b), spread_over_h);
  constexpr std::size_t slice = static_cast<std::size_t>(t::n_spread) * t::n_re * t::n_b;
  const double x = place_a * t::cp_place_per_unit, y = place_b * t::cp_place_per_unit;
  const int i0 = std::min(static_cast<int>(x), 3), j0 = std::min(static_cast<int>(y), 3);
  const double fx = x - i0, fy = y - j0;
  double phi = 0;
  for (int di = 0; di < 2; ++di)
    for (int dj = 0; dj < 2; ++dj) {
      const double w = (di ? fx : 1 - fx) * (dj ? fy : 1 - fy);
      if (w == 0) continue;
      int i = i0 + di, j = j0 + dj;
      // Above the diagonal: the place (j, i) with the transverse axes exchanged.
      const bool transposed = j > i;
      if (transposed) std::swap(i, j);
      const std::size_t place = static_cast<std::size_t>(i * (i + 1) / 2 + j);
      const double u00 = std::exp(stencil_sum(st, t::cp_log_u00 + place * slice));
      double sum = 0;
      int other = 0;  // the ratio tables skip j' = (0, 0)
      for (int k = 0; k < 9; ++k) {
        const int ja = t::cp_offsets[k][0], jb = t::cp_offsets[k][1];
        const double deposit = transposed ? da[jb + 1] * db[ja + 1] : da[ja + 1] * db[jb + 1];
        if (ja == 0 && jb == 0) {
          sum += deposit;
          continue;
        }
        const std::size_t at = (place * 8 + static_cast<std::size_t>(other++)) * slice;
        if (deposit != 0) sum += deposit * stencil_sum(held, t::cp_ratio + at);
      }
      phi += w * u00 * sum;
    }
  // The integral is positive; a sum that cancels to within the interpolation is held at 0.
  return std::max(phi, 0.0);
}

const SelfDisturbanceTable& self_disturbance_table() {
  static const SelfDisturbanceTable table;
  return table;
}

}  // namespace grainflow
