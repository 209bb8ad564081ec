#!/usr/bin/env python3
"""The self-disturbance a particle reads through OpenFOAM's cellPoint interpolation (`sampling
cellPoint`), on the finite-volume lattice grainFoam solves; writes
dem/fluid/lattice_self_disturbance_cellpoint_table.hpp (docs/models/undisturbed-velocity.md).

With `sampling cell` the particle reads its cells back with its footprint's weights, and the
read-back and the deposit share one kernel (scripts/lattice_self_disturbance.py). With
`sampling cellPoint` it still deposits with its footprint, but reads the velocity at its
centre by cellPoint interpolation: the cell value and three point values in the tetrahedron
(cell centre, face triangle) that holds the centre, each point value the mean of the eight
cells around the point (volPointInterpolation on a uniform mesh). On a uniform cubic mesh
(h = 1) the weight this puts on the cell whose centre lies at z from the particle is a
continuous, piecewise-linear function R(z) of z, not separable per axis (the tetrahedra).

Motion along the mesh axis z, the particle's place across it y = (y_x, y_y) in its cell fixed
(|y| <= 1/2). On the transverse cells j = (j_x, j_y) (offsets -1, 0, 1 from the particle's own)
the read-back along the motion is rho_j(zeta) = R(j - y, zeta), zeta the cell centre's distance
from the particle along z; the deposit is the footprint's marginal D_j' on the transverse cells
times the cell's box along z widened by the footprint's spread s (variance s^2 per axis):
g_d(k) = sinc(k/2) / (1 + s^2 k^2 / 2). Averaged over the passage, as in the cell-sampling
derivation, the disturbance read back along F is u' = -F phi / (mu_e h) with

    phi(y) = sum_j' D_j' U_j'(y),
    U_j'(y) = (2 pi)^-3 int_BZ sum_j cos(q_perp . (j - j')) P_zz(q)
              sum_G rho_j^(k) g_d(k) Re 1/(Lambda(q) + b + i Re_h k) d^3q,   k = q_z + 2 pi G

(only the cosines survive: the rest of the integrand is even in q_x and q_y). rho_j is
continuous and piecewise linear in zeta, and even in zeta (the kernel with the two diagonals of
each face averaged, below), so rho_j^(k) = -(1/k^2) sum_n ds_jn cos(k zeta_n) with ds_jn its
slope jumps at its breakpoints zeta_n (sum_n ds_jn = 0, sum_n ds_jn zeta_n^2 = 2 int rho_j):

    U_j'(y) = sum_j sum_n ds_jn H(zeta_n; |j_x - j'_x|, |j_y - j'_y|),
    H(zeta; a, c) = -(2 pi)^-3 int_BZ cos(a q_x) cos(c q_y) P_zz
                    sum_G (cos(k zeta) - 1)/k^2 g_d(k) Re 1/(Lambda + b + i Re_h k) d^3q

(the -1 adds nothing, sum_n ds_jn = 0, and keeps each term finite at k = 0). H is computed with
the transverse integral inside (graded Gauss-Legendre panels towards q = 0, as the cell tables)
and a fixed graded grid along q_z outside, the sum over G to |G| = 12 (its terms fall as
1/k^3). U_j' is tabulated over the axes of the cell tables (Re_h, b, s/h) and over the place y
on a grid of 1/8 (y_x >= y_y >= 0; the others by symmetry).

The tetrahedra. cellPoint splits each face into two triangles along the diagonal from the
face's tet base point; which diagonal a face of a block mesh gets follows its point order, and
a particle crosses faces of both kinds. The kernel here averages the two triangulations of every
face (so it keeps the cube's symmetries); the checks print how far either pure choice moves phi.

Checks printed first: the fixed q_z grid with the transverse integral inside against the cell
tables' quadrature (the same integrand, scripts/lattice_self_disturbance.py); U at Re_h = 0
against direct sums of the lattice Green's function over a periodic lattice of 64^3 cells with
the kernel's exact passage average (independent of the Fourier form in zeta); the Oseen limit
Re_h U_j' -> (1/2) <rho_j'> (the force carried off through one cell's section, read with the
read-back's passage-averaged weight on that cell).

With diffusionBandwidth the run time does not tabulate this integral with the averaging's
symbol D(q)^2 (another axis would multiply the table's 3.8 MB by 18): it models the cellPoint
read-back as the cell tables model theirs, exactly across the motion (the stencil's
passage-averaged weights on the transverse columns) and along it by a box widened to the
stencil's variance (self_disturbance.hpp). --smoothed-check prints how far that model is from
this integral with D(q)^2 over a set of cell Reynolds numbers, screenings, spreads, places and
deposits, per sigma/h.

Usage: scripts/python.sh scripts/lattice_self_disturbance_cellpoint.py [--out PATH]
[--check-only] (about 1 minute on one core); --smoothed-check (about 3 minutes).
"""
import argparse
import itertools
import os
import sys
import time

import numpy as np
from numpy.polynomial.legendre import leggauss

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import lattice_self_disturbance as lsd  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "..", "dem", "fluid", "lattice_self_disturbance_cellpoint_table.hpp")

PLACE_STEP = 1 / 8          # the grid of the particle's place across its motion
DZ = 1 / 16                 # the zeta grid: holds every breakpoint of rho_j for places on PLACE_STEP
ZETA = np.arange(0, 25) * DZ  # 0 .. 1.5
G_MAX = 12
PLACES = [(i, j) for i in range(5) for j in range(i + 1)]   # (y_x, y_y) = (i, j)/8, y_x >= y_y
DELTAS = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)]   # |j - j'| per transverse axis
OFFSETS = [(jx, jy) for jx in (-1, 0, 1) for jy in (-1, 0, 1)]


# --- The cellPoint kernel on a uniform cubic mesh --------------------------------------------

def _triangle(u, v, diagonal):
    """Barycentric weights on the corners (su, sv) of the square [-1, 1]^2 of the point (u, v),
    in the triangle of the split along `diagonal` (0: (-,-) to (+,+); 1: (+,-) to (-,+))."""
    if diagonal == 1:
        w = _triangle(-u, v, 0)
        return {(-su, sv): x for (su, sv), x in w.items()}
    if u >= v:
        return {(-1, -1): (1 - u) / 2, (1, -1): (u - v) / 2, (1, 1): (1 + v) / 2}
    return {(-1, -1): (1 - v) / 2, (-1, 1): (v - u) / 2, (1, 1): (1 + u) / 2}


def kernel(y, diagonal="average"):
    """The cellPoint weights of a point at y (|y_a| <= 1/2) from its cell's centre on the cells
    at offsets (-1..1)^3: {offset: weight}. The tetrahedron (centre, face triangle) of the face
    the largest |y_a| points to: the centre's weight 1 - t (t = 2 |y_a|), each triangle corner's
    t times its barycentric weight on the face; a corner's value is the mean of its 8 cells."""
    y = np.asarray(y, float)
    a = int(np.argmax(np.abs(y)))
    t = 2 * abs(y[a])
    out = {(0, 0, 0): 1 - t}
    if t == 0:
        return out
    sig = 1 if y[a] > 0 else -1
    b, c = (a + 1) % 3, (a + 2) % 3
    u, v = 2 * y[b] / t, 2 * y[c] / t
    choices = (0, 1) if diagonal == "average" else (diagonal,)
    for d in choices:
        for (su, sv), w in _triangle(u, v, d).items():
            share = t * w / len(choices) / 8
            for oa in (0, sig):
                for ob in (0, su):
                    for oc in (0, sv):
                        o = [0, 0, 0]
                        o[a], o[b], o[c] = oa, ob, oc
                        out[tuple(o)] = out.get(tuple(o), 0.0) + share
    return out


def passage(place, diagonal="average"):
    """rho_j(zeta) of a particle at `place` = (y_x, y_y) moving along z: an array
    [j_x + 1][j_y + 1][zeta index] on zeta = -1.5 .. 1.5 in steps of DZ."""
    n = int(round(3 / DZ)) + 1
    rho = np.zeros((3, 3, n))
    for yz in np.arange(-0.5, 0.5 + DZ / 2, DZ):
        for (jx, jy, dn), w in kernel((place[0], place[1], yz), diagonal).items():
            k = int(round((dn - yz + 1.5) / DZ))
            rho[jx + 1, jy + 1, k] = w  # shared ends (yz = +-1/2) agree: the kernel is continuous
    return rho


def slope_jumps(rho):
    """ds_n at each zeta grid point of a piecewise-linear rho (zero beyond the grid)."""
    p = np.pad(rho, [(0, 0)] * (rho.ndim - 1) + [(1, 1)])
    return (p[..., 2:] - 2 * p[..., 1:-1] + p[..., :-2]) / DZ


def coefficients(place, diagonal="average"):
    """S[j'][delta][zeta]: U_j' = sum_delta,zeta S H(zeta; delta), the slope jumps of rho_j at
    +-zeta gathered onto |zeta| and onto |j - j'|."""
    ds = slope_jumps(passage(place, diagonal))
    n0 = (ds.shape[-1] - 1) // 2
    folded = ds[..., n0:].copy()
    folded[..., 1:] += ds[..., n0 - 1::-1]
    s = np.zeros((9, len(DELTAS), len(ZETA)))
    for jp, (px, py) in enumerate(OFFSETS):
        for jx, jy in OFFSETS:
            dx, dy = sorted((abs(jx - px), abs(jy - py)))
            s[jp, DELTAS.index((dx, dy))] += folded[jx + 1, jy + 1]
    return s


# --- H(zeta; delta) --------------------------------------------------------------------------

class Quadrature:
    def __init__(self, nt=12, panels=8, nz=12, zpanels=10):
        x, w = leggauss(nt)
        edges = np.concatenate([[0], np.pi * np.logspace(-5, 0, panels)])
        q = np.concatenate([0.5 * (hi + lo) + 0.5 * (hi - lo) * x for lo, hi in zip(edges[:-1], edges[1:])])
        wq = np.concatenate([0.5 * (hi - lo) * w for lo, hi in zip(edges[:-1], edges[1:])])
        i, j = np.triu_indices(len(q))
        qx, qy = q[i], q[j]
        self.w = wq[i] * wq[j] * np.where(i == j, 1.0, 2.0)
        self.lp = 4 * np.sin(qx / 2) ** 2 + 4 * np.sin(qy / 2) ** 2
        self.sp = np.sin(qx) ** 2 + np.sin(qy) ** 2
        # Transverse weights per delta (a, c), symmetrised over q_x <-> q_y like the pairs.
        self.cw = np.array([0.5 * (np.cos(a * qx) * np.cos(c * qy) + np.cos(c * qx) * np.cos(a * qy))
                            for a, c in DELTAS]) * self.w
        xz, wz = leggauss(nz)
        ez = np.concatenate([[0], np.pi * np.logspace(-6, 0, zpanels)])
        self.qz = np.concatenate([0.5 * (hi + lo) + 0.5 * (hi - lo) * xz for lo, hi in zip(ez[:-1], ez[1:])])
        self.wz = np.concatenate([0.5 * (hi - lo) * wz for lo, hi in zip(ez[:-1], ez[1:])])
        self.G = np.arange(-G_MAX, G_MAX + 1)
        self.k = self.qz[:, None] + 2 * np.pi * self.G[None, :]          # [z][G]
        lz = 4 * np.sin(self.qz / 2) ** 2
        self.lam = self.lp[:, None] + lz[None, :]                         # [pair][z]
        self.p = 1 - np.sin(self.qz)[None, :] ** 2 / (self.sp[:, None] + np.sin(self.qz)[None, :] ** 2)
        # (cos(k zeta) - 1)/k^2 = -2 sin^2(k zeta / 2)/k^2, [z][G][zeta]
        kk = self.k[..., None]
        self.ramp = -2 * np.sin(kk * ZETA / 2) ** 2 / kk**2

    def transverse(self, re, b):
        """M[delta][z][G] = (2 pi)^-3 * 8 * int cos.. P_zz Re R over the transverse pairs, times
        the q_z weight (the factor 8: q in [0, pi]^3, the G sum covering -q_z)."""
        a = self.lam + b
        pw = self.p
        m = np.empty((len(DELTAS), len(self.qz), len(self.G)))
        for g in range(len(self.G)):
            rr = a / (a * a + (re * self.k[None, :, g]) ** 2)
            m[:, :, g] = self.cw @ (pw * rr)
        return m * self.wz[None, :, None] * 8 / (2 * np.pi) ** 3

    def H(self, m, s):
        """H[delta][zeta] for the footprint spread s (the deposit's box widened)."""
        gd = np.sinc(self.k / (2 * np.pi)) / (1 + s * s * self.k**2 / 2)
        return -np.einsum("dzg,zg,zgn->dn", m, gd, self.ramp)

    def cell_t00(self, re, b, s):
        """T_00 of the cell tables (deposit and read-back the same one cell) with this
        quadrature's order (transverse inside, fixed q_z grid) and the closed-form G sum."""
        a = self.lam + b
        z = lsd.Z(a, re, s, np.broadcast_to(self.qz, a.shape))
        return float((self.cw[0] @ (self.p * z)) @ self.wz) * 8 / (2 * np.pi) ** 3


# --- Checks ----------------------------------------------------------------------------------

def green(n, b):
    """The static lattice Green's function g_zz on n^3 periodic cells (zero mode out):
    (1/n^3) sum_q e^(i q.c) P_zz / (Lambda + b), indexed [c_x, c_y, c_z] mod n."""
    q = 2 * np.pi * np.fft.fftfreq(n)
    qx, qy, qz = np.meshgrid(q, q, q, indexing="ij", sparse=True)
    lam = 4 * (np.sin(qx / 2) ** 2 + np.sin(qy / 2) ** 2 + np.sin(qz / 2) ** 2) + b
    ss = np.sin(qx) ** 2 + np.sin(qy) ** 2 + np.sin(qz) ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        p = np.where(ss > 0, 1 - np.sin(qz) ** 2 / np.where(ss > 0, ss, 1), 1.0)
        f = np.where(lam > 0, p / np.where(lam > 0, lam, 1), 0.0)
    return np.real(np.fft.ifftn(f))


def direct_u(g, place, jp, diagonal="average"):
    """U_j'(Re_h = 0) by the lattice Green's function: the passage average (trapezoid over the
    breakpoints' grid: exact for the piecewise-linear kernel) of the read-back of a unit
    deposit in the cell at transverse offset j' in the particle's own layer."""
    yz = np.arange(-0.5, 0.5 + DZ / 2, DZ)
    vals = []
    for z in yz:
        vals.append(sum(w * g[o[0] - jp[0], o[1] - jp[1], o[2]]
                        for o, w in kernel((place[0], place[1], z), diagonal).items()))
    vals = np.array(vals)
    return float((vals[1:] + vals[:-1]).sum() * DZ / 2)


def checks(quad):
    ok = True
    cells = lsd.Quadrature()
    worst = 0
    for re, b, s in ((0, 0, 0), (0.3, 1e-3, 0.125), (4, 0, 0), (30, 1, 0.25), (300, 0, 0), (3000, 10, 0)):
        ref = cells.phi(re, b, s)[1]
        worst = max(worst, abs(quad.cell_t00(re, b, s) / ref - 1))
    print(f"cell T_00 with the q_z grid outside against the cell tables' quadrature: largest "
          f"relative difference {worst:.1e}")
    ok &= worst < 1e-3
    coef = {pl: coefficients(np.array(pl) * PLACE_STEP) for pl in PLACES}
    for b, n in ((1.0, 64), (0.05, 96)):
        g = green(n, b)
        h = quad.H(quad.transverse(0, b), 0)
        dev = 0
        for pl in ((0, 0), (2, 1), (3, 3), (4, 2)):
            y = np.array(pl) * PLACE_STEP
            for jp in ((0, 0), (1, 0), (-1, 1)):
                k = OFFSETS.index(jp)
                u = float((coef[pl][k] * h).sum())
                d = direct_u(g, y, jp)
                dev = max(dev, abs(u - d) / max(abs(d), 1e-3))
                if jp == (0, 0):
                    print(f"b = {b}, place {tuple(y)}: U_00 Fourier {u:.6f}, lattice sum {d:.6f}")
        print(f"b = {b}: U_j' against lattice sums on {n}^3 cells, largest relative difference {dev:.1e}")
        ok &= dev < 2e-3
    # The Oseen limit: Re_h U_j' -> (1/2) <rho_j'>.
    re = 1e5
    h = quad.H(quad.transverse(re, 0), 0)
    dev = 0
    for pl in ((0, 0), (3, 1), (4, 4)):
        y = np.array(pl) * PLACE_STEP
        rho = passage(y)
        for k, jp in enumerate(OFFSETS):
            mean = rho[jp[0] + 1, jp[1] + 1].sum() * DZ
            u = float((coef[pl][k] * h).sum()) * re
            dev = max(dev, abs(u - mean / 2))
    print(f"Re_h = 1e5: Re_h U_j' against <rho_j'>/2, largest difference {dev:.1e}")
    ok &= dev < 3e-3
    # The quadrature against a finer one (every place and j', relative to U_00).
    fine = Quadrature(24, 12, 24, 14)
    worst = 0
    allc = np.array([coef[pl] for pl in PLACES])
    for re, b, s in ((0, 0, 0), (0.3, 1e-3, 0.125), (4, 0, 0.25), (30, 1, 0), (300, 0, 0.5), (3000, 10, 0)):
        us = [np.einsum("pjdn,dn->pj", allc, qq.H(qq.transverse(re, b), s)) for qq in (quad, fine)]
        worst = max(worst, (np.abs(us[0] - us[1]) / us[1][:, 4:5]).max())
    print(f"quadrature against a finer one: largest difference relative to U_00 {worst:.1e}")
    ok &= worst < 1e-3
    # The diagonals: either pure triangulation against their average.
    h = quad.H(quad.transverse(4, 0), 0.1)
    for pl in ((2, 1), (4, 2)):
        y = np.array(pl) * PLACE_STEP
        us = [float((coefficients(y, d)[OFFSETS.index((0, 0))] * h).sum()) for d in ("average", 0, 1)]
        print(f"place {tuple(y)}, Re_h 4, s 0.1: U_00 averaged diagonals {us[0]:.5f}, "
              f"diagonal 0 {us[1]:.5f}, diagonal 1 {us[2]:.5f}")
    return ok


# --- diffusionBandwidth: the model against the exact integral -------------------------------

class SmoothedQuadrature(Quadrature):
    """The exact integrand with the averaging's symbol squared, D(q)^2 (the deposit and the
    read-back each averaged once; lattice_self_disturbance.smoothing_symbol)."""
    sigma = 0.0

    def transverse(self, re, b):
        a = self.lam + b
        pw = self.p * lsd.smoothing_symbol(self.sigma, self.lam) ** 2
        m = np.empty((len(DELTAS), len(self.qz), len(self.G)))
        for g in range(len(self.G)):
            m[:, :, g] = self.cw @ (pw * a / (a * a + (re * self.k[None, :, g]) ** 2))
        return m * self.wz[None, :, None] * 8 / (2 * np.pi) ** 3


def passage_moments(place):
    """The stencil's passage-averaged weights on the transverse columns [ja + 1][jb + 1] and
    its variance along the motion: Simpson's rule between the places where the tetrahedron
    changes (exact: the weights are linear there)."""
    cuts = sorted({float(np.clip(c, -0.5, 0.5)) for c in
                   (-0.5, 0.5, 0.0, place[0], -place[0], place[1], -place[1])})
    rho = np.zeros((3, 3))
    second = 0.0
    for lo, hi in zip(cuts[:-1], cuts[1:]):
        for yz, w in ((lo, 1), (0.5 * (lo + hi), 4), (hi, 1)):
            for (jx, jy, dn), k in kernel((place[0], place[1], yz)).items():
                rho[jx + 1, jy + 1] += (hi - lo) * w / 6 * k
                second += (hi - lo) * w / 6 * k * (dn - yz) ** 2
    return rho, second / rho.sum()


def smoothed_model(re, b, s, sigma, place, da, db):
    """The run-time model (self_disturbance.cpp, cell_point_smoothed): across the motion the
    stencil's column weights against the deposit's marginals through the cell tables' T_ij,
    along it a cell's box on either side widened by s_e, 1/6 + 2 s_e^2 = 1/12 + s^2 + V_R."""
    rho, var = passage_moments(place)
    se = np.sqrt(max(0.0, 0.5 * (s * s + var - 1 / 12)))
    t = lsd.Quadrature(sigmas=(sigma,)).phi(re, b, se)
    tt = np.array([[t[1], t[2], t[3]], [t[2], t[4], t[5]], [t[3], t[5], t[6]]])
    basis = np.array([[1, 0, 0], [-1, 2, 0], [1, -8, 8]], float)
    e = basis @ tt @ basis.T
    phi = 0.0
    for jx, jy in OFFSETS:
        for rx, ry in OFFSETS:
            phi += da[jx + 1] * db[jy + 1] * rho[rx + 1, ry + 1] * e[abs(rx - jx), abs(ry - jy)]
    return phi


def smoothed_check():
    """The largest relative difference of the model from the exact integral per sigma/h, over
    cell Reynolds numbers, screenings, spreads, places and deposits."""
    quad = SmoothedQuadrature()
    cases = [(0.15, 1e-6, 0.15), (0.15, 1e-6, 0.07), (4, 1e-6, 0.1), (4, 3.0, 0.1), (75, 1e-6, 0.2),
             (0.3, 30.0, 0.05)]
    places = [(0.25, 0.0), (0.25, 0.125), (0.5, 0.25), (0.375, 0.375), (0.45, 0.1)]
    deposits = [((0, 1, 0), (0, 1, 0)), ((0.1, 0.8, 0.1), (0, 0.7, 0.3))]
    for sigma in (0.2, 0.4, 0.667, 1.0, 1.333, 2.0):
        quad.sigma = sigma
        worst = 0.0
        for re, b, s in cases:
            h = quad.H(quad.transverse(re, b), s)
            for place in places:
                u = np.einsum("jdn,dn->j", coefficients(np.array(place)), h)
                for da, db in deposits:
                    exact = sum(da[jx + 1] * db[jy + 1] * u[OFFSETS.index((jx, jy))] for jx, jy in OFFSETS)
                    model = smoothed_model(re, b, s, sigma, place, da, db)
                    worst = max(worst, abs(model / exact - 1))
        print(f"sigma/h = {sigma}: the model against the exact integral, largest relative "
              f"difference {worst:.2%}", flush=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=OUT)
    ap.add_argument("--check-only", action="store_true")
    ap.add_argument("--skip-checks", action="store_true")
    ap.add_argument("--smoothed-check", action="store_true",
                    help="only compare the diffusionBandwidth model with the exact integral")
    a = ap.parse_args()
    if a.smoothed_check:
        return smoothed_check()
    quad = Quadrature()
    t0 = time.time()
    if not a.skip_checks and not checks(quad):
        sys.exit("lattice_self_disturbance_cellpoint: a check failed")
    print(f"checks: {time.time() - t0:.0f} s", flush=True)
    if a.check_only:
        return
    table = tabulate(quad)
    write(a.out, table)
    print(f"wrote {a.out} in {time.time() - t0:.0f} s")


def tabulate(quad):
    """U_j' over [place][j'][spread][re][b]."""
    lr, lb, sp = lsd.axis(lsd.LOG_RE, True), lsd.axis(lsd.LOG_B, True), lsd.axis(lsd.SPREAD, False)
    coef = np.array([coefficients(np.array(pl) * PLACE_STEP) for pl in PLACES])
    u = np.empty((len(PLACES), 9, len(sp), len(lr), len(lb)))
    t0 = time.time()
    for i, r in enumerate(lr):
        for j, b in enumerate(lb):
            m = quad.transverse(10**r, 10**b)
            for k, s in enumerate(sp):
                u[:, :, k, i, j] = np.einsum("pjdn,dn->pj", coef, quad.H(m, s))
        print(f"log10 Re_h = {r:.2f} done ({time.time() - t0:.0f} s)", flush=True)
    centre = OFFSETS.index((0, 0))
    if (u[:, centre] <= 0).any():
        sys.exit("lattice_self_disturbance_cellpoint: U_00 not positive somewhere")
    return u


def write(path, u):
    centre = OFFSETS.index((0, 0))
    others = [k for k in range(9) if k != centre]
    log_u00 = np.log(u[:, centre])
    ratio = u[:, others] / u[:, centre][:, None]
    places = ", ".join(f"{{{i}, {j}}}" for i, j in PLACES)
    lsd.write_header(
        path, ["cp_log_u00", "cp_ratio"],
        ["log U_00: the deposit in the particle's own transverse cell",
         "U_j' / U_00 for the other eight j' (the order of cp_offsets without {0, 0})"],
        [log_u00, ratio],
        [f"inline constexpr int cp_n_places = {len(PLACES)};",
         f"inline constexpr int cp_places[][2] = {{{places}}};  // (y_x, y_y) * cp_place_per_unit",
         f"inline constexpr double cp_place_per_unit = {1 / PLACE_STEP:g};",
         "inline constexpr int cp_offsets[][2] = {{-1, -1}, {-1, 0}, {-1, 1}, {0, -1}, {0, 0}, "
         "{0, 1}, {1, -1}, {1, 0}, {1, 1}};  // j' = (j'_x, j'_y)"],
        ["// Generated by scripts/lattice_self_disturbance_cellpoint.py: do not edit. The",
         "// self-disturbance read through cellPoint interpolation (self_disturbance.hpp,",
         "// lattice_self_disturbance_cellpoint): U_j'(Re_h, b, s/h) of a particle at the place",
         "// (y_x, y_y) across its motion (y_x >= y_y >= 0) for a unit deposit in the transverse",
         "// cell j'; the axes of Re_h, b and s/h are those of lattice_self_disturbance_table.hpp."],
        "[place][j'][spread][re][b] (cp_log_u00 without the j' axis)")


if __name__ == "__main__":
    main()
