#!/usr/bin/env python3
"""Ergun packed bed: pressure drop against superficial velocity.

Below minimum fluidisation the bed is a fixed packing and its pressure drop follows Ergun
(1952, Chem. Eng. Prog. 48:89):
    dp/L = 150 mu U (1-eps)^2 / (eps^3 d^2) + 1.75 rho U^2 (1-eps) / (eps^3 d),
evaluated with the bed's own mean void fraction and height, measured from the particles
just before the gas is turned on. Above minimum fluidisation (Wen & Yu 1966,
Re_mf = sqrt(33.7^2 + 0.0408 Ar) - 33.7) the bed floats and its pressure drop is its
buoyant weight per area, N V_p (rho_p - rho_f) g / A.

Stages (superficial velocity and time window) must match the table in 0/U. Passes when
every fixed-bed stage is within 10 % of Ergun and every fluidised stage within 5 % of the
weight; prints one line per stage and exits 1 otherwise. Writes ergunPackedBed.png.
Usage: analyse.py [--short]
"""
import math
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from foam_case import series  # noqa: E402 (tutorials/cfd-dem/foam_case.py)

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
from run_index import run_snapshots  # noqa: E402 (tutorials/run_index.py)

SHORT = "--short" in sys.argv
rho_p, rho_f, mu, g = 2500.0, 1.2, 1.8e-5, 9.81
area = 0.012 * 0.012
# (superficial velocity [m/s], start [s], end [s]) of each stage, as in 0/U.
if SHORT:
    flow_start, stages = 0.15, [(0.30, 0.15, 0.25), (0.60, 0.25, 0.45)]
else:
    flow_start, stages = 0.2, [(0.15, 0.2, 0.3), (0.30, 0.3, 0.4), (0.60, 0.4, 0.6),
                               (0.70, 0.6, 0.8)]

# --- the bed just before the gas is turned on ------------------------------------------
snaps = run_snapshots("particles")
times = [h5py.File(f, "r").attrs["time"] for f in snaps]
k = int(np.argmin([abs(t - flow_start) for t in times]))
with h5py.File(snaps[k], "r") as f:
    z = f["position"][:, 2]
    r = f["radius"][:]
n = len(r)
d = 2 * r.mean()
vp = 4 / 3 * math.pi * r**3


def slice_volume(zc, rad, z1, z2):
    """Volume of spheres (centres zc, radii rad) between the planes z1 < z2."""
    a = np.clip(z1 - zc, -rad, rad)
    b = np.clip(z2 - zc, -rad, rad)
    return math.pi * ((rad**2) * (b - a) - (b**3 - a**3) / 3)


dz = 0.25e-3
edges = np.arange(0, z.max() + r.max() + dz, dz)
phi = np.array([slice_volume(z, r, a, b).sum() for a, b in zip(edges[:-1], edges[1:])]) / (area * dz)
mid = 0.5 * (edges[:-1] + edges[1:])
bulk = np.median(phi[(mid > 3 * d) & (mid < z.max() - 3 * d)])
top = mid[np.nonzero(phi > 0.5 * bulk)[0][-1]]
core = (mid > 3 * d) & (mid < top - 3 * d)
eps = 1 - phi[core].mean()
height = vp.sum() / (area * (1 - eps))
weight = vp.sum() * (rho_p - rho_f) * g / area
ar = g * rho_f * (rho_p - rho_f) * d**3 / mu**2
u_mf = (math.sqrt(33.7**2 + 0.0408 * ar) - 33.7) * mu / (rho_f * d)


def ergun(u):
    return height * (150 * mu * u * (1 - eps) ** 2 / (eps**3 * d**2) +
                     1.75 * rho_f * u**2 * (1 - eps) / (eps**3 * d))


# --- measured pressure drop --------------------------------------------------------------
# Every postProcessing/inletPressure/<start time>/ folder: a restart adds one.
t, p_inlet, _ = series(".", "inletPressure")
dp = rho_f * p_inlet
print(f"ergunPackedBed: {n} particles, d = {d * 1e3:.3f} mm, bed eps = {eps:.4f}, height "
      f"{height * 1e3:.2f} mm, U_mf(Wen-Yu) = {u_mf:.3f} m/s, weight/area = {weight:.2f} Pa")
ok = True
results = []
for u, t0, t1 in stages:
    window = (t > t0 + 0.4 * (t1 - t0)) & (t <= t1)  # the last 60 % of the stage
    if not window.any():
        sys.exit(f"analyse.py: postProcessing/inletPressure holds no time in "
                 f"{t0 + 0.4 * (t1 - t0):g}-{t1:g} s, the stage at U = {u:.2f} m/s (it runs "
                 f"from {t[0]:g} to {t[-1]:g} s): has the run reached {t1:g} s?")
    measured = dp[window].mean()
    if u < u_mf:
        ref, tol, name = ergun(u), 0.10, "Ergun"
    else:
        ref, tol, name = weight, 0.05, "weight/area"
    err = measured / ref - 1
    good = abs(err) <= tol
    ok &= good
    results.append((u, measured, ref, name))
    print(f"  U = {u:.2f} m/s: dp = {measured:8.2f} Pa, {name} {ref:8.2f} Pa, "
          f"error {100 * err:+6.2f} % (allowed {100 * tol:.0f} %): {'ok' if good else 'FAILED'}")

fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4))
a1.plot(t, dp, lw=0.8, label="grainFoam: inlet - outlet")
a1.axhline(weight, color="k", ls="--", lw=0.8, label="bed weight / area")
a1.set_xlabel("t [s]")
a1.set_ylabel("pressure drop [Pa]")
a1.legend()
us = np.linspace(0.01, 1.2, 200)
a2.plot(us, np.minimum(ergun(us), weight), "k-", label="Ergun, capped at weight/area")
a2.plot([u for u, *_ in results], [m for _, m, *_ in results], "o", label="grainFoam (stage means)")
a2.axvline(u_mf, color="0.6", ls=":", label=f"U_mf (Wen-Yu) = {u_mf:.2f} m/s")
a2.set_xlabel("superficial velocity U [m/s]")
a2.set_ylabel("pressure drop [Pa]")
a2.legend()
fig.suptitle(f"Packed bed of {n} beads (eps = {eps:.3f}, H = {height * 1e3:.1f} mm)")
fig.tight_layout()
fig.savefig("ergunPackedBed.png", dpi=120)
sys.exit(0 if ok else 1)
