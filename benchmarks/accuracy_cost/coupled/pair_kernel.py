#!/usr/bin/env python3
"""The pair's interaction under diffusion-based averaging (docs/models/undisturbed-velocity.md,
"With diffusion-based averaging"): the velocity one sphere's force induces at the other, l
away sideways in a periodic cube, as a ratio to Hasimoto's periodic Stokeslet G_zz (the
reference of settling_pair.py):

  continuum  Hasimoto's Fourier series with the averaging's Gaussian: deposit and read-back
             each spread by sigma per axis, e^(-sigma^2 k^2); optionally also the cells'
             boxes of deposit and read-back (sinc^2 per axis, `sampling cell`);
  lattice    the model lattice of scripts/lattice_self_disturbance.py on the periodic mesh:
             7-point Laplacian, collocated projection 1 - sin^2 q_z / sum sin^2 q_a, the
             averaging's symbol D(q)^2, a force in one cell read back two cells away.

Usage: pair_kernel.py [--cells 3] [--spacing 6] [--width 12] [--sigma 2]   (diameters, cells)
"""
import argparse
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", "scripts"))
import settling_pair as sp  # noqa: E402
from lattice_self_disturbance import smoothing_symbol  # noqa: E402


def continuum(L, l, sigma, cell, n=60):
    """8 pi mu G_zz at (l, 0, 0) in the periodic cube L, both ends spread by sigma per axis
    (and by the cell's box, width `cell`, if cell > 0)."""
    k1 = 2 * np.pi / L * np.arange(-n, n + 1)
    kx, ky, kz = np.meshgrid(k1, k1, k1, indexing="ij")
    k2 = kx**2 + ky**2 + kz**2
    k2[n, n, n] = 1
    f = (1 - kz**2 / k2) * np.exp(-2 * sigma**2 * k2) / k2 * np.cos(kx * l)
    if cell:
        for k in (kx, ky, kz):
            f = f * np.sinc(k * cell / (2 * np.pi)) ** 2
    f[n, n, n] = 0
    return 8 * math.pi * f.sum() / L**3


def lattice(N, m, sigma_cells):
    """8 pi mu h G_zz of the model lattice (N^3 periodic cells) at m cells along x."""
    q1 = 2 * np.pi * np.fft.fftfreq(N)
    qx, qy, qz = np.meshgrid(q1, q1, q1, indexing="ij")
    lam = 4 * (np.sin(qx / 2) ** 2 + np.sin(qy / 2) ** 2 + np.sin(qz / 2) ** 2)
    s2 = np.sin(qx) ** 2 + np.sin(qy) ** 2 + np.sin(qz) ** 2
    proj = np.where(s2 > 1e-14, 1 - np.sin(qz) ** 2 / np.where(s2 > 1e-14, s2, 1), 1.0)
    smooth = np.vectorize(lambda x: smoothing_symbol(sigma_cells, x))(lam) if sigma_cells else 1.0
    val = proj * smooth**2 * np.cos(qx * m) / np.where(lam > 0, lam, 1)
    val[0, 0, 0] = 0
    return 8 * math.pi * val.sum() / N**3


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cells", type=float, default=3.0)
    ap.add_argument("--spacing", type=float, default=6.0)
    ap.add_argument("--width", type=int, default=12)
    ap.add_argument("--sigma", type=float, default=2.0)
    a = ap.parse_args()
    L = a.width * a.cells
    ref = float(sp.periodic_zz(np.array([a.spacing, 0.0, 0.0]), (L, L, L)))
    m = round(a.spacing / a.cells)
    print(f"periodic cube {L:g} d, spacing {a.spacing:g} d, cells {a.cells:g} d, sigma {a.sigma:g} d: "
          f"Hasimoto 8 pi mu G_zz = {ref:.5f} / d")
    # Without averaging the continuum series needs some decay to converge: sigma = 0.15 d.
    for s in (0.15, a.sigma):
        name = f"sigma {s:g} d" if s > 0.15 else "no averaging (the continuum with sigma 0.15 d)"
        print(f"  {name}: continuum {continuum(L, a.spacing, s, 0) / ref:.3f}, with the cells' "
              f"boxes {continuum(L, a.spacing, s, a.cells) / ref:.3f}, model lattice "
              f"{lattice(a.width, m, s / a.cells if s > 0.15 else 0) / a.cells / ref:.3f} (x Hasimoto)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
