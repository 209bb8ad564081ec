#!/usr/bin/env python3
"""Cost of heat transfer, off and on (docs/accuracy-vs-cost.md, "Heat transfer on and off").

A bed of 4000 glass beads (d = 1 mm) settled on a floor (settled once, untimed, then read
from its snapshot by every variant) runs S steps with:
  - heat off, by `grain` of a baseline build without the heat code (--baseline DIR), if given:
    the cost of the code's presence when off;
  - heat off;
  - heat on: contact conduction, floor at 400 K, beads at 300 K;
  - heat on with the soft-particle contact radius (`contact_radius: morris_static`);
  - a fluid block (water-like gas flow) without heat, and the same with convection and conduction;
  - the fluid block with eps computed from the particles (4 mm cells) without heat, and the
    same with conduction and Gunn's convection at each particle's cell eps.
Cost: CPU seconds of the `grain` process (the machine may be shared), median of interleaved
rounds (order reversed every other round).

Usage: heat_cost.py [--rounds N] [--steps S] [--build DIR] [--baseline DIR] [--out FILE.md]
"""
import argparse
import glob
import os
import resource
import statistics
import subprocess
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
DT = 1e-5

MATERIAL = "  - {{name: glass, youngs_modulus: 5e7, poisson_ratio: 0.25, density: 2500{heat}}}\n"
HEAT_MATERIAL = ", heat_capacity: 840, conductivity: 1.1"

SCENE = """domain: {{min: [0, 0, 0], max: [0.02, 0.02, 0.04], periodic: [true, true, false]}}
gravity: [0, 0, -9.81]
time: {{step: {dt}, end: {end}, expected_max_speed: 0.5}}
{heat_block}materials:
{material}interaction_defaults: {{restitution: 0.5, friction: 0.5}}
contact: {{normal: hertz, tangential: history}}
walls:
  - {{type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass{floor}}}
insert:
{insert}output: {{directory: {out}, progress: false, snapshot_interval: {end}, log_interval: {end}}}
{fluid}"""

FILL = """  - {type: fill, region: {box: {min: [0, 0, 0], max: [0.02, 0.02, 0.04]}}, count: 4000,
     material: glass, radius: {distribution: constant, value: 0.5e-3}, seed: 3}
"""
FROM_SNAPSHOT = "  - {{type: snapshot, file: {file}, keep_velocity: true{temperature}}}\n"

FLUID = """fluid:
  density: 1.2
  viscosity: 1.8e-5
  velocity: [0, 0, 0.3]
{void_fraction}  drag: schiller_naumann
  model: B
  forces: [drag, pressure_gradient, viscous]
{thermal}"""
FLUID_THERMAL = "  temperature: 500\n  heat_capacity: 1005\n  conductivity: 0.026\n"


COMPUTED_EPS = "  void_fraction: {cell_size: 0.004, minimum: 0.3}\n"


def scene(end, out, insert, heat, fluid, thermal_fluid=False, morris=False, computed_eps=False):
    thermal = FLUID_THERMAL + ("  convection: gunn\n" if computed_eps else "")
    return SCENE.format(
        dt=DT, end=end, out=out, insert=insert,
        heat_block=("heat: {contact_radius: morris_static}\n" if morris else "heat: {}\n") if heat else "",
        material=MATERIAL.format(heat=(HEAT_MATERIAL + (", real_youngs_modulus: 6.3e10" if morris else ""))
                                 if heat else ""),
        floor=", temperature: 400" if heat else "",
        fluid=FLUID.format(thermal=thermal if thermal_fluid else "",
                           void_fraction=COMPUTED_EPS if computed_eps else "") if fluid else "")


def cpu_of(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--build", default=os.environ.get("GRAINFLOW_BUILD_DIR", os.path.join(ROOT, "build")))
    ap.add_argument("--baseline", help="build directory of a grain without the heat code")
    ap.add_argument("--out")
    args = ap.parse_args()
    grain = os.path.join(args.build, "bin", "grain")
    work = tempfile.mkdtemp(prefix="heat_cost.")
    # The bed: 0.25 s of settling, untimed.
    settle = os.path.join(work, "settle.yaml")
    with open(settle, "w") as f:
        f.write(scene(0.25, os.path.join(work, "settle"), FILL, False, False))
    subprocess.run([grain, "run", settle], check=True, stdout=subprocess.DEVNULL)
    snapshot = sorted(glob.glob(os.path.join(work, "settle", "particles_*.h5")))[-1]
    end = args.steps * DT
    cold = FROM_SNAPSHOT.format(file=snapshot, temperature="")
    warm = FROM_SNAPSHOT.format(file=snapshot, temperature=", temperature: 300")
    cases = []
    if args.baseline:
        cases.append(("heat off (baseline build, no heat code)",
                      os.path.join(args.baseline, "bin", "grain"), (cold, False, False)))
    cases += [("heat off", grain, (cold, False, False)),
              ("heat on: conduction, floor at 400 K", grain, (warm, True, False)),
              ("heat on: conduction, morris_static contact radius", grain, (warm, True, False, False, True)),
              ("fluid forces, heat off", grain, (cold, False, True)),
              ("fluid forces, heat on: conduction + convection", grain, (warm, True, True, True)),
              ("fluid forces, computed eps, heat off", grain, (cold, False, True, False, False, True)),
              ("fluid forces, computed eps, heat on: conduction + Gunn convection", grain,
               (warm, True, True, True, False, True))]
    files = []
    for k, (_, _, spec) in enumerate(cases):
        path = os.path.join(work, f"scene_{k}.yaml")
        with open(path, "w") as f:
            f.write(scene(end, os.path.join(work, f"out_{k}"), *spec))
        files.append(path)
    times = {k: [] for k in range(len(cases))}
    for r in range(args.rounds):
        order = range(len(cases)) if r % 2 == 0 else reversed(range(len(cases)))
        for k in order:
            times[k].append(cpu_of([cases[k][1], "run", files[k]]))
    ref = statistics.median(times[1 if args.baseline else 0])
    lines = [f"| variant | CPU s (median of {args.rounds}) | spread (min-max) | relative to heat off |",
             "|---|---:|---:|---:|"]
    for k, (name, _, _) in enumerate(cases):
        t = statistics.median(times[k])
        lines.append(f"| {name} | {t:.3f} | {min(times[k]):.3f}-{max(times[k]):.3f} | {t / ref:.3f} |")
    text = "\n".join(lines)
    print(f"heat transfer, 4000 settled beads, {args.steps} steps:\n{text}")
    if args.out:
        with open(args.out, "w") as f:
            f.write(text + "\n")


if __name__ == "__main__":
    main()
