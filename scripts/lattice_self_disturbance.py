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
Checks printed at the end: phi(0, 0, 0) = (2/3) Watson's integral (Watson 1939), phi -> 1/(2 Re_h)
for large Re_h at s = 0 (the force carried off by the fluid crossing one cell's section, read
half-way), and the quadrature against a finer one.

Usage: scripts/python.sh scripts/lattice_self_disturbance.py [--out PATH] [--check-only]
(about 20 minutes on one core).
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
    def __init__(self, nt=12, nz=32, panels=8):
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

    def phi(self, re, b, s):
        ap = (T(1 / s, self.qx) * T(1 / s, self.qy)) if s > 0 else 1.0
        a0 = self.lp + b
        w0 = np.sqrt(a0)
        if re > 0:
            w0 = np.minimum(w0, a0 / re)
        w0 = np.maximum(w0, 1e-14)[:, None]
        top = np.arctan(np.pi / w0)
        th = 0.5 * top * (1 + self.xz[None, :])
        qz = w0 * np.tan(th)
        wq = 0.5 * top * self.wz[None, :] * w0 / np.cos(th) ** 2
        a = self.lp[:, None] + 4 * np.sin(qz / 2) ** 2 + b
        p = 1 - np.sin(qz) ** 2 / (self.sp[:, None] + np.sin(qz) ** 2)
        inner = (p * Z(a, re, s, qz) * wq).sum(axis=1)
        return 8 * float((ap * inner * self.w).sum()) / (2 * np.pi) ** 3


def axis(spec, log):
    lo, hi, per = spec
    n = int(round((hi - lo) * per)) + 1
    return lo + np.arange(n) / per


def checks(quad):
    fine = Quadrature(24, 64, 12)
    watson = 0.2527310098
    ok = True
    v = quad.phi(0, 0, 0)
    print(f"phi(0,0,0) = {v:.7f}, (2/3) Watson = {2 * watson / 3:.7f}")
    ok &= abs(v / (2 * watson / 3) - 1) < 2e-4
    v = quad.phi(1e5, 0, 0)
    print(f"Re_h phi(1e5,0,0) = {1e5 * v:.5f}, expected 1/2")
    ok &= abs(2e5 * v - 1) < 2e-3
    worst = 0
    for re in (0, 0.3, 3, 30, 300):
        for b in (0, 1e-3, 1, 100):
            for s in (0, 0.15, 0.6):
                worst = max(worst, abs(quad.phi(re, b, s) / fine.phi(re, b, s) - 1))
    print(f"quadrature against a finer one: largest relative difference {worst:.1e}")
    return ok and worst < 1e-3


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=OUT)
    ap.add_argument("--check-only", action="store_true")
    ap.add_argument("--skip-checks", action="store_true")
    a = ap.parse_args()
    quad = Quadrature()
    if not a.skip_checks and not checks(quad):
        sys.exit("lattice_self_disturbance: a check failed")
    if a.check_only:
        return
    lr, lb, sp = axis(LOG_RE, True), axis(LOG_B, True), axis(SPREAD, False)
    t0 = time.time()
    table = np.empty((len(sp), len(lr), len(lb)))
    for k, s in enumerate(sp):
        for i, r in enumerate(lr):
            for j, b in enumerate(lb):
                table[k, i, j] = np.log(quad.phi(10**r, 10**b, s))
        print(f"s/h = {s:.2f} done ({time.time() - t0:.0f} s)", flush=True)
    lines = [
        "#pragma once",
        "// Generated by scripts/lattice_self_disturbance.py: do not edit. log phi_lat(Re_h, b, s/h),",
        "// the particle's self-disturbance on the finite-volume lattice (self_disturbance.hpp).",
        "namespace grainflow::lattice_table {",
        f"inline constexpr double log_re_lo = {LOG_RE[0]!r}, log_re_per_decade = {LOG_RE[2]!r};",
        f"inline constexpr double log_b_lo = {LOG_B[0]!r}, log_b_per_decade = {LOG_B[2]!r};",
        f"inline constexpr double spread_lo = {SPREAD[0]!r}, spread_per_unit = {SPREAD[2]!r};",
        f"inline constexpr int n_spread = {len(sp)}, n_re = {len(lr)}, n_b = {len(lb)};",
        "// [spread][re][b]",
        "inline constexpr double log_phi[] = {",
    ]
    flat = table.ravel()
    for k in range(0, len(flat), 6):
        lines.append("    " + ", ".join(f"{v:.10e}" for v in flat[k:k + 6]) + ",")
    lines += ["};", "}  // namespace grainflow::lattice_table", ""]
    with open(a.out, "w") as f:
        f.write("\n".join(lines))
    print(f"wrote {a.out}: {flat.size} values in {time.time() - t0:.0f} s")


if __name__ == "__main__":
    main()
