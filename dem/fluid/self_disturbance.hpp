#pragma once
// The velocity a particle's own momentum feedback induces at the particle itself, in an
// unresolved coupled run (the "self-induced velocity"), and the undisturbed slip the drag
// law needs (docs/models/undisturbed-velocity.md).
//
// The coupling spreads the force -F that the particle exerts on the fluid over the mesh
// and reads the fluid back with a kernel of its own; the disturbance it reads is modelled
// as that of a Gaussian-regularised point force in the linearised (Oseen-Brinkman)
// volume-averaged momentum equation,
//     rho_e W.grad u' = -grad p' + mu_e lap u' - beta u' - F g_sigma(x),   div u' = 0,
// with W the undisturbed slip (fluid minus particle velocity), beta the drag coefficient
// per volume of the other particles (Brinkman screening) and g_sigma a Gaussian whose
// variance sigma^2 per axis is that of deposit and read-back kernels together. In Fourier
// space (Oseen 1910; regularised Stokeslets: Cortez 2001, SIAM J. Sci. Comput. 23:1204;
// the regularised self-induced velocity in Euler-Lagrange coupling: Balachandar, Liu &
// Lakhote 2019, J. Comput. Phys. 376:160; Evrard, Denner & van Wachem 2020, J. Comput.
// Phys. X 8:100078) the disturbance at the particle is, along F,
//     u'(0) = -F phi(Re_sigma, b) / (mu_e sigma),
//     phi = 1/(4 pi^2) int_0^inf s^2 exp(-s^2/2) g(A) / (s^2 + b) ds,
//     A = (s^2 + b) / (Re_sigma s),   g(A) = 2 A (1 + A^2) atan(1/A) - 2 A^2,
// Re_sigma = rho_e |W| sigma / mu_e, b = beta sigma^2 / mu_e. Limits: phi(0, 0) =
// sqrt(pi/2) / (3 pi^2) (Stokes), phi -> 1 / (4 pi Re_sigma) as Re_sigma grows (Oseen: the
// force carried off by advection), phi(0, b) = (sqrt(pi/2) - (pi/2) sqrt(b) e^(b/2)
// erfc(sqrt(b/2))) / (3 pi^2) (Brinkman).
//
// That continuous form is the model's continuum reference. The coupling uses its lattice
// form (lattice_self_disturbance below): the same equation discretised as grainFoam
// discretises it, whose response at the scale of a cell differs from the continuous one
// (softer in Stokes flow, and carrying the force off through a whole cell's section at high
// cell Reynolds number).
#include <array>
#include <cmath>
#include <vector>

namespace grainflow {

// Watson's lattice integral (2 pi)^-3 int_[-pi,pi]^3 d^3q / sum_a 4 sin^2(q_a/2) (Watson 1939,
// Q. J. Math. 10:266): the 7-point Laplacian's Green's function at the origin.
inline constexpr double watson_integral = 0.2527310098;

// phi(Re_sigma, b) by Gauss-Legendre quadrature (about 1e-12 relative).
double self_disturbance_factor(double re_sigma, double screening);

// phi on a table in (log Re_sigma, log b), for the particle loops: bicubic (Catmull-Rom) in
// log phi over 10^-5..10^6 in Re_sigma and 10^-10..10^8 in b, 8 points per decade (13 000
// quadratures at construction, about 0.5 s); below the table's ends phi is flat to within
// 1e-5, above them the quadrature is used. Relative error against the quadrature below 2e-4
// for Re_sigma <= 1e4 and b <= 1e6, below 2e-3 up to the table's upper ends
// (tests/dem/fluid/self_disturbance_test.cpp).
class SelfDisturbanceTable {
 public:
  SelfDisturbanceTable();
  double operator()(double re_sigma, double screening) const;

 private:
  double at(int i, int j) const { return log_phi_[static_cast<std::size_t>(i) * nb_ + j]; }
  int nr_, nb_;
  std::vector<double> log_phi_;
};

// The one table of the process, built on first use (thread-safe).
const SelfDisturbanceTable& self_disturbance_table();

// The self-disturbance on the finite-volume lattice grainFoam solves (what the coupling uses):
// a particle moving at the slip W along a mesh axis through fluid at rest, on a uniform cubic
// mesh of cell size h, deposits -F with its footprint weights and reads the velocity back with
// the same weights (sampling cell); averaged over its passage through the cells the
// disturbance it reads, along F, is u' = -F phi_lat / (mu_e h) with
//     phi_lat = (2 pi)^-3 int_BZ A(q_x) A(q_y) P_zz(q)
//               sum_G |g(q_z + 2 pi G)|^2 Re 1 / (Lambda(q) + b + i Re_h (q_z + 2 pi G)) d^3q,
// Lambda = sum_a 4 sin^2(q_a/2) (7-point Laplacian), P_zz = 1 - sin^2 q_z / sum_a sin^2 q_a
// (collocated projection with the Gauss linear pressure gradient), |g(k)|^2 = sinc^2(k/2) /
// (1 + s^2 k^2) the deposit-read autocorrelation of a cell widened by the footprint's spread
// s, A(q) = sum_G |g(q + 2 pi G)|^2, Re_h = rho_e W h / mu_e, b = beta h^2 / mu_e, h = 1.
// The Oseen term is the source moving through fixed cells: each lattice wavenumber q_z is
// forced at the frequencies W (q_z + 2 pi G) of its images. Limits: phi_lat(0, 0, 0) =
// (2/3) Watson's integral; phi_lat -> 1 / (2 Re_h) at s = 0 as Re_h grows (the force
// carried off through one cell's section, read half-way). Tabulated by
// scripts/lattice_self_disturbance.py in lattice_self_disturbance_table.hpp over
// 1e-3 <= Re_h <= 1e4, 1e-6 <= b <= 1e4, 0 <= s/h <= 1/2 and interpolated (tricubic
// Catmull-Rom in log phi, log Re_h, log b, s/h); below the lower ends of Re_h and b it is
// held, above the upper ends extrapolated linearly in log-log (phi ~ 1/Re_h, 1/b). For
// s/h > 1/2 (cells finer than about half the particle) the cell size is taken as 2 s, where
// the lattice's own scale has stopped mattering: u' = -F phi_lat(Re_2s, b_2s, 1/2) / (2 mu_e s).
//
// With diffusionBandwidth (coupling/foam/diffusionSmoothing.H) the deposit and the read-back are
// each averaged by its diffusion, of standard deviation sigma per axis: the integrand gains
// D(q)^2, D the averaging's symbol on the lattice, (1 - Lambda/12)^(k-1) (1 - r Lambda) for
// pseudo-time T = sigma^2/2 (cell units) in k - 1 full steps of 1/12 and one of r. Tabulated
// by scripts/lattice_self_disturbance.py --smoothed in lattice_self_disturbance_smoothed_table.hpp
// for smoothing_over_h = sigma/h up to 2.5 (see smoothed_values in the .cpp for the
// interpolation, exact in sigma up to sigma/h = 1); beyond 2.25 the continuous Gaussian form
// joined to the lattice's. 0: no averaging.
double lattice_self_disturbance(double re_h, double screening, double spread_over_h,
                                double smoothing_over_h = 0);

// The self-disturbance with the particle's actual place across its motion. The footprint's
// weights, summed over the cells of one transverse axis (its marginal W_j on the cells at
// integer offsets j = -1, 0, 1 from the particle's own), stay the same while the particle
// moves along the other axis, and the lattice reads them back exactly: the transverse factor
// of the integrand is |sum_j W_j e^(i q j)|^2 = C0 + C1 cos q + C2 cos 2q (C0 = sum W_j^2,
// C1 = 2 sum W_j W_j+1, C2 = 2 W_-1 W_1) in place of the place-averaged A(q). Written in the
// non-negative basis f_0 = 1, f_1 = (1 + cos q)/2, f_2 = f_1^2 (one cell; half and half over
// two; 1/4, 1/2, 1/4 over three) as a_0 f_0 + a_1 f_1 + a_2 f_2 with
//     a_0 = C0 - C1 + C2,   a_1 = 2 C1 - 8 C2,   a_2 = 8 C2,
// the disturbance is phi_lat = sum_ij a_i(x) a_j(y) T_ij(Re_h, b, s/h), each T_ij the integral
// above with f_i(q_x) f_j(q_y) for A(q_x) A(q_y) (the passage average along the motion, with
// the spread s, stays). The six T_ij are tabulated with phi_lat (same axes, same
// interpolation). Averaged over places the a_i give back the place-averaged phi_lat
// (scripts/lattice_self_disturbance.py checks it).
inline std::array<double, 3> transverse_coefficients(double w_minus, double w_0, double w_plus) {
  const double c0 = w_minus * w_minus + w_0 * w_0 + w_plus * w_plus;
  const double c1 = 2 * (w_minus * w_0 + w_0 * w_plus);
  const double c2 = 2 * w_minus * w_plus;
  return {c0 - c1 + c2, 2 * c1 - 8 * c2, 8 * c2};
}

// phi_lat with the transverse coefficients ax, ay (transverse_coefficients) of the two axes
// across the motion.
double lattice_self_disturbance(double re_h, double screening, double spread_over_h,
                                const std::array<double, 3>& ax, const std::array<double, 3>& ay,
                                double smoothing_over_h = 0);

// The self-disturbance read through OpenFOAM's cellPoint interpolation (sampling cellPoint).
// The particle deposits with its footprint as above but reads the velocity at its centre: the
// cell value and three point values of the tetrahedron (cell centre, face triangle) holding
// it, each point value the mean of its eight cells. On a uniform cubic mesh that puts on the
// cell whose centre lies at z from the particle a continuous, piecewise-linear weight R(z),
// not separable per axis. With the particle's place (place_a, place_b) across its motion (its
// offset from its cell's centre in cells, |place| <= 1/2) fixed during the passage and the
// footprint's marginals da, db on the transverse cells -1, 0, 1 (weights, sum 1),
//     phi = sum_j' da[j'_a] db[j'_b] U_j'(Re_h, b, s/h; place),
//     U_j' = (2 pi)^-3 int_BZ sum_j cos(q_perp . (j - j')) P_zz(q)
//            sum_G rho_j^(k) g_d(k) Re 1/(Lambda(q) + b + i Re_h k) d^3q,
// rho_j^ the Fourier transform along the motion of the read-back's weight on the transverse
// cell j (the two diagonals of each face averaged: the cube's symmetries), g_d(k) = sinc(k/2)
// / (1 + s^2 k^2 / 2) the deposit's box widened by the footprint's spread (only the deposit
// is spread now). Tabulated by scripts/lattice_self_disturbance_cellpoint.py (checked against
// direct lattice sums, 4.4e-4, and the Oseen limit Re_h U_j' -> <rho_j'>/2) over the axes of
// the cell tables and the place on a grid of 1/8 (y_a >= y_b >= 0, the rest by symmetry):
// log U_00 and the ratios U_j'/U_00 (which change sign), tricubic in (Re_h, b, s/h) as the
// cell tables (the ratios held at the ends), bilinear in the place.
//
// With diffusionBandwidth (smoothing_over_h = sigma/h > 0) the integrand gains D(q)^2 as for
// the cell tables, and the read-back is modelled as the cell tables model theirs: across the
// motion exactly, by the stencil's passage-averaged weights rho_j on the transverse columns
// (cell_point_passage) against the deposit's marginals, phi = sum_ac C_ac E_ac with C_ac the
// weight of cos(a q_a) cos(c q_b) in sum_j'j da db rho_j cos(q.(j - j')) and E_ac the
// lattice integral with that cosine, from the six smoothed T_ij; along the motion by a cell's
// box on either side, each widened by the spread s_e whose variance makes the pair's
// 1/6 + 2 s_e^2 that of the cellPoint pair, 1/12 + s^2 (the deposit) + V_R (the stencil's
// variance along the motion). The averaging damps the difference in shape that remains:
// against the exact integral with the stencil's own profile within 0.5 % from sigma/h = 1,
// 1.6 % at 0.67, 3.7 % at 0.4 and 6.5 % at 0.2 (direct lattice sums, unit tests; scripts/
// lattice_self_disturbance_cellpoint.py --smoothed-check for Re_h, b and s). At sigma = 0
// the exact form above is used.
double lattice_self_disturbance_cellpoint(double re_h, double screening, double spread_over_h,
                                          double place_a, double place_b,
                                          std::array<double, 3> da, std::array<double, 3> db,
                                          double smoothing_over_h = 0);

// The cellPoint stencil of a particle at (place_a, place_b) across its motion (cell units
// from its cell's centre), averaged over its passage along the motion through one cell: the
// weight rho[ja + 1][jb + 1] on the transverse column at offset (ja, jb) (sum 1), and the
// variance along the motion of the read cells' distance from the particle (1/6 at the
// centre: the tent of the cell value between the two face centres).
struct CellPointPassage {
  double rho[3][3];
  double variance;
};
CellPointPassage cell_point_passage(double place_a, double place_b);

// What the diffusionBandwidth model of the cellPoint read takes from the particle's place and
// marginals (fixed between two samplings): the weights of cos(a q_a) cos(c q_b) in the
// transverse factor, and the spread s_e/h along the motion.
struct CellPointRead {
  double cosines[3][3];
  double spread_over_h;
};
CellPointRead cell_point_read(double place_a, double place_b, const std::array<double, 3>& da,
                              const std::array<double, 3>& db, double spread_over_h);
// lattice_self_disturbance_cellpoint with diffusionBandwidth, from the read's geometry.
double lattice_self_disturbance_cellpoint(double re_h, double screening, const CellPointRead& r,
                                          double smoothing_over_h);

// The mobility m = u' / F [s/kg] of a particle's self-disturbance on cells of size h [m]
// with footprint spread s [m], at slip w [m/s], for the momentum equation with density rho_e,
// viscosity mu_e and Brinkman coefficient beta [kg/m^3/s]. ax, ay: the transverse
// coefficients of the particle's place across its motion; null: the place-averaged factor
// (also used where s > h/2 and the cell size is taken as 2 s). sigma [m]: diffusionBandwidth's
// standard deviation per axis (b / sqrt 2), 0 for none.
inline double lattice_self_mobility(double h, double s, double w, double rho_e, double mu_e,
                                    double beta, const std::array<double, 3>* ax = nullptr,
                                    const std::array<double, 3>* ay = nullptr, double sigma = 0) {
  const double l = 2 * s > h ? 2 * s : h;
  const double re = rho_e * w * l / mu_e, b = beta * l * l / mu_e;
  const double phi = ax && ay && l == h ? lattice_self_disturbance(re, b, s / l, *ax, *ay, sigma / l)
                                        : lattice_self_disturbance(re, b, s / l, sigma / l);
  return phi / (mu_e * l);
}

// lattice_self_mobility for sampling cellPoint: the place and the footprint's marginals on the
// two transverse axes; sigma [m] as for lattice_self_mobility. Where the footprint's spread
// exceeds half a cell (2 s > h) the cell size is taken as 2 s and the place-averaged cell
// factor is used, as for sampling cell.
inline double lattice_self_mobility_cellpoint(double h, double s, double w, double rho_e,
                                              double mu_e, double beta, double place_a,
                                              double place_b, const std::array<double, 3>& da,
                                              const std::array<double, 3>& db, double sigma = 0) {
  if (2 * s > h) return lattice_self_mobility(h, s, w, rho_e, mu_e, beta, nullptr, nullptr, sigma);
  const double re = rho_e * w * h / mu_e, b = beta * h * h / mu_e;
  return lattice_self_disturbance_cellpoint(re, b, s / h, place_a, place_b, da, db, sigma / h) /
         (mu_e * h);
}

// lattice_self_mobility_cellpoint with diffusionBandwidth (sigma > 0 [m]) from the read's
// geometry (cell_point_read with s/h), computed once per sampling.
inline double lattice_self_mobility_cellpoint(double h, double s, double w, double rho_e,
                                              double mu_e, double beta, const CellPointRead& r,
                                              double sigma) {
  if (2 * s > h) return lattice_self_mobility(h, s, w, rho_e, mu_e, beta, nullptr, nullptr, sigma);
  const double re = rho_e * w * h / mu_e, b = beta * h * h / mu_e;
  return lattice_self_disturbance_cellpoint(re, b, r, sigma / h) / (mu_e * h);
}

// The undisturbed slip for drag: given the slip the particle sees (sampled fluid minus
// particle velocity, |w_seen|), the drag coefficient law k(|w|) [kg/s] and the disturbance
// mobility m(|w|) = phi / (mu_e sigma) [s/kg], solves |w| = |w_seen| / (1 - k(|w|) m(|w|))
// by fixed-point iteration. Returns the factor 1 / (1 - k m) (>= 1) by which the drag on
// the seen slip must grow; `limited` is set when k m reached `max_km` and was held there.
template <class K, class M>
double undisturbed_factor(double w_seen, K&& k, M&& m, double max_km, bool& limited) {
  double w = w_seen, factor = 1;
  limited = false;
  for (int it = 0; it < 30; ++it) {
    double km = k(w) * m(w);
    if (km > max_km) {
      km = max_km;
      limited = true;
    } else {
      limited = false;
    }
    const double next = 1 / (1 - km);
    const bool done = std::abs(next - factor) <= 1e-12 * next;
    factor = next;
    w = w_seen * factor;
    if (done) break;
  }
  return factor;
}

}  // namespace grainflow
