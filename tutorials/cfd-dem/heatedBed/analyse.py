#!/usr/bin/env python3
"""Heated bubbling bed: the mean bead temperature against an energy-balance estimate.

usage: analyse.py [--short] [--tolerance F] [--log LOG ...] [CASE]

Reads, from the case folder CASE (default: this script's folder):
  log.grainFoam                     the thermal energies at every write time (`grainFoam
                                    thermal energy: particles E_p J (m c C_p J/K), fluid ...`):
                                    the mean bead temperature is E_p / C_p exactly; they must
                                    start at the run's start: for a restarted run give every
                                    piece of its log, oldest first (--log); a restart's log
                                    alone is refused, naming its start time;
  postProcessing/inletFlow          Q = -sum(phi) over the inlet, every fluid step;
  postProcessing/heatIn, heatOut    sum(phi T) over the inlet and the outlet, every fluid step;
  particles/particles_*.h5          the snapshots (picture);
  constant/transportProperties      rho, Cp.

Two references, both from the energy balance of the column (walls adiabatic):
  1. Conservation: the thermal energy of beads and air, E_p + E_f, grows by what the gas
     carries in minus what it carries out, rho c_p sum_steps dt (-sum_in phi T - sum_out phi T),
     to within the conduction through the inlet and outlet faces (not in the enthalpy flows:
     below 0.5 %). Checked to 1 % of the heat that came in.
  2. Energy-balance bounds on the mean bead temperature. The air enters with the enthalpy
     flow H_in(t) = -sum_in phi T at the volume flow Q(t) (both measured) and leaves the bed
     at the temperature of its top beads, which lies between T_0 and the beads' mean when
     the bed is at least as hot at the bottom as at the top (the bed's number of transfer
     units with Gunn's h is about 10: the air takes the beads' temperature). So, with the
     air's heat content in the bed neglected (about 1.5 % of m c),
       lower bound, a well-mixed bed:      m c dT/dt = rho c_p (H_in - Q T),
       upper bound, a stratified bed:      m c dT/dt = rho c_p (H_in - Q T_0), T <= T_in,
     each integrated over the fluid steps (implicit Euler). The mean bead temperature
     (E_p / (m c) from the log, exactly) must lie between them, within --tolerance (default
     0.01) of T_in - T_0, at every write time; where it lies says how mixed the bed is.
Exit status 1 if either fails. Plots: heatedBed.png (temperatures), heatedBed_particles.png
(beads coloured by temperature at the write time nearest to half-way heating); *_short*.png
with --short.
"""
import argparse
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
ap.add_argument("--short", action="store_true", help="the Allrun --short case")
ap.add_argument("--tolerance", type=float, default=None)
ap.add_argument("--log", nargs="+", metavar="LOG",
                help="grainFoam's logs of the run, oldest first: for a restarted run (whose "
                     "log.grainFoam starts at the restart) every piece, each restart's after "
                     "the log it continues (default: CASE/log.grainFoam)")
args = ap.parse_args()
case = args.case
if args.tolerance is None:
    args.tolerance = 0.01
plot_name = "heatedBed_short" if args.short else "heatedBed"


NUM = r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)"
ENERGY = re.compile(r"grainFoam thermal energy: particles " + NUM + r" J \(m c " + NUM +
                    r" J/K\), fluid " + NUM + r" J \(eps rho c_p V " + NUM + r" J/K\), sum " +
                    NUM + " J")
RESTART = re.compile(r"^grainFoam coupling: restart at time " + NUM, re.M)
TIME = re.compile(r"^Time = " + NUM + "$", re.M)


def energy_rows(path):
    """(rows [t, E_p, C_p, E_f, C_f, sum], restart time or None) of one grainFoam log; a log
    that starts with a restart (its `grainFoam coupling: restart at time` line before the
    first time step) dates the energy lines before its first `Time =` at the restart."""
    try:
        text = open(path).read()
    except OSError as e:
        sys.exit(f"analyse.py: cannot read {path}, grainFoam's log: {e.strerror or e}")
    times = [(m.start(), float(m.group(1))) for m in TIME.finditer(text)]
    restart = RESTART.search(text)
    if restart and times and restart.start() > times[0][0]:
        restart = None  # a restart later in the log: logs of two pieces joined into one
    start = float(restart.group(1)) if restart else 0.0
    rows = []
    for m in ENERGY.finditer(text):
        before = [t for pos, t in times if pos < m.start()]
        rows.append([before[-1] if before else start] + [float(x) for x in m.groups()])
    return rows, (start if restart else None)


# The energy balance starts from the thermal energies at the run's start: the log of a restart
# alone starts elsewhere. A restarted run's log comes in pieces, joined here oldest first.
# A --log name is taken as given, or else in the case folder.
logs = ([p if os.path.exists(p) else os.path.join(case, p) for p in args.log] if args.log
        else [os.path.join(case, "log.grainFoam")])
pieces = sorted(os.path.basename(p) for p in os.listdir(case) if p.startswith("log.grainFoam"))
rows = []
for i, path in enumerate(logs):
    piece, restart = energy_rows(path)
    if not piece:
        sys.exit(f"analyse.py: no `grainFoam thermal energy` lines in {path}")
    if i == 0 and restart is not None:
        sys.exit(f"analyse.py: {path} starts at t = {restart:g} s, the log of a restart "
                 f"(`grainFoam coupling: restart at time {restart:g}`): the energy balance "
                 "needs the thermal energies from the run's start, t = 0. Give every piece "
                 "of the run's log, oldest first: --log FIRST_LOG [...] "
                 f"{os.path.basename(path)} (logs in {case}: {', '.join(pieces)})")
    if i > 0:
        if restart is None:
            sys.exit(f"analyse.py: {path}, after {logs[i - 1]} in --log, is not a restart's "
                     "log (no `grainFoam coupling: restart at time` before its first time "
                     "step): give the logs of one run, oldest first")
        if restart > rows[-1][0] + 1e-9:
            sys.exit(f"analyse.py: {path} continues from t = {restart:g} s, and the log "
                     f"before it, {logs[i - 1]}, ends at t = {rows[-1][0]:g} s: the log of "
                     "the piece between them is missing from --log")
        rows = [r for r in rows if r[0] <= restart + 1e-9]  # a restart replaces what follows
    rows += piece
e = np.array(rows)   # t, E_p, C_p, E_f, C_f, sum
_, keep = np.unique(e[:, 0], return_index=True)
e = e[keep]

transport = f"{case}/constant/transportProperties"
rho_f = float(foam_entry(transport, "rho"))
cp_f = float(foam_entry(transport, "Cp"))
t_q, q, _ = series(case, "inletFlow")
t_hi, h_in, _ = series(case, "heatIn")
t_ho, h_out, _ = series(case, "heatOut")
n = min(len(t_q), len(t_hi), len(t_ho))
t, q, h_in, h_out = t_q[:n], -q[:n], -h_in[:n], h_out[:n]   # inflow positive
if e[0, 0] > t[0] + 1e-9:
    sys.exit(f"analyse.py: the thermal energies in {', '.join(logs)} start at t = "
             f"{e[0, 0]:g} s, the enthalpy flows (postProcessing/inletFlow) at t = {t[0]:g} s: "
             "the energy balance needs the energies from the run's start; give the log of "
             "every piece of the run with --log, oldest first")
dt = np.diff(np.concatenate(([0.0], t)))

# 1. Conservation: E(t) - E(0) against the enthalpy carried in minus out (Euler sums: the
# function objects run after each step's solve, as the implicit step's fluxes are).
carried = rho_f * cp_f * np.cumsum(dt * (h_in - h_out))
e0 = e[0, 5]
worst_cons = 0.0
for ti, *_, total in e:
    k = np.searchsorted(t, ti - 1e-9)
    if k < len(t) and abs(t[k] - ti) < 1e-6 and ti > 0:
        worst_cons = max(worst_cons, abs((total - e0) - carried[k]) / max(abs(carried[-1]), 1e-300))

# 2. Bounds: well-mixed bed (air leaving at the mean bead temperature) and stratified bed (air
# leaving at the initial temperature until the beads reach T_in); implicit Euler per step.
c_p = e[0, 2]
t0_beads = e[0, 1] / c_p
est = np.empty(n)
upper = np.empty(n)
temp = hot = t0_beads
for k in range(n):
    temp = (temp + dt[k] * rho_f * cp_f * h_in[k] / c_p) / (1 + dt[k] * rho_f * cp_f * q[k] / c_p)
    est[k] = temp
    hot = hot + dt[k] * rho_f * cp_f * (h_in[k] - q[k] * t0_beads) / c_p
    upper[k] = hot
t_in_final = h_in[-1] / q[-1] if q[-1] > 0 else float("nan")
upper = np.minimum(upper, t_in_final)
span = t_in_final - t0_beads
beads = e[:, 1] / e[:, 2]
estimate_at = np.interp(e[:, 0], t, est, left=t0_beads)
upper_at = np.interp(e[:, 0], t, upper, left=t0_beads)
below = float(np.max((estimate_at - beads) / span))
above = float(np.max((beads - upper_at) / span))
ok_est = below <= args.tolerance and above <= args.tolerance
heating = upper_at - estimate_at > 0.02 * span
where = (beads - estimate_at)[heating] / (upper_at - estimate_at)[heating]
ok_cons = worst_cons < 0.01
snaps = run_snapshots(f"{case}/particles")
with h5py.File(snaps[-1], "r") as f:
    n_beads, bead_mass = len(f["id"]), float(np.sum(f["mass"][:]))
    # Coarse-grained parcels (an insertion's coarse_grain): each stands for real_count beads.
    n_real = float(np.sum(f["real_count"][:])) if "real_count" in f else float(n_beads)
scene = yaml.safe_load(open(os.path.join(case, "particles.yaml")))   # the domain only
counted = f"{n_beads} beads" if n_real == n_beads else \
    f"{n_beads} parcels ({n_real:.0f} real beads)"
print(f"heatedBed: {counted}, m c = {c_p:.5g} J/K, inflow rho c_p Q = "
      f"{rho_f * cp_f * q[-1]:.4g} W/K (time constant {c_p / (rho_f * cp_f * q[-1]):.3f} s), "
      f"T_in {t_in_final:.1f} K")
print(f"  at t = {e[-1, 0]:.3f} s: mean bead temperature {beads[-1]:.2f} K, bounds "
      f"{estimate_at[-1]:.2f} K (well mixed) and {upper_at[-1]:.2f} K (stratified); below the "
      f"lower bound by at most {100 * max(below, 0):.2f} %, above the upper by at most "
      f"{100 * max(above, 0):.2f} % of T_in - T_0 (tolerance {100 * args.tolerance:g} %: "
      f"{'ok' if ok_est else 'FAILED'}); between them the beads sat at "
      f"{np.min(where) + 0.0 if where.size else float('nan'):.2f} to "
      f"{np.max(where) if where.size else float('nan'):.2f} of the way from well mixed to "
      f"stratified")
print(f"  energy of beads and air gained {e[-1, 5] - e0:.4f} J, carried in minus out "
      f"{carried[-1]:.4f} J: largest gap {100 * worst_cons:.3f} % of it (tolerance 1 %: "
      f"{'ok' if ok_cons else 'FAILED'})")

# --- plots ---------------------------------------------------------------------------------
fig, ax = plt.subplots(figsize=(8, 4.5))
with np.errstate(divide="ignore", invalid="ignore"):
    t_inlet = np.where(q > 1e-12, h_in / q, np.nan)
    t_outlet = np.where(h_out != 0, h_out / np.where(q > 1e-12, q, np.nan), np.nan)
ax.plot(t, t_inlet, color="tab:red", lw=1, label="air in (inlet)")
ax.plot(t, t_outlet, color="tab:orange", lw=0.8, label="air out (outlet, flow-weighted)")
ax.plot(t, est, color="k", ls="--", lw=1.2,
        label="lower bound: well-mixed bed (air leaves at the mean bead temperature)")
ax.plot(t, upper, color="k", ls=":", lw=1.2,
        label="upper bound: stratified bed (air leaves at the initial temperature)")
ax.plot(e[:, 0], beads, "o", ms=4, color="tab:blue", label="mean bead temperature (grainFoam)")
ax.plot(e[:, 0], e[:, 3] / e[:, 4], "s", ms=3, color="tab:green", label="mean air temperature")
ax.set_xlabel("time [s]")
ax.set_ylabel("temperature [K]")
ax.set_title(f"{counted} of glass (c = {c_p / bead_mass:.0f} J/(kg K)) fluidised by hot air",
             fontsize=10)
ax.legend(fontsize=7, loc="lower right")
fig.tight_layout()
fig.savefig(os.path.join(case, plot_name + ".png"), dpi=110)

if snaps:
    half = t0_beads + 0.5 * (beads[-1] - t0_beads)
    pick = snaps[-1]
    best = float("inf")
    for s in snaps:
        with h5py.File(s, "r") as f:
            if "temperature" in f:
                gap = abs(float(np.mean(f["temperature"][:])) - half)
                if gap < best:
                    best, pick = gap, s
    with h5py.File(pick, "r") as f:
        x, temp_p = f["position"][:], f["temperature"][:]
        d_p = f["diameter"][:] if "diameter" in f else 2 * f["radius"][:]
        t_pick = float(f.attrs["time"])
    lo, hi = np.array(scene["domain"]["min"], float), np.array(scene["domain"]["max"], float)
    z_top = min(hi[2], max(0.03, 1.3 * (np.percentile(x[:, 2], 99) + d_p.max())))
    fig, ax = plt.subplots(figsize=(6.4, 4.0 * (z_top - lo[2]) / (hi[0] - lo[0]) + 1.2), dpi=110)
    ax.set_xlim(lo[0] * 1e3, hi[0] * 1e3)
    ax.set_ylim(lo[2] * 1e3, z_top * 1e3)
    ax.set_aspect("equal")
    order = np.argsort(x[:, 1])
    sc = ax.scatter(x[order, 0] * 1e3, x[order, 2] * 1e3, s=1, c=temp_p[order], cmap="inferno",
                    edgecolors="none")
    fig.colorbar(sc, ax=ax, label="bead temperature [K]", shrink=0.8)
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("z [mm]")
    ax.set_title(f"t = {t_pick:.2f} s", fontsize=10)
    fig.tight_layout()
    fig.canvas.draw()
    ppm = (ax.transData.transform((1, 0))[0] - ax.transData.transform((0, 0))[0]) * 72 / fig.dpi
    sc.set_sizes((d_p[order] * 1e3 * ppm) ** 2)
    fig.savefig(os.path.join(case, plot_name + "_particles.png"), dpi=110)

sys.exit(0 if ok_cons and ok_est else 1)
