#!/usr/bin/env python3
"""Tables and plots of the coupled sweeps (coupled_sweeps.py's CSV).

Usage: plot_coupled.py RESULTS.csv OUT_DIR
Writes OUT_DIR/accuracy_cost_void_fraction.png, OUT_DIR/accuracy_cost_interval.png and prints
the markdown tables for docs/accuracy-vs-cost-coupled.md.
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

rows = list(csv.DictReader(open(sys.argv[1])))
# Particles and DEM step of each sweep (coupled_sweeps.py): the bed has 3300 beads, the
# settling case one; the DEM step is 1e-5 s throughout.
PARTICLES = {"void_fraction": 3300, "interval_bed": 3300, "interval_settling": 1}
DT_DEM = 1e-5


def per_particle_step(r):
    """Total CPU microseconds per particle-step (DEM steps x particles)."""
    return 1e6 * r["cpu_s"] / (PARTICLES[r["sweep"]] * r["sim_seconds"] / DT_DEM)


out = sys.argv[2]
for r in rows:
    for k in ("cell_over_d", "steps_per_fluid", "measured", "reference", "error", "sim_seconds",
              "dem_s", "coupling_s", "fluid_s", "cpu_s"):
        r[k] = float(r[k])

# --- void fraction x sampling x cell size ----------------------------------------------
vf = [r for r in rows if r["sweep"] == "void_fraction"]
print("| footprint | sampling | cell / d | Δp error vs Ergun | coupling s per simulated s | total CPU s per simulated s | total CPU µs per particle-step |")
print("|---|---|---|---|---|---|---|")
for r in sorted(vf, key=lambda r: (r["method"], r["sampling"], r["cell_over_d"])):
    print(f"| {r['method']} | {r['sampling']} | {r['cell_over_d']:g} | {100 * r['error']:+.1f} % | "
          f"{r['coupling_s'] / r['sim_seconds']:.1f} | {r['cpu_s'] / r['sim_seconds']:.0f} | "
          f"{per_particle_step(r):.2f} |")
fig, ax = plt.subplots(figsize=(6.5, 4.5))
for method, marker in (("centre", "s"), ("divided", "o"), ("smoothed", "^")):
    for sampling, ls in (("cell", "-"), ("cellPoint", "--")):
        pts = sorted((r["cell_over_d"], r) for r in vf if r["method"] == method and r["sampling"] == sampling)
        if not pts:
            continue
        ax.plot([r["coupling_s"] / r["sim_seconds"] for _, r in pts],
                [100 * abs(r["error"]) for _, r in pts], ls, marker=marker,
                label=f"{method}, {sampling}")
        for c, r in pts:
            ax.annotate(f"{c:g}d", (r["coupling_s"] / r["sim_seconds"], 100 * abs(r["error"])),
                        fontsize=7, xytext=(3, 3), textcoords="offset points")
ax.set_xscale("log")
ax.set_yscale("log")
ax.set_xlabel("coupling CPU seconds per simulated second")
ax.set_ylabel("|Δp error| vs Ergun [%]")
ax.set_title("Fixed bed, 3300 beads: footprint, sampling, cell size (labels: cell / d)")
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(os.path.join(out, "accuracy_cost_void_fraction.png"), dpi=120)

# --- coupling interval ------------------------------------------------------------------
print()
print("| case | DEM steps per fluid step | error | total CPU s per simulated s | total CPU µs per particle-step | fluid share |")
print("|---|---|---|---|---|---|")
fig, ax = plt.subplots(figsize=(6.5, 4.5))
for sweep, label in (("interval_settling", "settling sphere: u_t vs Schiller-Naumann"),
                     ("interval_bed", "fixed bed: Δp vs Ergun")):
    pts = sorted((r["steps_per_fluid"], r) for r in rows if r["sweep"] == sweep)
    for n, r in pts:
        share = r["fluid_s"] / max(r["dem_s"] + r["coupling_s"] + r["fluid_s"], 1e-12)
        print(f"| {label.split(':')[0]} | {n:g} | {100 * r['error']:+.2f} % | "
              f"{r['cpu_s'] / r['sim_seconds']:.0f} | {per_particle_step(r):.2f} | {100 * share:.0f} % |")
    ax.plot([r["cpu_s"] / r["sim_seconds"] for _, r in pts], [100 * abs(r["error"]) for _, r in pts],
            "o-", label=label)
    for n, r in pts:
        ax.annotate(f"N={n:g}", (r["cpu_s"] / r["sim_seconds"], 100 * abs(r["error"])), fontsize=7,
                    xytext=(3, 3), textcoords="offset points")
ax.set_xscale("log")
ax.set_yscale("log")
ax.set_xlabel("total CPU seconds per simulated second")
ax.set_ylabel("|error| [%]")
ax.set_title("Coupling interval N = dt_CFD / dt_DEM")
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(os.path.join(out, "accuracy_cost_interval.png"), dpi=120)
