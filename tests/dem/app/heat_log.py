#!/usr/bin/env python3
"""log.csv's thermal_J column against the energy balance (grain.heat_log).

    heat_log.py GRAIN WORKDIR [MPIEXEC]

300 beads of two materials in a closed box with adiabatic walls, conducting among themselves,
glass releasing 1000 W/kg and steel absorbing 300 W/kg (heat_source). Conduction moves heat
between particles and changes no total, so the particles' thermal energy must be
    E(t) = sum m c T0 + (sum m q) t,
with m, c, q and T0 of every particle read from the first snapshot and the scene (not from the
log). Checks on 1 rank and, with MPIEXEC, on 2: the column exists, E(0) is sum m c T0 to 1e-12
relative, every row's E(t) is the line above to 1e-8 of the rise (the sum's round-off and the
rows' time stamps), and the ranks agree to 1e-12.
"""
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np

grain, work = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
mpiexec = sys.argv[3] if len(sys.argv) > 3 else None
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
C = {0: 5.0, 1: 2.0}        # heat capacity [J/(kg K)] by material index
Q = {0: 1000.0, 1: -300.0}  # heat source [W/kg]
scene = f"""domain: {{min: [0, 0, 0], max: [0.012, 0.012, 0.03]}}
gravity: [0, 0, -9.81]
time: {{step: 5e-6, end: 0.02}}
heat: {{}}
materials:
  - {{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500, heat_capacity: {C[0]}, conductivity: 2, heat_source: {Q[0]}}}
  - {{name: steel, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 7800, heat_capacity: {C[1]}, conductivity: 20, heat_source: {Q[1]}}}
interaction_defaults: {{restitution: 0.5, friction: 0.5}}
contact: {{normal: hertz, tangential: history}}
walls:
  - {{type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass}}
  - {{type: plane, name: x0, point: [0, 0, 0], normal: [1, 0, 0], material: glass}}
  - {{type: plane, name: x1, point: [0.012, 0, 0], normal: [-1, 0, 0], material: glass}}
  - {{type: plane, name: y0, point: [0, 0, 0], normal: [0, 1, 0], material: glass}}
  - {{type: plane, name: y1, point: [0, 0.012, 0], normal: [0, -1, 0], material: glass}}
insert:
  - {{type: fill, region: {{box: {{min: [0, 0, 0], max: [0.012, 0.012, 0.004]}}}}, count: 150, material: glass, radius: {{distribution: uniform, min: 4e-4, max: 6e-4}}, temperature: 300}}
  - {{type: fill, region: {{box: {{min: [0, 0, 0.004], max: [0.012, 0.012, 0.008]}}}}, count: 150, material: steel, radius: {{distribution: uniform, min: 4e-4, max: 6e-4}}, temperature: 500, seed: 7}}
output: {{snapshot_interval: 0.01, log_interval: 0.001, fields: [id, position, mass, material, temperature]}}
"""
with open(os.path.join(work, "scene.yaml"), "w") as f:
    f.write(scene)
failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


def run(out, ranks):
    cmd = [grain, "run", "scene.yaml", "--output", out, "--no-progress"]
    if ranks > 1:
        cmd = [mpiexec, "-np", str(ranks), "--oversubscribe"] + cmd
    r = subprocess.run(cmd, cwd=work, capture_output=True, text=True, timeout=300)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)}: exit {r.returncode}\n{r.stdout[-2000:]}{r.stderr[-2000:]}")
    log = np.genfromtxt(os.path.join(work, out, "log.csv"), delimiter=",", names=True)
    with h5py.File(os.path.join(work, out, "particles_000000.h5"), "r") as f:
        m, mat, t0 = f["mass"][:], f["material"][:], f["temperature"][:]
    c = np.array([C[int(k)] for k in mat])
    q = np.array([Q[int(k)] for k in mat])
    return log, float(np.sum(m * c * t0)), float(np.sum(m * q))


energies = []
for ranks in [1, 2] if mpiexec else [1]:
    log, e0, power = run(f"out{ranks}", ranks)
    check("thermal_J" in log.dtype.names, f"{ranks} rank(s): log.csv has a column thermal_J")
    if "thermal_J" not in log.dtype.names:
        break
    e = log["thermal_J"]
    check(abs(e[0] / e0 - 1) < 1e-12, f"{ranks} rank(s): E(0) = {e[0]:.12g} J, sum m c T0 = "
          f"{e0:.12g} J")
    expected = e0 + power * log["time_s"]
    worst = float(np.max(np.abs(e - expected))) / (power * log["time_s"][-1])
    check(worst < 1e-8, f"{ranks} rank(s): E(t) = sum m c T0 + (sum m q) t over {len(e)} rows, "
          f"sum m q = {power:.6g} W, E rises by {e[-1] - e[0]:.6g} J: largest difference "
          f"{worst:.2e} of the rise (1e-8)")
    energies.append(e)
if len(energies) == 2:
    d = float(np.max(np.abs(energies[0] / energies[1] - 1)))
    check(d < 1e-12, f"1 and 2 ranks agree to {d:.1e} (1e-12)")
print(f"grain.heat_log: {len(failures)} failed checks")
sys.exit(1 if failures else 0)
