#!/usr/bin/env python3
"""Tabulates the self-disturbance of a particle on the finite-volume lattice grainFoam solves,
and writes dem/fluid/lattice_self_disturbance_table.hpp (docs/models/undisturbed-velocity.md).

A particle moving at the slip W along a mesh axis through fluid at rest on a uniform cubic mesh
of cell size h deposits -F on the cells with its footprint weights and reads the velocity back
with the same weights (`sampling cell`). In cell units (h = 1, mu_e = 1, F = 1) the part of the
disturbance at the particle along F, averaged over the particle's passage through the cells, is

    phi = (2 pi)^-3 int_BZ A(q_x) A(q_y) P_zz(q) Z(q) d^3q,
    Z(q) = sum_G |g(q_z + 2 pi G)|^2 Re 1 / (Lambda(q) + b + i Re_h (q_z + 2 pi G)),

with
  Lambda(q) = sum_a 4 sin^2(q_a / 2)        the 7-point Laplacian (Gauss linear corrected),
  P_zz = 1 - sin^2 q_z / sum_a sin^2 q_a    the collocated projection: the cell-centred pressure
                                            gradient (Gauss linear) has the symbol i sin q_a;
                                            Rhie-Chow's compact pressure Laplacian differs from
                                            it by a term of order (viscous / (1/dt)) that the
                                            small fluid steps of a coupled run make small,
  |g(k)|^2 = sinc^2(k/2) / (1 + s^2 k^2)    the deposit-read autocorrelation along an axis: the
                                            cell (a box of width 1) convolved with the footprint's
                                            own spread, an autocorrelation e^(-|x|/s)/(2s) of
                                            variance 2 s^2, s^2 the footprint points' variance
                                            per axis,
  A(q) = sum_G |g(q + 2 pi G)|^2            the transverse axes (the particle's position across
                                            the cells averaged),
  Re_h = rho_e W h / mu_e,  b = beta h^2 / mu_e.

The Oseen term is the time derivative of a source that moves through fixed cells, not the
convection scheme: linearised about fluid at rest the convection term vanishes, and the source
moving at W has, for every lattice wavenumber q_z, the frequencies W (q_z + 2 pi G) of its
images; their response is summed (Poisson summation), hence the continuous wavenumber in the
Oseen term and the periodic Lambda and P. The sums over G have closed forms
(sum_G 1/((q + 2 pi G)^2 + c^2) = sinh c / (2 c (cosh c - cos q))), the Brillouin-zone
integral is done by Gauss-Legendre quadrature (graded panels towards q = 0; along q_z a tangent
substitution that resolves the Oseen wake's Lorentzian of width (Lambda + b)/Re_h).
With the particle's own place across its motion (its footprint's weight marginal W_j on the
cells j = -1, 0, 1 of a transverse axis, constant over the passage) A(q) becomes
|sum_j W_j e^(i q j)|^2 = a_0 f_0 + a_1 f_1 + a_2 f_2 (basis(), coefficients()); the six
tables T_ij, f_i(q_x) f_j(q_y) in place of A(q_x) A(q_y), are computed in the same pass.

Checks printed first: phi(0, 0, 0) = T_00(0, 0, 0) = (2/3) Watson's integral (Watson 1939),
phi -> 1/(2 Re_h) for large Re_h at s = 0 (the force carried off by the fluid crossing one
cell's section, read half-way), the T_ij at Re_h = 0, s = 0 against direct lattice sums, the
place average of the T_ij against phi, and the quadrature against a finer one.

With diffusionBandwidth (coupling/foam/diffusionSmoothing.H) the deposit and the read-back are
each averaged by the diffusion, whose symbol on the lattice is D(q) (smoothing_symbol()): the
integrand gains D(q)^2. `--smoothed` writes those tables for sigma/h up to 2.5 into
dem/fluid/lattice_self_disturbance_smoothed_table.hpp (checked first against direct lattice
sums with D^2 and a finer quadrature).

Usage: scripts/python.sh scripts/lattice_self_disturbance.py [--out PATH] [--check-only]
(about 7 minutes on one core); ... --smoothed [--smoothed-out PATH] (about 5 minutes).
"""
import argparse
import os
import sys
import time

import numpy as np
from numpy.polynomial.legendre import leggauss

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "..", "dem", "fluid", "lattice_self_disturbance_table.hpp")

# The table's axes (also written into the header).
LOG_RE = (-3.0, 4.0, 3)     # log10 Re_h from, to, points per decade
LOG_B = (-6.0, 4.0, 1.5)    # log10 b
SPREAD = (0.0, 0.5, 8)      # s/h from, to, points per unit
# diffusionBandwidth (sigma = b / sqrt 2 per axis): up to sigma/h = 1, the axis u = 12 T = 6 (sigma/h)^2
# at half-integers (within u in [j, j + 1] the averaging does j full steps and one of (u - j)/12,
# so phi is a quadratic in u there: interpolated exactly from u = j, j + 1/2, j + 1); beyond,
# sigma/h in quarters (smooth: cubic in log phi).
SMOOTH_U = (0.5, 6.0, 2)      # u from, to, points per unit
SMOOTH_SIGMA = (1.25, 2.5, 4)  # sigma/h from, to, points per unit
SMOOTHED_OUT = os.path.join(HERE, "..", "dem", "fluid", "lattice_self_disturbance_smoothed_table.hpp")


# The transverse tables: pairs (i, j), i <= j, of the basis functions (basis()).
PAIRS = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)]


def basis(q):
    """f_0 = 1 (one cell), f_1 = (1 + cos q)/2 (half and half over two cells), f_2 = f_1^2
    (1/4, 1/2, 1/4 over three cells): |sum_j W_j e^(i q j)|^2 of a footprint whose marginal
    weights W_j span at most three cells is a_0 f_0 + a_1 f_1 + a_2 f_2 (coefficients()); all
    three are non-negative, so every T_ij is, and is interpolated in log."""
    c = (1 + np.cos(q)) / 2
    return [np.ones_like(q), c, c * c]


def coefficients(w):
    """a_0, a_1, a_2 of the marginal weights (W_-1, W_0, W_1), sum 1: with C0 = sum W_j^2,
    C1 = 2 sum W_j W_j+1, C2 = 2 W_-1 W_1, |.|^2 = C0 + C1 cos q + C2 cos 2q."""
    wm, w0, wp = w
    c0 = wm * wm + w0 * w0 + wp * wp
    c1 = 2 * (wm * w0 + w0 * wp)
    c2 = 2 * wm * wp
    return np.array([c0 - c1 + c2, 2 * c1 - 8 * c2, 8 * c2])


def smoothing_symbol(sigma, lam):
    """The symbol of grainFoam's diffusion-based averaging (coupling/foam/diffusionSmoothing.C)
    on a uniform cubic mesh of cell 1: pseudo-time T = sigma^2 / 2 in steps of the largest
    stable size 1/12 (a cell gives away half its value) and one last step of the remainder,
    D = (1 - lam/12)^(k-1) (1 - r lam), k = ceil(12 T), r = T - (k-1)/12; lam the 7-point
    Laplacian's symbol. Continuous in sigma; on long runs of steps it tends to exp(-T lam)."""
    if sigma == 0:
        return 1.0
    t = 0.5 * sigma * sigma
    k = max(1, int(np.ceil(12 * t - 1e-9)))
    return (1 - lam / 12) ** (k - 1) * (1 - (t - (k - 1) / 12) * lam)


def T(c, q):
    """1 - 4 sin^2(q/2) sum_G 1/((q + 2 pi G)^2 + c^2), stable for every c > 0."""
    c, q = np.broadcast_arrays(np.asarray(c, float), np.asarray(q, float))
    sn2 = np.sin(q / 2) ** 2
    out = np.empty(c.shape)
    lo, hi = c < 0.1, c > 20
    mid = ~lo & ~hi
    for m in (lo, mid):
        cm, s2 = c[m], sn2[m]
        sh2 = np.sinh(cm / 2) ** 2
        ex = cm**2 / 6 + cm**4 / 120 + cm**6 / 5040 if m is lo else (np.sinh(cm) - cm) / cm
        out[m] = (sh2 - s2 * ex) / (sh2 + s2)
    cm, s2 = c[hi], sn2[hi]
    e = np.exp(-cm)
    ish2 = 4 * e / (1 - e) ** 2
    coth = (1 + e) / (1 - e)
    out[hi] = (1 - s2 * (2 * coth - cm * ish2) / cm) / (1 + s2 * ish2)
    return out


def Z(a, re, s, qz):
    """sum_G sinc^2(k/2) / (1 + s^2 k^2) Re 1/(a + i re k), k = qz + 2 pi G."""
    if re == 0:
        return (T(1 / s, qz) if s > 0 else 1.0) / a
    c = a / re
    if s == 0:
        return T(c, qz) / a
    # Partial fractions in k^2: a divided difference of F(c) = T(c)/c^2 in y = 1/c^2.
    y1 = s * s
    y = 1 / c**2
    y = np.where(np.abs(y - y1) < 1e-4 * y1, y1 * (1 + 1e-3), y)
    cc = 1 / np.sqrt(y)
    return (T(cc, qz) / cc**2 - T(1 / s, qz) * y1) / (y - y1) / a


class Quadrature:
    def __init__(self, nt=12, nz=32, panels=8, sigmas=(0.0,)):
        self.sigmas = sigmas
        x, w = leggauss(nt)
        edges = np.concatenate([[0], np.pi * np.logspace(-5, 0, panels)])
        q = np.concatenate([0.5 * (hi + lo) + 0.5 * (hi - lo) * x for lo, hi in zip(edges[:-1], edges[1:])])
        wq = np.concatenate([0.5 * (hi - lo) * w for lo, hi in zip(edges[:-1], edges[1:])])
        i, j = np.triu_indices(len(q))  # q_x <= q_y: the integrand is symmetric in them
        self.qx, self.qy = q[i], q[j]
        self.w = wq[i] * wq[j] * np.where(i == j, 1.0, 2.0)
        self.lp = 4 * np.sin(self.qx / 2) ** 2 + 4 * np.sin(self.qy / 2) ** 2
        self.sp = np.sin(self.qx) ** 2 + np.sin(self.qy) ** 2
        self.xz, self.wz = leggauss(nz)
        # The transverse basis f_0 = 1, f_1 = (1 + cos q)/2, f_2 = (1 + cos q)^2/4 on q_x, q_y;
        # on the triangle q_x <= q_y the pair's weight is symmetrised (the rest of the
        # integrand is symmetric in q_x, q_y).
        fx = basis(self.qx)
        fy = basis(self.qy)
        self.wij = [0.5 * (fx[i] * fy[j] + fx[j] * fy[i]) * self.w for i, j in PAIRS]

    def phi(self, re, b, s):
        """The place-averaged phi (A(q_x) A(q_y)) and the six transverse tables T_ij, i <= j;
        with several smoothing widths (sigmas), an array [sigma][7]."""
        ap = (T(1 / s, self.qx) * T(1 / s, self.qy)) if s > 0 else 1.0
        rows = []
        for inner in self._inner(re, b, s):
            out = [float((ap * inner * self.w).sum())]
            out += [float((wij * inner).sum()) for wij in self.wij]
            rows.append(8 * np.array(out) / (2 * np.pi) ** 3)
        return rows[0] if len(rows) == 1 else np.array(rows)

    def _inner(self, re, b, s):
        a0 = self.lp + b
        w0 = np.sqrt(a0)
        if re > 0:
            w0 = np.minimum(w0, a0 / re)
        w0 = np.maximum(w0, 1e-14)[:, None]
        top = np.arctan(np.pi / w0)
        th = 0.5 * top * (1 + self.xz[None, :])
        qz = w0 * np.tan(th)
        wq = 0.5 * top * self.wz[None, :] * w0 / np.cos(th) ** 2
        lam = self.lp[:, None] + 4 * np.sin(qz / 2) ** 2
        p = 1 - np.sin(qz) ** 2 / (self.sp[:, None] + np.sin(qz) ** 2)
        # diffusionBandwidth: the deposit and the read-back are each averaged once (D^2).
        base = p * Z(lam + b, re, s, qz) * wq
        return [(base * smoothing_symbol(sg, lam) ** 2).sum(axis=1) for sg in self.sigmas]


def axis(spec, log):
    lo, hi, per = spec
    n = int(round((hi - lo) * per)) + 1
    return lo + np.arange(n) / per


def lattice_sum(n, b, sigma=0.0):
    """T_ij(Re_h = 0, b, s = 0) as the lattice Green's function at the origin on a periodic
    lattice of n^3 cells, by a direct sum over its n^3 wavenumbers (the zero mode left out):
    (1/n^3) sum_q f_i(q_x) f_j(q_y) P_zz(q) / (Lambda(q) + b). Independent of the quadrature;
    at s = 0 and Re_h = 0 the passage average along the motion is 1 (sum_G sinc^2 = 1)."""
    q = 2 * np.pi * np.arange(n) / n
    qx, qy, qz = np.meshgrid(q, q, q, indexing="ij", sparse=True)
    lam = 4 * np.sin(qx / 2) ** 2 + 4 * np.sin(qy / 2) ** 2 + 4 * np.sin(qz / 2) ** 2 + b
    ss = np.sin(qx) ** 2 + np.sin(qy) ** 2 + np.sin(qz) ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        p = np.where(ss > 0, 1 - np.sin(qz) ** 2 / np.where(ss > 0, ss, 1), 1.0)
        g = np.where(lam > 0, p / np.where(lam > 0, lam, 1), 0.0)
    g = g * smoothing_symbol(sigma, lam - b) ** 2
    fx, fy = basis(qx), basis(qy)
    out = []
    for i, j in PAIRS:
        out.append(float((0.5 * (fx[i] * fy[j] + fx[j] * fy[i]) * g).sum()) / n**3)
    return np.array(out)


def against_finer(quad, fine, spreads):
    """The largest relative difference of every tabulated value against a finer quadrature."""
    worst = 0
    for re in (0, 0.3, 3, 30, 300):
        for b in (0, 1e-3, 1, 100):
            for s in spreads:
                worst = max(worst, np.abs(quad.phi(re, b, s) / fine.phi(re, b, s) - 1).max())
    return worst


def checks(quad):
    fine = Quadrature(24, 64, 12)
    watson = 0.2527310098
    ok = True
    v = quad.phi(0, 0, 0)
    print(f"phi(0,0,0) = {v[0]:.7f}, T_00(0,0,0) = {v[1]:.7f}, (2/3) Watson = {2 * watson / 3:.7f}")
    ok &= abs(v[0] / (2 * watson / 3) - 1) < 2e-4 and abs(v[1] / (2 * watson / 3) - 1) < 2e-4
    v = quad.phi(1e5, 0, 0)
    print(f"Re_h phi(1e5,0,0) = {1e5 * v[0]:.5f}, Re_h T_00 = {1e5 * v[1]:.5f}, expected 1/2")
    ok &= abs(2e5 * v[0] - 1) < 2e-3 and abs(2e5 * v[1] - 1) < 2e-3
    # The transverse tables against direct lattice sums (Richardson over n = 64, 128 for the
    # 1/n error of the left-out zero mode at b = 0; at b = 1 the sum has converged).
    for b in (0.0, 1.0):
        q = quad.phi(0, b, 0)[1:]
        s1, s2 = lattice_sum(64, b), lattice_sum(128, b)
        ref = 2 * s2 - s1 if b == 0 else s2
        dev = np.abs(q / ref - 1)
        print(f"T_ij(0, {b:g}, 0) quadrature " + " ".join(f"{x:.6f}" for x in q))
        print(f"               lattice sum " + " ".join(f"{x:.6f}" for x in ref)
              + f"  largest relative difference {dev.max():.1e}")
        ok &= dev.max() < 1e-3
    # The place-averaged factor (today's A(q_x) A(q_y), phi[0]) from the transverse tables:
    # a footprint whose points are spread along each axis as e^(-x/s)/s (x > 0) has the
    # autocorrelation e^(-|x|/s)/(2s) that A(q) assumes; its marginal weights over the cells,
    # (W_-1, W_0, W_1) = (0, 1 - e^(-(1/2 - u)/s), e^(-(1/2 - u)/s)) for a centre at u in
    # its cell (weights beyond the neighbour, a share s (e^(-1/s) - e^(-2/s)) of the average,
    # lumped into it), averaged over u, give phi = sum_ij a_i a_j T_ij.
    u = (np.arange(2000) + 0.5) / 2000 - 0.5
    for s in (0.125, 0.1875, 0.25):
        e = np.exp(-(0.5 - u) / s)
        a = np.mean([coefficients((0.0, 1 - x, x)) for x in e], axis=0)
        worst = 0
        for re, b in ((0, 0), (0.3, 1e-3), (4, 0), (30, 1)):
            v = quad.phi(re, b, s)
            t = {pair: v[1 + k] for k, pair in enumerate(PAIRS)}
            tot = sum(a[i] * a[j] * t[(min(i, j), max(i, j))] for i in range(3) for j in range(3))
            worst = max(worst, abs(tot / v[0] - 1))
        tail = s * (np.exp(-1 / s) - np.exp(-2 / s))
        print(f"place average, s/h = {s}: sum a_i a_j T_ij against phi: largest relative "
              f"difference {worst:.1e} (lumped share {tail:.1e})")
        # Lumping a share x of the weight one cell inwards changes phi by about 3 x (printed
        # for s/h = 1/4, where the share is 4.5e-3); required where it is below 1e-3.
        if tail < 1e-3:
            ok &= worst < 2e-3 + 3 * tail
    worst = against_finer(quad, fine, (0, 0.15, 0.6))
    print(f"quadrature against a finer one: largest relative difference {worst:.1e}")
    return ok and worst < 1e-3


def smoothed_checks():
    """diffusionBandwidth: the T_ij at Re_h = 0, s = 0 against direct lattice sums with D^2,
    the quadrature against a finer one, and (printed) the continuous Gaussian limit: a
    deposit-read kernel of variance 2 sigma^2 + 1/6 (D twice and the cell's box) gives
    phi = (1/(3 pi)) sqrt(2/pi) ... = 0.0423142 / sigma_total at Re = 0, b = 0."""
    sig = (0.5, 1.0, 2.0)
    quad = Quadrature(sigmas=sig)
    fine = Quadrature(24, 64, 12, sigmas=sig)
    ok = True
    for b in (0.0, 1.0):
        v = quad.phi(0, b, 0)
        for k, sg in enumerate(sig):
            s1, s2 = lattice_sum(64, b, sg), lattice_sum(128, b, sg)
            ref = 2 * s2 - s1 if b == 0 else s2
            dev = np.abs(v[k][1:] / ref - 1).max()
            print(f"sigma/h = {sg}, b = {b:g}: T_ij against lattice sums, largest relative "
                  f"difference {dev:.1e}")
            ok &= dev < 1e-3
    for sg, row in zip(sig, quad.phi(0, 0, 0)):
        cont = 0.0423142 / np.sqrt(2 * sg * sg + 1 / 6)
        print(f"sigma/h = {sg}: phi(0, 0, 0) = {row[0]:.5f}, continuous Gaussian {cont:.5f} "
              f"(lattice / continuous {row[0] / cont:.4f})")
    worst = against_finer(quad, fine, (0, 0.15, 0.5))
    print(f"smoothed: quadrature against a finer one: largest relative difference {worst:.1e}")
    return ok and worst < 1e-3


def write_header(path, names, notes, table, axes, comment, order, digits=7):
    lines = ["#pragma once"] + comment + ["namespace grainflow::lattice_table {"] + axes
    for name, note, t in zip(names, notes, table):
        lines += [f"// {note}; {order}", f"inline constexpr double {name}[] = {{"]
        flat = t.ravel()
        for k in range(0, len(flat), 6):
            lines.append("    " + ", ".join(f"{v:.{digits}e}" for v in flat[k:k + 6]) + ",")
        lines += ["};"]
    lines += ["}  // namespace grainflow::lattice_table", ""]
    with open(path, "w") as f:
        f.write("\n".join(lines))


# The tables' names and comments (the smoothed ones add "_smoothed").
NAMES = ["log_phi"] + [f"log_t{i}{j}" for i, j in PAIRS]
NOTES = ["the place-averaged factor, A(q_x) A(q_y)"] + [
    f"T_{i}{j}: f_{i}(q_x) f_{j}(q_y) (symmetric in i, j)" for i, j in PAIRS]


def tabulate(quad):
    """log phi and the log T_ij over the axes: [table][spread][re][b], or with several
    smoothing widths [table][sigma][spread][re][b]."""
    lr, lb, sp = axis(LOG_RE, True), axis(LOG_B, True), axis(SPREAD, False)
    t0 = time.time()
    slabs = []
    for s in sp:
        slabs.append([[np.log(quad.phi(10**r, 10**b, s)) for b in lb] for r in lr])
        print(f"s/h = {s:.2f} done ({time.time() - t0:.0f} s)", flush=True)
    table = np.moveaxis(np.array(slabs), -1, 0)
    return np.moveaxis(table, 4, 1) if table.ndim == 5 else table


def main_smoothed(a):
    if not a.skip_checks and not smoothed_checks():
        sys.exit("lattice_self_disturbance: a smoothed check failed")
    if a.check_only:
        return
    sg = np.concatenate([np.sqrt(axis(SMOOTH_U, False) / 6), axis(SMOOTH_SIGMA, False)])
    t0 = time.time()
    table = tabulate(Quadrature(sigmas=tuple(sg)))
    write_header(
        a.smoothed_out, [n + "_smoothed" for n in NAMES], NOTES, table,
        [f"inline constexpr double smooth_u_lo = {SMOOTH_U[0]!r}, smooth_u_per_unit = {SMOOTH_U[2]!r};",
         f"inline constexpr int n_smooth_u = {len(axis(SMOOTH_U, False))};",
         f"inline constexpr double smooth_sigma_lo = {SMOOTH_SIGMA[0]!r}, "
         f"smooth_sigma_per_unit = {SMOOTH_SIGMA[2]!r};",
         f"inline constexpr int n_smooth_sigma = {len(axis(SMOOTH_SIGMA, False))};",
         f"inline constexpr int n_smooth = {len(sg)};"],
        ["// Generated by scripts/lattice_self_disturbance.py --smoothed: do not edit. The tables",
         "// of lattice_self_disturbance_table.hpp with diffusionBandwidth's averaging of the",
         "// deposit and of the read-back. Slices: first u = 6 (sigma/h)^2 = smooth_u_lo + i /",
         "// smooth_u_per_unit (n_smooth_u), then sigma/h = smooth_sigma_lo + i /",
         "// smooth_sigma_per_unit (n_smooth_sigma); the axes of Re_h, b and s/h are those of",
         "// lattice_self_disturbance_table.hpp."],
        "[smooth][spread][re][b]")
    print(f"wrote {a.smoothed_out}: {table.size} values in {time.time() - t0:.0f} s")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=OUT)
    ap.add_argument("--smoothed", action="store_true",
                    help="write the tables with diffusionBandwidth's averaging instead")
    ap.add_argument("--smoothed-out", default=SMOOTHED_OUT)
    ap.add_argument("--check-only", action="store_true")
    ap.add_argument("--skip-checks", action="store_true")
    a = ap.parse_args()
    if a.smoothed:
        return main_smoothed(a)
    quad = Quadrature()
    if not a.skip_checks and not checks(quad):
        sys.exit("lattice_self_disturbance: a check failed")
    if a.check_only:
        return
    lr, lb, sp = axis(LOG_RE, True), axis(LOG_B, True), axis(SPREAD, False)
    t0 = time.time()
    table = tabulate(quad)
    write_header(
        a.out, NAMES, NOTES, table,
        [f"inline constexpr double log_re_lo = {LOG_RE[0]!r}, log_re_per_decade = {LOG_RE[2]!r};",
         f"inline constexpr double log_b_lo = {LOG_B[0]!r}, log_b_per_decade = {LOG_B[2]!r};",
         f"inline constexpr double spread_lo = {SPREAD[0]!r}, spread_per_unit = {SPREAD[2]!r};",
         f"inline constexpr int n_spread = {len(sp)}, n_re = {len(lr)}, n_b = {len(lb)};"],
        ["// Generated by scripts/lattice_self_disturbance.py: do not edit. log phi_lat(Re_h, b, s/h),",
         "// the particle's self-disturbance on the finite-volume lattice (self_disturbance.hpp)."],
        "[spread][re][b]", digits=10)
    print(f"wrote {a.out}: {table.size} values in {time.time() - t0:.0f} s")

if __name__ == "__main__":
    main()
