#!/usr/bin/env python3
"""K/K_Stokes against void fraction at three Reynolds numbers for every drag law.

Uses the independent formulas of drag_reference.py (same folder). Writes
docs/models/fluid-forces-drag.png. Run: scripts/python.sh tests/dem/fluid/plot_drag_laws.py
"""
import math
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import drag_reference as ref  # noqa: E402

root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
eps = [0.35 + 0.005 * i for i in range(131)]  # 0.35 .. 1.0 (ε = 1 excluded where φ divides)
fig, axes = plt.subplots(1, 3, figsize=(15, 4.8), sharey=True)
stokes = 3 * math.pi * ref.MU * ref.D
for ax, re in zip(axes, [0.1, 10.0, 500.0]):
    for name, law in ref.LAWS:
        xs, ys = [], []
        for e in eps:
            if e >= 1.0:
                continue
            u = re * ref.MU / (ref.RHO * e * ref.D)
            xs.append(e)
            ys.append(law(e, u) / stokes)
        ax.semilogy(xs, ys, label=name, lw=1.4, ls="--" if name in ("gidaspow",) else "-")
    ax.set_title(f"Re = ρ_f ε d U/μ = {re:g}")
    ax.set_xlabel("void fraction ε")
    ax.grid(True, which="both", alpha=0.3)
axes[0].set_ylabel("K / 3πμd")
axes[2].legend(fontsize=8)
fig.suptitle("grainflow drag laws: drag excluding the mean-pressure part, F = K (u_f − v)")
fig.tight_layout()
out = os.path.join(root, "docs", "theory", "fluid-forces-drag.png")
fig.savefig(out, dpi=110)
print("wrote", out)
