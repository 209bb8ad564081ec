#!/usr/bin/env python3
"""Million-bead fluidised bed (parcels): pressure drop against the bed weight, minimum
fluidisation against Ergun and Wen-Yu for the real beads, bed height, cost.

usage: analyse.py [--short] [--from T] [--tolerance F] [CASE]

Reads, from the case folder CASE (default: this script's folder):
  postProcessing/pInlet, pOutlet   area-averaged kinematic pressure p on the inlet and
                                    outlet patches every fluid step (controlDict functions);
  postProcessing/inletFlow          sum of phi over the inlet (the superficial inflow);
  particles/particles_*.h5          parcel snapshots (diameter, mass, coarse_grain k,
                                    real_count k^3) at the write times;
  log.grainFoam                     the closing time split (wall and CPU seconds);
  constant/transportProperties      rho, nu;  the scene named in constant/couplingProperties.

Reference values (DESIGN.md section 7), all for the REAL beads (d = parcel diameter / k):
  bed weight per area   dp_w = sum V_parcel (rho_p - rho_f) g / A  (a parcel's volume is k^3
                        real volumes: the real bed's weight)
  Wen & Yu (1966)       Re_mf = sqrt(33.7^2 + 0.0408 Ar) - 33.7,  Ar = g rho_f (rho_p - rho_f) d^3 / mu^2
  Ergun (1952)          dp/L = 150 mu U (1-e)^2 / (e^3 d^2) + 1.75 rho_f U^2 (1-e) / (e^3 d);
                        U_mf where dp/L = (1-e)(rho_p - rho_f) g, with the settled bed's e
  the drag law's own packed bed (di_felice, VANS model A): dp/L = n F(U/e) / e, n = (1-e)/V_bead,
                        and its U_mf the same way (the coupling's error apart from the law's)
with d the Sauter mean diameter of the real beads. p excludes hydrostatics, so
dp = rho_f (p_inlet - p_outlet) is the bed's share alone. The measured U_mf is where the
fitted packed-bed curve dp = a U + b U^2 (ramp samples below 0.7 dp_w) meets dp_w.
The time average of dp from --from (default 0.7 s) to the end must lie within --tolerance
(default 0.05) of dp_w; the exit status is 1 otherwise. Plots: largeBed.png (dp and bed
height over time), largeBed_fluidisation.png (dp against U_s), largeBed_particles.png.
--short (the Allrun --short case, to 0.8 s): --from 0.6 --tolerance 0.10, plots
largeBed_short*.png.
"""
import argparse
import math
import os
import re
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import yaml

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from foam_case import foam_entry, series  # noqa: E402 (tutorials/cfd-dem/foam_case.py)

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
from run_index import run_snapshots  # noqa: E402 (tutorials/run_index.py)

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("case", nargs="?", default=os.path.dirname(os.path.abspath(__file__)))
ap.add_argument("--short", action="store_true",
                help="the Allrun --short case: --from 0.6 --tolerance 0.10, plots *_short*.png")
ap.add_argument("--from", dest="t_from", type=float, default=None,
                help="start of the time average [s] (default 0.7; 0.6 with --short)")
ap.add_argument("--tolerance", type=float, default=None,
                help="allowed relative gap between mean dp and the bed weight (default 0.05; "
                     "0.10 with --short)")
args = ap.parse_args()
case = args.case
if args.t_from is None:
    args.t_from = 0.6 if args.short else 0.7
if args.tolerance is None:
    args.tolerance = 0.10 if args.short else 0.05
plot_name = "largeBed_short" if args.short else "largeBed"


# --- fluid, parcels, geometry -------------------------------------------------------------
transport = f"{case}/constant/transportProperties"
rho_f = float(foam_entry(transport, "rho"))
mu = rho_f * float(foam_entry(transport, "nu"))
scene_file = os.path.join(case, foam_entry(f"{case}/constant/couplingProperties", "scene"))
scene = yaml.safe_load(open(scene_file))
g = float(np.linalg.norm(scene.get("gravity", [0, 0, 0])))
lo, hi = np.array(scene["domain"]["min"], float), np.array(scene["domain"]["max"], float)

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
        # Bed height: the level below which 95 % of the parcel centres lie (robust to the
        # few parcels that bursting bubbles throw up).
        heights.append(np.percentile(f["position"][:, 2], 95))
snap_t, heights = np.array(snap_t), np.array(heights)


def load(path):
    with h5py.File(path, "r") as f:
        return {key: f[key][:] for key in ("position", "velocity", "diameter", "mass",
                                           "coarse_grain", "real_count")} | \
            {"time": float(f.attrs["time"])}


last = load(snaps[-1])
x, v, d_parcel, m_p = last["position"], last["velocity"], last["diameter"], last["mass"]
k, real_count = last["coarse_grain"], last["real_count"]
d_real = d_parcel / k
v_parcel = math.pi / 6 * d_parcel**3
rho_p = m_p / v_parcel
weight = np.sum(v_parcel * (rho_p - rho_f)) * g / area  # [Pa]
n_real = int(round(real_count.sum()))
d32 = np.sum(real_count * d_real**3) / np.sum(real_count * d_real**2)
rho_pm = np.sum(m_p) / np.sum(v_parcel)
ar = g * rho_f * (rho_pm - rho_f) * d32**3 / mu**2
re_mf = math.sqrt(33.7**2 + 0.0408 * ar) - 33.7
u_mf_wy = re_mf * mu / (rho_f * d32)

# --- the settled bed (last snapshot before the inflow starts) and Ergun ----------------------
t_on = t[np.argmax(u_s > 1e-9)] if np.any(u_s > 1e-9) else t[-1]
settled_index = np.nonzero(snap_t <= t_on + 1e-9)[0]
settled_index = settled_index[-1] if len(settled_index) else 0
settled = load(snaps[settled_index])
z = settled["position"][:, 2]
h_settled = heights[settled_index]
# Void fraction of the bed's core: parcel volume with centres between 3 parcel diameters
# above the distributor and 3 below the 95 % level, over that slab's volume.
dmax = settled["diameter"].max()
z1, z2 = 3 * dmax, h_settled - 3 * dmax
inside = (z >= z1) & (z < z2)
eps = 1 - np.sum(math.pi / 6 * settled["diameter"][inside] ** 3) / (area * (z2 - z1))
# Ergun at minimum fluidisation (per bed length): a U + b U^2 = (1 - eps)(rho_p - rho_f) g.
a_e = 150 * mu * (1 - eps) ** 2 / (eps**3 * d32**2)
b_e = 1.75 * rho_f * (1 - eps) / (eps**3 * d32)
c_e = (1 - eps) * (rho_pm - rho_f) * g
u_mf_ergun = (-a_e + math.sqrt(a_e**2 + 4 * b_e * c_e)) / (2 * b_e)


def di_felice_gradient(u_sup):
    """-dp/dx [Pa/m] of a packed bed of the real beads at superficial velocity u_sup under the
    case's own drag law, Di Felice (1994) as dem/fluid/di_felice.hpp writes it: per bead
    F = K U, K = (pi/8) rho_f d^2 eps^(2-chi) (0.63 sqrt(U) + 4.8 sqrt(mu/(rho_f eps d)))^2,
    U = u_sup/eps the interstitial slip, chi = 3.7 - 0.65 exp(-(1.5 - log10 Re)^2/2),
    Re = rho_f eps d U/mu; with VANS model A the fluid carries n F / eps per volume."""
    u = u_sup / eps
    re = rho_f * eps * d32 * u / mu
    chi = 3.7 - 0.65 * math.exp(-0.5 * (1.5 - math.log10(re)) ** 2) if re > 0 else 3.7
    root = 0.63 * math.sqrt(u) + 4.8 * math.sqrt(mu / (rho_f * eps * d32))
    force = math.pi / 8 * rho_f * d32**2 * eps ** (2 - chi) * root**2 * u
    return (1 - eps) / (math.pi / 6 * d32**3) * force / eps


lo_u, hi_u = 1e-6, 10.0  # U_mf of the drag law: its packed-bed gradient = (1 - eps)(rho_p - rho_f) g
for _ in range(200):
    mid = 0.5 * (lo_u + hi_u)
    lo_u, hi_u = (mid, hi_u) if di_felice_gradient(mid) < c_e else (lo_u, mid)
u_mf_df = 0.5 * (lo_u + hi_u)
# Measured: packed-bed part of the ramp (inflow rising, dp below 0.7 of the weight).
ramp = (u_s > 1e-9) & (u_s < u_s.max() - 1e-9) & (dp < 0.7 * weight) & (t <= t[np.argmax(u_s)])
if ramp.sum() >= 5:
    A = np.column_stack([u_s[ramp], u_s[ramp] ** 2])
    (a_m, b_m), *_ = np.linalg.lstsq(A, dp[ramp], rcond=None)
    u_mf_meas = ((-a_m + math.sqrt(a_m**2 + 4 * b_m * weight)) / (2 * b_m) if b_m != 0
                 else weight / a_m)
else:
    a_m = b_m = u_mf_meas = float("nan")

# --- the check ---------------------------------------------------------------------------
window = t >= args.t_from - 1e-9
if window.sum() < 10:
    sys.exit(f"analyse.py: fewer than 10 pressure samples after --from {args.t_from} s "
             f"(the run ends at {t[-1]:.3f} s)")
dp_mean = dp[window].mean()
dp_std = dp[window].std()
ratio = dp_mean / weight
u_final = u_s[window].mean()
h_fluid = heights[snap_t >= args.t_from - 1e-9].mean() if np.any(snap_t >= args.t_from) else float("nan")
ok = abs(ratio - 1) <= args.tolerance

# Cost: grainFoam's closing time split (wall and CPU seconds, the slowest rank).
cost = ""
log = os.path.join(case, "log.grainFoam")
if os.path.exists(log):
    text = open(log).read()
    wall = re.findall(r"^grainFoam time split: DEM ([\d.e+-]+) s .*coupling ([\d.e+-]+) s .*fluid "
                       r"([\d.e+-]+) s", text, re.M)
    cpu = re.findall(r"^grainFoam CPU time split: DEM ([\d.e+-]+) s .*coupling ([\d.e+-]+) s .*fluid "
                     r"([\d.e+-]+) s", text, re.M)
    ranks = re.findall(r"^nProcs : (\d+)", text, re.M)
    if wall and cpu:
        w, c = [float(s) for s in wall[-1]], [float(s) for s in cpu[-1]]
        cost = (f"; cost per simulated second ({ranks[0] if ranks else 1} rank(s), {t[-1]:.2f} s): "
                f"wall {sum(w)/t[-1]:.0f} s, CPU {sum(c)/t[-1]:.0f} s per rank "
                f"(DEM {100*c[0]/sum(c):.0f} %, coupling {100*c[1]/sum(c):.0f} %, "
                f"fluid {100*c[2]/sum(c):.0f} %)")

print(f"largeBed: {len(d_parcel)} parcels of k = {np.unique(k).round(6).tolist()} stand for "
      f"{n_real} real beads d32 {d32*1e3:.3f} mm; U_mf Wen-Yu {u_mf_wy:.3f} m/s, Ergun "
      f"(settled eps {eps:.3f}) {u_mf_ergun:.3f} m/s, the drag law's (di_felice) packed bed "
      f"{u_mf_df:.3f} m/s, measured {u_mf_meas:.3f} m/s; "
      f"U_s {u_final:.3f} m/s = {u_final/u_mf_wy:.2f} U_mf(Wen-Yu); mean dp over "
      f"{args.t_from:g}-{t[-1]:.3g} s {dp_mean:.1f} Pa (std {100*dp_std/dp_mean:.1f} %), bed weight "
      f"{weight:.1f} Pa, ratio {ratio:.4f} (tolerance {100*args.tolerance:g} %: "
      f"{'ok' if ok else 'FAILED'}); bed height settled {h_settled*1e3:.1f} mm, fluidised "
      f"{h_fluid*1e3:.1f} mm{cost}")

# --- plots ---------------------------------------------------------------------------------
title = f"{n_real:,} glass beads (d = {d32*1e3:.2f} mm) as {len(d_parcel):,} parcels, k = {k.max():g}"
fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
a1.plot(t, dp, lw=0.4, color="tab:blue", alpha=0.6, label="Δp inlet–outlet (every fluid step)")
w = max(1, int(round(0.05 / np.median(np.diff(t)))))
if len(dp) > w:
    a1.plot(t[w - 1:], np.convolve(dp, np.ones(w) / w, mode="valid"), color="tab:blue", lw=1.5,
            label="running mean over 0.05 s")
a1.axhline(weight, color="k", ls="--", label=f"bed weight Σ V_parcel (ρ_p−ρ_f) g / A = {weight:.0f} Pa")
a1.axhspan(weight * (1 - args.tolerance), weight * (1 + args.tolerance), color="k", alpha=0.08)
a1.axvspan(args.t_from, t[-1], color="tab:green", alpha=0.08)
a1.plot([args.t_from, t[-1]], [dp_mean, dp_mean], color="tab:green", lw=2,
        label=f"mean {dp_mean:.0f} Pa = {ratio:.3f} × weight")
a1.set_ylabel("Δp [Pa]")
a1.set_ylim(0, 1.6 * weight)
a1.legend(loc="lower right", fontsize=8)
a1.set_title(title, fontsize=10)
b1 = a1.twinx()
b1.plot(t, u_s / u_mf_wy, color="tab:red", lw=1)
b1.set_ylabel("U_s / U_mf (Wen–Yu)", color="tab:red")
b1.set_ylim(0, 2.5 * max(1e-9, np.max(u_s / u_mf_wy)))
b1.tick_params(axis="y", colors="tab:red")
a2.plot(snap_t, heights * 1e3, "o-", ms=3, color="tab:brown", label="95 % of parcel centres below")
a2.set_xlabel("time [s]")
a2.set_ylabel("bed height [mm]")
a2.set_ylim(0, None)
a2.legend(loc="lower right", fontsize=8)
fig.tight_layout()
fig.savefig(os.path.join(case, plot_name + ".png"), dpi=110)

# The fluidisation curve: dp against the superficial velocity, with Ergun for the real beads.
fig, ax = plt.subplots(figsize=(7, 4.5))
rising = t <= t[np.argmax(u_s)] + 1e-9
ax.plot(u_s[rising], dp[rising], ".", ms=2, color="tab:blue", label="ramp (inflow rising)")
ax.plot(u_s[window], dp[window], ".", ms=2, color="tab:green", alpha=0.4,
        label=f"after {args.t_from:g} s (bubbling)")
uu = np.linspace(0, u_s.max(), 200)
ax.plot(uu, (a_e * uu + b_e * uu**2) * weight / c_e, "k-", lw=1,  # L = weight / c_e
        label=f"Ergun, real d32 and settled ε = {eps:.3f}")
ax.plot(uu, [di_felice_gradient(u) * weight / c_e for u in uu], "-", color="tab:purple", lw=1,
        label="the drag law's own packed bed (di_felice, real d32, ε)")
if np.isfinite(u_mf_meas):
    ax.plot(uu, a_m * uu + b_m * uu**2, "--", color="tab:blue", lw=1, label="fit of the ramp below 0.7 × weight")
ax.axhline(weight, color="k", ls="--", lw=1, label="bed weight")
for i, (u, name, col) in enumerate(((u_mf_wy, "Wen–Yu", "tab:red"), (u_mf_ergun, "Ergun", "k"),
                                    (u_mf_df, "di_felice", "tab:purple"),
                                    (u_mf_meas, "measured", "tab:blue"))):
    if np.isfinite(u):
        ax.axvline(u, color=col, ls=":", lw=1)
        ax.text(u, (1.45 - 0.12 * i) * weight, f" U_mf {name} {u:.3f}", color=col, fontsize=7,
                va="top")
ax.set_xlim(0, 1.05 * u_s.max())
ax.set_ylim(0, 1.5 * weight)
ax.set_xlabel("superficial velocity U_s [m/s]")
ax.set_ylabel("Δp [Pa]")
ax.set_title(title, fontsize=10)
ax.legend(loc="lower right", fontsize=7)
fig.tight_layout()
fig.savefig(os.path.join(case, plot_name + "_fluidisation.png"), dpi=110)

# Front view of the last snapshot, parcels drawn to scale, the front ones (largest y) last.
z_top = min(hi[2], max(1.2 * (np.max(x[:, 2]) + d_parcel.max()), 1.5 * h_fluid if np.isfinite(h_fluid) else 0))
width_in = 3.6
fig, ax = plt.subplots(figsize=(width_in + 1.6, width_in * (z_top - lo[2]) / (hi[0] - lo[0]) + 0.9),
                       dpi=110)
ax.set_xlim(lo[0] * 1e3, hi[0] * 1e3)
ax.set_ylim(lo[2] * 1e3, z_top * 1e3)
ax.set_aspect("equal")
order = np.argsort(x[:, 1])
speed = np.linalg.norm(v, axis=1)
sc = ax.scatter(x[order, 0] * 1e3, x[order, 2] * 1e3, s=1, c=speed[order], cmap="viridis",
                vmin=0, vmax=np.percentile(speed, 99), edgecolors="none")
fig.colorbar(sc, ax=ax, label="parcel speed [m/s]", shrink=0.8)
ax.set_xlabel("x [mm]")
ax.set_ylabel("z [mm]")
ax.set_title(f"t = {last['time']:.2f} s, U_s = {u_final/u_mf_wy:.1f} U_mf; parcels to scale", fontsize=9)
fig.tight_layout()
fig.canvas.draw()
points_per_mm = (ax.transData.transform((1, 0))[0] - ax.transData.transform((0, 0))[0]) * 72 / fig.dpi
sc.set_sizes((d_parcel[order] * 1e3 * points_per_mm) ** 2)
fig.savefig(os.path.join(case, plot_name + "_particles.png"), dpi=110)

sys.exit(0 if ok else 1)
