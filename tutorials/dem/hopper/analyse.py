#!/usr/bin/env python3
"""Hopper discharge: measured mass flow rate against Beverloo's correlation.

Beverloo, Leniger & van de Velde (1961), Chem. Eng. Sci. 15:260:
    W = C rho_b sqrt(g) (D0 - k d)^(5/2)
with C = 0.58 and k = 1.5, the values Beverloo et al. fitted for circular orifices
(Nedderman 1992, "Statics and kinematics of granular materials", §10.2, quotes C =
0.58 +- 0.05 and k = 1.5 for spheres). rho_b is the bulk density of the settled bed,
measured here from the first snapshot (the bed at t = 0; --bed FILE gives it for a run
restarted into another folder, whose series starts at the restart); d is the mean diameter
(2.0 mm); D0 = 12 mm.
Beverloo's data are for flat-bottomed bins: a conical hopper flows faster. Rose &
Tanaka (1956) give the factor F = (tan(theta) tan(phi_d))^-0.35 (theta the hopper
half-angle from the vertical, phi_d ~ 45 deg the angle of the stagnant-zone
boundary; Nedderman §10.3), 1.17 for this hopper's 32 deg half-angle -- drawn as a line.
"""
import argparse
import math
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
from run_index import run_snapshots  # noqa: E402 (tutorials/run_index.py)

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("out", nargs="?", default="output/discharge",
                help="the discharge's output folder (default output/discharge)")
ap.add_argument("--bed", help="the settled bed at t = 0 (a snapshot), for a series that does "
                              "not start at t = 0: a run restarted into another folder")
args = ap.parse_args()
out = args.out
files = run_snapshots(out)
t, mass = [], []
for name in files:
    with h5py.File(name, "r") as f:
        z = f["position"][:, 2]
        t.append(float(f.attrs["time"]))
        mass.append(float(f["mass"][:][z > 0].sum()))
t, mass = np.array(t), np.array(mass)

# Bulk density of the bed at t = 0: solid volume of the centres inside a central
# cylinder (radius 5 mm, z 10-25 mm, at least 6 mm from the cone wall) over its volume.
# A run restarted into another folder starts its series there at the restart: its first
# snapshot is a bed already part emptied.
bed = args.bed or files[0]
if args.bed is None and t[0] > 0:
    sys.exit(f"analyse.py: the snapshot series of {out} starts at t = {t[0]:.6g} s "
             f"({files[0]}), not with the settled bed at t = 0 (a run restarted into another "
             "folder starts its series there at the restart): the bulk density needs the bed "
             "at t = 0. Give the folder the run started in, or give the bed with --bed: "
             "output/settled.h5 (the bed discharge.yaml starts from) or the first snapshot of "
             "the folder the run started in")
with h5py.File(bed, "r") as f:
    x, r, m = f["position"][:], f["radius"][:], f["mass"][:]
# A bed given with --bed must be the settled bed: no fewer particles above the orifice than
# the series' first snapshot holds (a part-emptied bed would give another bulk density).
if args.bed is not None:
    with h5py.File(files[0], "r") as f:
        first = int((f["position"][:, 2] > 0).sum())
    if int((x[:, 2] > 0).sum()) < first:
        sys.exit(f"analyse.py: --bed {bed} holds {int((x[:, 2] > 0).sum())} particles above the "
                 f"orifice, fewer than the series' first snapshot ({files[0]}, t = {t[0]:.6g} s: "
                 f"{first}): it is not the settled bed the discharge started from; give "
                 "output/settled.h5 or the first snapshot of the folder the run started in")
rho_p = float(np.mean(m / (4 / 3 * math.pi * r**3)))
inside = (np.hypot(x[:, 0], x[:, 1]) < 0.005) & (x[:, 2] > 0.010) & (x[:, 2] < 0.025)
phi = float((4 / 3 * math.pi * r[inside] ** 3).sum() / (math.pi * 0.005**2 * 0.015))
rho_b = phi * rho_p
d = 2 * float(np.mean(r))
D0, C, k, g = 0.012, 0.58, 1.5, 9.81
w_beverloo = C * rho_b * math.sqrt(g) * (D0 - k * d) ** 2.5
theta = math.atan((0.025 - D0 / 2) / 0.030)
F = (math.tan(theta) * math.tan(math.radians(45))) ** -0.35

# Steady discharge: fit the hopper mass between 0.2 s (flow established) and 1.0 s, or
# from the first snapshot of a series that starts later.
# A snapshot falls within a step of its nominal time (0.19999 s for 0.2 s): 1 ms of slack.
window = (t >= 0.2 - 1e-3) & (t <= 1.0 + 1e-3)
if window.sum() < 2:
    sys.exit(f"analyse.py: {out} holds {window.sum()} snapshot(s) between 0.2 and 1.0 s "
             f"(the run ends at {t[-1]:.3g} s): the fit needs the full discharge (time.end 1.2)")
slope, intercept = np.polyfit(t[window], mass[window], 1)
w_measured = -slope
rate_t = 0.5 * (t[1:] + t[:-1])
rate = -np.diff(mass) / np.diff(t)

print(f"bulk solid fraction {phi:.3f}, bulk density {rho_b:.0f} kg/m3, d = {1e3 * d:.2f} mm"
      + (f" (the bed at t = 0: {bed})" if args.bed else ""))
print(f"measured discharge rate {1e3 * w_measured:.2f} g/s (fit over {t[window][0]:.2f}-"
      f"{t[window][-1]:.2f} s" + (f"; the series starts at {t[0]:.3g} s" if t[0] > 0.2 else "")
      + ")")
print(f"Beverloo (C = 0.58, k = 1.5) {1e3 * w_beverloo:.2f} g/s; "
      f"ratio measured/Beverloo {w_measured / w_beverloo:.2f}; "
      f"Rose-Tanaka hopper factor {F:.2f} -> {1e3 * F * w_beverloo:.2f} g/s")

fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
a1.plot(t, 1e3 * mass, "o-", ms=3, label="DEM: mass in hopper")
a1.plot(t[window], 1e3 * (slope * t[window] + intercept), "k--", label=f"fit: {1e3 * w_measured:.1f} g/s")
a1.set_xlabel("t [s]")
a1.set_ylabel("mass above the orifice [g]")
a1.legend()
a2.plot(rate_t, 1e3 * rate, "o-", ms=3, label="DEM (between snapshots)")
a2.axhline(1e3 * w_beverloo, color="k", label="Beverloo C = 0.58, k = 1.5")
a2.axhspan(1e3 * w_beverloo * 0.50 / 0.58, 1e3 * w_beverloo * 0.63 / 0.58, color="k", alpha=0.1,
           label="Beverloo, C = 0.50-0.63")
a2.axhline(1e3 * F * w_beverloo, color="C3", ls=":", label=f"x Rose-Tanaka hopper factor {F:.2f}")
a2.set_xlabel("t [s]")
a2.set_ylabel("discharge rate [g/s]")
a2.set_ylim(bottom=0)
a2.legend(fontsize=8)
fig.suptitle(f"Conical hopper, D0 = 12 mm, d = {1e3 * d:.1f} mm, rho_b = {rho_b:.0f} kg/m3")
fig.tight_layout()
fig.savefig("hopper.png", dpi=120)
print("hopper.png written")
