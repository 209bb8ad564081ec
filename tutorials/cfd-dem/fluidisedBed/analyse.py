#!/usr/bin/env python3
"""Fluidised-bed analysis: bed pressure drop against the bed's buoyant weight.

usage: analyse.py [--short] [--from T] [--tolerance F] [CASE]

Reads, from the case folder CASE (default: this script's folder):
  postProcessing/pInlet, pOutlet   area-averaged kinematic pressure p on the inlet and
                                    outlet patches every fluid step (controlDict functions);
  postProcessing/inletFlow          sum of phi over the inlet (the superficial inflow);
  particles/particles_*.h5          particle snapshots at the write times;
  log.grainFoam                     the walls' share of the weight (output.wall_loads);
  constant/transportProperties      rho, nu;  the scene named in constant/couplingProperties.

Reference values (DESIGN.md section 7):
  bed weight per area   dp_w = N V_p (rho_p - rho_f) g / A            (the plateau above U_mf)
  Wen & Yu (1966)       Re_mf = sqrt(33.7^2 + 0.0408 Ar) - 33.7,  Ar = g rho_f (rho_p - rho_f) d^3 / mu^2
with d the Sauter mean diameter of the beads. p excludes hydrostatics, so
dp = rho_f (p_inlet - p_outlet) is the bed's share alone (the air column's rho_f g H is
not in it). The time average of dp from --from (default 0.5 s: 0.2 s after the inflow has
reached its final value) to the end must lie within --tolerance (default 0.05) of dp_w;
the exit status is 1 otherwise. Plots: fluidisedBed.png, fluidisedBed_particles.png.
--short (the Allrun --short case, 2000 beads to 0.6 s): --from 0.4 --tolerance 0.10, and
the plots are called fluidisedBed_short*.png.
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
import yaml

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# tutorials/cfd-dem/foam_case.py
from foam_case import foam_entry, mean_wall_share, series  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
from run_index import run_snapshots  # noqa: E402 (tutorials/run_index.py)

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("case", nargs="?", default=os.path.dirname(os.path.abspath(__file__)))
ap.add_argument("--short", action="store_true",
                help="the Allrun --short case: --from 0.4 --tolerance 0.10, plots *_short*.png")
ap.add_argument("--from", dest="t_from", type=float, default=None,
                help="start of the time average [s] (default 0.5; 0.4 with --short)")
ap.add_argument("--tolerance", type=float, default=None,
                help="allowed relative gap between mean dp and the bed weight (default 0.05; "
                     "0.10 with --short)")
args = ap.parse_args()
case = args.case
if args.t_from is None:
    args.t_from = 0.4 if args.short else 0.5
if args.tolerance is None:
    args.tolerance = 0.10 if args.short else 0.05
plot_name = "fluidisedBed_short" if args.short else "fluidisedBed"


# --- fluid, beads, geometry ------------------------------------------------------------
if not os.path.isdir(case):
    sys.exit(f"analyse.py: no case folder {case}")
for needed in ("constant/transportProperties", "constant/couplingProperties"):
    if not os.path.isfile(os.path.join(case, needed)):
        sys.exit(f"analyse.py: no {os.path.join(case, needed)}: {case} is not a grainFoam case "
                 "folder (give the fluidisedBed case folder)")
transport = f"{case}/constant/transportProperties"
rho_f = float(foam_entry(transport, "rho"))
mu = rho_f * float(foam_entry(transport, "nu"))
scene_file = os.path.join(case, foam_entry(f"{case}/constant/couplingProperties", "scene"))
try:
    with open(scene_file) as f:
        scene = yaml.safe_load(f)
except OSError as e:
    sys.exit(f"analyse.py: cannot read {scene_file}, the scene constant/couplingProperties "
             f"names: {e.strerror or e}")
g = float(np.linalg.norm(scene.get("gravity", [0, 0, 0])))

t_in, p_in, area = series(case, "pInlet")
t_out, p_out, _ = series(case, "pOutlet")
t_q, q_in, _ = series(case, "inletFlow")
n = min(len(t_in), len(t_out), len(t_q))
t, dp = t_in[:n], rho_f * (p_in[:n] - p_out[:n])  # [Pa]
u_s = -q_in[:n] / area  # superficial inflow [m/s]; phi < 0 enters the domain

snaps = run_snapshots(f"{case}/particles")
heights, snap_t = [], []
for s in snaps:
    with h5py.File(s, "r") as f:
        snap_t.append(float(f.attrs["time"]))
        # Bed height: the level below which 95 % of the beads' centres lie (robust to the
        # few beads that bursting bubbles throw up).
        heights.append(np.percentile(f["position"][:, 2], 95))
snap_t, heights = np.array(snap_t), np.array(heights)
with h5py.File(snaps[-1], "r") as f:
    x, v = f["position"][:], f["velocity"][:]
    d_p, m_p = f["diameter"][:], f["mass"][:]
    t_last = float(f.attrs["time"])

v_p = math.pi / 6 * d_p**3
rho_p = m_p / v_p
weight = np.sum(v_p * (rho_p - rho_f)) * g / area  # [Pa]
d32 = np.sum(d_p**3) / np.sum(d_p**2)
rho_pm = np.sum(m_p) / np.sum(v_p)
ar = g * rho_f * (rho_pm - rho_f) * d32**3 / mu**2
re_mf = math.sqrt(33.7**2 + 0.0408 * ar) - 33.7
u_mf = re_mf * mu / (rho_f * d32)

# --- the check ---------------------------------------------------------------------------
window = t >= args.t_from - 1e-9
if window.sum() < 10:
    sys.exit(f"analyse.py: fewer than 10 pressure samples after --from {args.t_from} s "
             f"(the run ends at {t[-1]:.3f} s)")
dp_mean = dp[window].mean()
ratio = dp_mean / weight
u_final = u_s[window].mean()
settle = snap_t <= t[np.argmax(u_s > 1e-9)] + 1e-9 if np.any(u_s > 1e-9) else snap_t <= snap_t[-1]
h_settled = heights[settle][-1] if np.any(settle) else float("nan")
h_fluid = heights[snap_t >= args.t_from - 1e-9].mean() if np.any(snap_t >= args.t_from) else float("nan")
ok = abs(ratio - 1) <= args.tolerance

print(f"fluidisedBed: {len(d_p)} beads d32 {d32*1e3:.3f} mm, U_mf (Wen-Yu) {u_mf:.3f} m/s, "
      f"U_s {u_final:.3f} m/s = {u_final/u_mf:.2f} U_mf; mean dp over {args.t_from:g}-{t[-1]:.3g} s "
      f"{dp_mean:.1f} Pa, bed weight {weight:.1f} Pa, ratio {ratio:.4f} "
      f"(tolerance {100*args.tolerance:g} %: {'ok' if ok else 'FAILED'}); bed height settled "
      f"{h_settled*1e3:.1f} mm, fluidised {h_fluid*1e3:.1f} mm")
# The rest of the weight rests on the walls (particles.yaml output.wall_loads: grainFoam's
# `wall loads` lines): the distributor where beads lie on it, the side walls by friction.
walls, span = mean_wall_share(os.path.join(case, "log.grainFoam"), args.t_from)
if span > 0:
    print(f"fluidisedBed: the walls carry {walls:.4f} of the weight over the {span:.3g} s of "
          f"write intervals after {args.t_from:g} s (grainFoam's wall loads); gas and walls "
          f"together {ratio + walls:.4f}")

# --- plots ---------------------------------------------------------------------------------
fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
a1.plot(t, dp, lw=0.4, color="tab:blue", alpha=0.6, label="Δp inlet–outlet (every fluid step)")
w = max(1, int(round(0.05 / np.median(np.diff(t)))))
if len(dp) > w:
    a1.plot(t[w - 1:], np.convolve(dp, np.ones(w) / w, mode="valid"), color="tab:blue", lw=1.5,
            label="running mean over 0.05 s")
a1.axhline(weight, color="k", ls="--", label=f"bed weight N V_p (ρ_p−ρ_f) g / A = {weight:.0f} Pa")
a1.axhspan(weight * (1 - args.tolerance), weight * (1 + args.tolerance), color="k", alpha=0.08)
a1.axvspan(args.t_from, t[-1], color="tab:green", alpha=0.08)
a1.plot([args.t_from, t[-1]], [dp_mean, dp_mean], color="tab:green", lw=2,
        label=f"mean {dp_mean:.0f} Pa = {ratio:.3f} × weight")
a1.set_ylabel("Δp [Pa]")
a1.set_ylim(0, 1.6 * weight)
a1.legend(loc="lower right", fontsize=8)
a1.set_title(f"{len(d_p)} glass beads (d = {d32*1e3:.2f} mm) in air")
b1 = a1.twinx()
b1.plot(t, u_s / u_mf, color="tab:red", lw=1)
b1.set_ylabel("U_s / U_mf (Wen–Yu)", color="tab:red")
b1.set_ylim(0, 2.5 * max(1e-9, np.max(u_s / u_mf)))  # keeps the line off the weight line
b1.tick_params(axis="y", colors="tab:red")
a2.plot(snap_t, heights * 1e3, "o-", ms=3, color="tab:brown", label="95 % of bead centres below")
a2.set_xlabel("time [s]")
a2.set_ylabel("bed height [mm]")
a2.set_ylim(0, None)
a2.legend(loc="lower right", fontsize=8)
fig.tight_layout()
fig.savefig(os.path.join(case, plot_name + ".png"), dpi=110)

# Front view of the last snapshot, beads drawn to scale, the front ones (largest y) last.
lo, hi = np.array(scene["domain"]["min"], float), np.array(scene["domain"]["max"], float)
z_top = min(hi[2], max(1.2 * (np.max(x[:, 2]) + d_p.max()), 1.5 * h_fluid if np.isfinite(h_fluid) else 0))
width_in = 3.2  # axes width; the height follows the column's aspect
fig, ax = plt.subplots(figsize=(width_in + 1.6, width_in * (z_top - lo[2]) / (hi[0] - lo[0]) + 0.9),
                       dpi=110)
ax.set_xlim(lo[0] * 1e3, hi[0] * 1e3)
ax.set_ylim(lo[2] * 1e3, z_top * 1e3)
ax.set_aspect("equal")
order = np.argsort(x[:, 1])
speed = np.linalg.norm(v, axis=1)
sc = ax.scatter(x[order, 0] * 1e3, x[order, 2] * 1e3, s=1, c=speed[order], cmap="viridis",
                vmin=0, vmax=np.percentile(speed, 99), edgecolors="none")
fig.colorbar(sc, ax=ax, label="bead speed [m/s]", shrink=0.8)
ax.set_xlabel("x [mm]")
ax.set_ylabel("z [mm]")
ax.set_title(f"t = {t_last:.2f} s, U_s = {u_final/u_mf:.1f} U_mf", fontsize=10)
fig.tight_layout()
fig.canvas.draw()  # fixes the axes box (equal aspect), hence the scale mm -> points
points_per_mm = (ax.transData.transform((1, 0))[0] - ax.transData.transform((0, 0))[0]) * 72 / fig.dpi
sc.set_sizes((d_p[order] * 1e3 * points_per_mm) ** 2)
fig.savefig(os.path.join(case, plot_name + "_particles.png"), dpi=110)

sys.exit(0 if ok else 1)
