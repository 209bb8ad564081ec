#!/usr/bin/env python3
"""The heated packed bed of `coupling.heat_front` (tests/coupling/cases/heated_bed) swept over
the cell height and the fluid time step, and run with heat off, side by side (issue 21,
point 3; docs/models/heat-transfer.md, docs/accuracy-vs-cost-coupled.md).

Each run: a fresh copy of the case with the edits named in its row, run to --end with a
write every 0.1 s; errors of the fluid's and the beads' thermal fronts (theta = 1/2) against
Schumann (1929) with Gunn's (1978) coefficient (tests/coupling/schumann.py), the largest
|error| over the write times and the error at the last; cost: grainFoam's CPU time split
(DEM + coupling + fluid, process CPU seconds, particle output left out).

Rows:
  cells d, 2 d, 4 d high (28, 14, 7 cells over 84 mm; 2 x 2 cells of 2 d across) at 1 ms;
  fluid steps 0.5, 1, 2 ms (25, 50, 100 DEM steps of 20 us) on cells of d;
  heat off: the same case (cells d, 1 ms) without `heat:` and its keys, alternated with
  heat on --repeat times for the cost comparison.

usage: heat_front.py [--end 0.5] [--repeat 2] [--work DIR] [--build DIR]
"""
import argparse
import os
import re
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tests", "support"))
sys.path.insert(0, os.path.join(ROOT, "tests", "coupling"))
import grainfoam_cases as cases  # noqa: E402
import schumann  # noqa: E402
from grainfoam_driver import Runner  # noqa: E402

HEAT_OFF = [
    ("particles.yaml", "heat: {conduction: none}\n", ""),
    ("particles.yaml", ",\n     heat_capacity: 6, conductivity: 1}", "}"),
    ("particles.yaml", "material: glass, temperature: 300}", "material: glass}"),
    ("particles.yaml", "  temperature: 300      # grain's prescribed T_f; grainFoam's fluid "
                       "temperature is 0/T\n", ""),
    ("particles.yaml", "  heat_capacity: 1000\n  conductivity: 0.026\n  convection: gunn\n", ""),
]


def cpu_split(log):
    """(DEM, coupling, fluid) process CPU seconds of the whole run (grainFoam's last split)."""
    num = r"([-+0-9.eE]+)"
    m = re.findall(r"^grainFoam CPU time split: DEM " + num + r" s \([^)]*\), coupling " + num +
                   r" s \([^)]*\), fluid " + num + " s", log, re.MULTILINE)
    return tuple(float(x) for x in m[-1]) if m else (float("nan"),) * 3


def run(runner, name, end, cells=28, step="1e-3", heat=True):
    edits = [("system/controlDict", "endTime         0.4;", f"endTime         {end:g};"),
             ("system/blockMeshDict", "(2 2 28)", f"(2 2 {cells})"),
             ("system/controlDict", "deltaT          1e-3;", f"deltaT          {step};")]
    if not heat:
        edits += HEAT_OFF
    case = runner.fresh_case("heated_bed", name, edits)
    if not heat:
        os.remove(os.path.join(case, "0", "T"))
    t0 = time.monotonic()
    log = runner.solve(case, 1)
    wall = time.monotonic() - t0
    return case, log, cpu_split(log), wall


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--end", type=float, default=0.5)
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--work", default=os.path.join(HERE, "output"))
    parser.add_argument("--build", default=os.environ.get("GRAINFLOW_BUILD_DIR",
                                                          os.path.join(ROOT, "build")))
    a = parser.parse_args()
    build = os.path.abspath(a.build)
    args = argparse.Namespace(foam_env=os.path.join(ROOT, "scripts", "foam_env.sh"),
                              solver=os.path.join(build, "bin", "grainFoam"), mpiexec="mpiexec",
                              lib_dir=os.path.join(build, "lib"),
                              cases=os.path.join(ROOT, "tests", "coupling", "cases"),
                              work=os.path.abspath(a.work))
    if not os.path.isfile(os.path.join(args.lib_dir, "libgrainflowFoamBCs.so")):
        # The library's folder: wherever the build put it.
        for root, _, files in os.walk(build):
            if "libgrainflowFoamBCs.so" in files:
                args.lib_dir = root
                break
    os.makedirs(args.work, exist_ok=True)
    runner = Runner(args)
    bed = cases.heated_bed_reference()
    z_bed = cases.BED_LAYERS * cases.BED_D
    print(f"heated bed: d = 3 mm, eps = {bed.eps:.4f}, U = {bed.u} m/s, Re = {bed.re:.1f}, "
          f"Gunn Nu = {bed.nu:.3f}, h = {bed.h:.2f} W/(m2 K), end {a.end:g} s")
    refs = {}

    def errors(case):
        profiles, moved = cases.heat_front_profiles(case, bed)
        worst_f = worst_s = 0.0
        last = None
        for t, fluid, solid, profile_error in profiles:
            if t not in refs:
                refs[t] = (schumann.front(bed.fluid, t, z_bed), schumann.front(bed.solid, t, z_bed))
            ef, es = fluid / refs[t][0] - 1, solid / refs[t][1] - 1
            worst_f, worst_s = max(worst_f, abs(ef)), max(worst_s, abs(es))
            last = (t, ef, es, profile_error)
        return worst_f, worst_s, last, moved

    rows = []
    for label, cells, step in (("cells d", 28, "1e-3"), ("cells 2 d", 14, "1e-3"),
                               ("cells 4 d", 7, "1e-3"), ("step 0.5 ms", 28, "5e-4"),
                               ("step 2 ms", 28, "2e-3")):
        case, log, cpu, wall = run(runner, label.replace(" ", "_"), a.end, cells, step)
        wf, ws, last, moved = errors(case)
        rows.append((label, cells, step, wf, ws, last, sum(cpu), cpu, moved))
        print(f"  {label}: fluid front worst {100 * wf:.2f} %, beads {100 * ws:.2f} %; at "
              f"t = {last[0]:.1f} s {100 * last[1]:+.2f} %, {100 * last[2]:+.2f} %; CPU "
              f"{sum(cpu):.1f} s (DEM {cpu[0]:.1f}, coupling {cpu[1]:.1f}, fluid {cpu[2]:.1f}); "
              f"bed moved {moved / cases.BED_D:.4f} d", flush=True)
    on, off = [], []
    for k in range(a.repeat):
        for heat in (False, True):
            _, log, cpu, wall = run(runner, f"cost_{'on' if heat else 'off'}_{k}", a.end, heat=heat)
            (on if heat else off).append(cpu)
            print(f"  cost run {k}, heat {'on' if heat else 'off'}: CPU {sum(cpu):.1f} s (DEM "
                  f"{cpu[0]:.1f}, coupling {cpu[1]:.1f}, fluid {cpu[2]:.1f})", flush=True)
    print()
    print("| run | cells high | fluid step | DEM steps per fluid step | fluid front: worst error "
          "(at the end) | bead front: worst error (at the end) | CPU s (DEM / coupling / fluid) |")
    print("|---|---|---|---|---|---|---|")
    for label, cells, step, wf, ws, last, total, cpu, _ in rows:
        print(f"| {label} | {cells} | {float(step) * 1e3:g} ms | {round(float(step) / 2e-5)} | "
              f"{100 * wf:.2f} % ({100 * last[1]:+.2f} %) | {100 * ws:.2f} % "
              f"({100 * last[2]:+.2f} %) | {total:.1f} ({cpu[0]:.1f} / {cpu[1]:.1f} / {cpu[2]:.1f}) |")
    print()
    mean = lambda runs, k: float(np.mean([r[k] for r in runs]))  # noqa: E731
    print("| heat | CPU s, DEM | coupling | fluid | total |")
    print("|---|---|---|---|---|")
    for name, runs in (("off", off), ("on", on)):
        print(f"| {name} | {mean(runs, 0):.2f} | {mean(runs, 1):.2f} | {mean(runs, 2):.2f} | "
              f"{sum(mean(runs, k) for k in range(3)):.2f} |")
    print(f"(means of {a.repeat} alternated runs each; per run: off "
          + ", ".join(f"{sum(r):.1f}" for r in off) + " s; on " + ", ".join(f"{sum(r):.1f}" for r in on)
          + " s)")


if __name__ == "__main__":
    main()
