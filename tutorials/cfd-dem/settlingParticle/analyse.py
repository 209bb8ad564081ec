#!/usr/bin/env python3
"""Settling sphere: the particle's velocity against the terminal velocity of its drag law.

Reference: the terminal velocity u_t solves (3/4) C_D(Re) rho_f u_t^2 / d = (rho_p - rho_f) g
with Schiller & Naumann's C_D = 24/Re (1 + 0.15 Re^0.687) (Schiller & Naumann 1933;
Clift, Grace & Weber 1978), solved here by bisection. The simulated velocity is averaged
after the particle has reached it (t > 10 response times). Exit status 1 when the mean
differs from u_t by more than 3 %.
"""
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
from run_index import run_snapshots  # noqa: E402 (tutorials/run_index.py)

d, rho_p, rho_f, mu, g = 2e-4, 2500.0, 1000.0, 1e-3, 9.81


def excess(u):
    re = rho_f * u * d / mu
    cd = 24 / re * (1 + 0.15 * re**0.687)
    return 0.75 * cd * rho_f * u * u / d - (rho_p - rho_f) * g


lo, hi = 1e-9, 10.0
for _ in range(200):
    mid = 0.5 * (lo + hi)
    lo, hi = (lo, mid) if excess(mid) > 0 else (mid, hi)
u_t = 0.5 * (lo + hi)

t, w = [], []
for f in run_snapshots("particles"):
    with h5py.File(f, "r") as h:
        t.append(h.attrs["time"])
        w.append(-h["velocity"][0][2])
t, w = np.array(t), np.array(w)
tau = rho_p * d * d / (18 * mu)  # Stokes response time
late = t > 10 * tau
mean = w[late].mean()
error = mean / u_t - 1
ok = abs(error) <= 0.03
print(f"settlingParticle: u_t(Schiller-Naumann) = {u_t:.5f} m/s, simulated mean {mean:.5f} m/s "
      f"(min {w[late].min():.5f}, max {w[late].max():.5f}), error {100 * error:+.2f} % "
      f"(allowed 3 %): {'ok' if ok else 'FAILED'}")

plt.figure(figsize=(6, 4))
plt.plot(t, w * 1e3, "o-", label="grainFoam (particle)")
plt.axhline(u_t * 1e3, color="k", ls="--", label=f"Schiller-Naumann u_t = {u_t * 1e3:.2f} mm/s")
plt.axhspan(u_t * 0.97e3, u_t * 1.03e3, color="0.9", label="±3 %")
plt.xlabel("t [s]")
plt.ylabel("settling speed [mm/s]")
plt.title("Glass sphere d = 0.2 mm settling in water")
plt.legend(loc="lower right")
plt.tight_layout()
plt.savefig("settlingParticle.png", dpi=120)
sys.exit(0 if ok else 1)
