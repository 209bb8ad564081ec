#!/usr/bin/env python3
"""1000 snapshots of 2 particles with two grain builds side by side (docs/reliability.md).

    snapshot_series.py GRAIN_A GRAIN_B [ROUNDS] [WORKDIR]

Runs `grain run two_particles_1000_snapshots.yaml` (1001 snapshots) with each build in turn,
ROUNDS times (default 3), and prints each build's median wall time and CPU time (user +
system of the process, from getrusage), and the ratios. The CPU time is the better measure
on a shared machine: the wall time includes waiting for the cores.
"""
import os
import resource
import shutil
import statistics
import subprocess
import sys
import time

here = os.path.dirname(os.path.abspath(__file__))
scene = os.path.join(here, "two_particles_1000_snapshots.yaml")
grains = sys.argv[1:3]
rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 3
work = sys.argv[4] if len(sys.argv) > 4 else "snapshot_series_output"
os.makedirs(work, exist_ok=True)
wall = {g: [] for g in grains}
cpu = {g: [] for g in grains}
for r in range(rounds):
    for k, grain in enumerate(grains):
        out = os.path.join(work, f"out_{k}")
        shutil.rmtree(out, ignore_errors=True)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.monotonic()
        subprocess.run([grain, "run", scene, "--output", out, "--no-progress"], check=True,
                       stdout=subprocess.DEVNULL)
        wall[grain].append(time.monotonic() - start)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu[grain].append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
        files = len([n for n in os.listdir(out) if n.endswith(".h5")])
        print(f"round {r + 1}: {grain}: {wall[grain][-1]:.2f} s wall, {cpu[grain][-1]:.2f} s CPU, "
              f"{files} snapshots", flush=True)
a, b = grains
print(f"| build | median wall s | median CPU s |\n|---|---|---|")
for g in grains:
    print(f"| {g} | {statistics.median(wall[g]):.2f} | {statistics.median(cpu[g]):.2f} |")
print(f"ratio A / B: wall {statistics.median(wall[a]) / statistics.median(wall[b]):.1f}, "
      f"CPU {statistics.median(cpu[a]) / statistics.median(cpu[b]):.1f}")
