#!/usr/bin/env python3
"""Pour-and-settle analysis: kinetic energy decay and the settled solid fraction.

The solid fraction is measured in a core region away from the floor and the side
walls (wall layers are looser), from the last snapshot, and compared with the
packing range of frictional, monodisperse-like spheres: random loose packing
~0.55-0.60 (Onoda & Liniger 1990, PRL 64:2727) up to random close packing ~0.64
(Scott & Kilgour 1969). With friction 0.5 a poured bed sits near the loose end.
"""
import math
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
from run_index import log_columns, run_snapshots  # noqa: E402 (tutorials/run_index.py)

out = sys.argv[1] if len(sys.argv) > 1 else "output"
if not os.path.isdir(out):
    sys.exit(f"analyse.py: no output folder {out} (run ./Allrun first, or give the folder "
             "`grain run` wrote)")
# The complete rows only: a last row cut short (a killed run, or a log read while the run
# writes it) may have lost digits of its last field, e.g. the exponent of ke_rot_J.
log = log_columns(out, "time_s", "ke_trans_J", "ke_rot_J")
t = np.array(log["time_s"])
ke = np.array(log["ke_trans_J"]) + np.array(log["ke_rot_J"])

last = run_snapshots(out)[-1]
with h5py.File(last, "r") as f:
    x = f["position"][:]
    r = f["radius"][:]
top = np.max(x[:, 2] + r)
# Core: 4 mm from side walls, 3 mm above the floor, 3 mm below the free surface.
lo = np.array([0.004, 0.004, 0.003])
hi = np.array([0.036, 0.036, top - 0.003])
vol = np.prod(hi - lo)
# Exact sphere-slab volumes would be overkill: count each sphere's volume by the
# fraction of a 9x9x9 sub-grid of points inside the core (error << 1 %).
g = (np.arange(9) + 0.5) / 9 * 2 - 1
sub = np.array([(a, b, c) for a in g for b in g for c in g if a * a + b * b + c * c <= 1])
solid = 0.0
for xi, ri in zip(x, r):
    pts = xi + ri * sub
    inside = np.all((pts >= lo) & (pts <= hi), axis=1).mean()
    solid += inside * 4 / 3 * math.pi * ri**3
phi = solid / vol
print(f"settled bed: {len(r)} particles, top at {top*1e3:.1f} mm, core solid fraction {phi:.3f} "
      f"(random loose 0.55-0.60, random close 0.64)")
print(f"final kinetic energy {ke[-1]:.3e} J at t = {t[-1]:.6g} s (peak {ke.max():.3e} J)")

fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
a1.semilogy(t, np.maximum(ke, 1e-16))
a1.set_xlabel("time [s]")
a1.set_ylabel("kinetic energy [J]")
a1.set_title("pour and settle: energy")
a2.bar(["grainflow"], [phi], color="tab:blue")
a2.axhspan(0.55, 0.60, color="tab:orange", alpha=0.3, label="random loose packing")
a2.axhline(0.64, color="tab:red", ls="--", label="random close packing")
a2.set_ylim(0.4, 0.7)
a2.set_ylabel("solid fraction of the core")
a2.legend(loc="lower right")
a2.set_title(f"settled bed: {phi:.3f}")
fig.tight_layout()
fig.savefig("pour_settle.png", dpi=110)
