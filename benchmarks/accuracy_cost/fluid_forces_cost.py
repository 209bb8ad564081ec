#!/usr/bin/env python3
"""Cost of each fluid force, switched on one at a time (one-way mode in `grain`).

The same scene (4000 glass beads, d = 1 mm, settling through water in a box periodic
sideways, between a floor and a lid, with a linear shear along the height, so that every lift
force has something to act on) runs with: no fluid block;
the smallest valid list [drag, pressure_gradient, viscous]; that list plus one more force;
and the smallest list with each drag law. Cost: CPU seconds of the `grain` process (the
machine may be shared), median of interleaved rounds, relative to the run without fluid.
Accuracy of each force is tested against its closed form in tests/dem/fluid/; this table is
the cost side, and the proof that a force a scene does not list costs nothing.

Usage: fluid_forces_cost.py [--rounds N] [--steps S] [--build DIR] [--out FILE.md]
"""
import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))

SCENE = """domain: {{min: [0, 0, 0], max: [0.03, 0.03, 0.03], periodic: [true, true, false]}}
gravity: [0, 0, -9.81]
time: {{step: 1e-5, end: {end}, expected_max_speed: 0.5}}
materials:
  - {{name: glass, youngs_modulus: 5e7, poisson_ratio: 0.25, density: 2500}}
interaction_defaults: {{restitution: 0.5, friction: 0.5}}
contact: {{normal: hertz, tangential: history}}
walls:
  - {{type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass}}
  - {{type: plane, name: lid, point: [0, 0, 0.03], normal: [0, 0, -1], material: glass}}
insert:
  - {{type: fill, region: {{box: {{min: [0, 0, 0], max: [0.03, 0.03, 0.03]}}}}, count: 4000,
     material: glass, radius: {{distribution: constant, value: 0.5e-3}}, seed: 3}}
output: {{directory: {out}, progress: false, snapshot_interval: {end}, log_interval: {end}}}
{fluid}"""

FLUID = """fluid:
  density: 1000
  viscosity: 1e-3
  velocity: [0.01, 0, 0]
  shear: {{rate: 5, flow_direction: [1, 0, 0], gradient_direction: [0, 0, 1], origin: [0, 0, 0.015]}}
  drag: {drag}
  model: B
  forces: [{forces}]
"""

BASE = ["drag", "pressure_gradient", "viscous"]
EXTRA = ["virtual_mass", "saffman_mei", "magnus", "rotational_drag"]
LAWS = ["schiller_naumann", "di_felice", "rong", "wen_yu", "ergun", "gidaspow", "koch_hill",
        "beetstra", "tenneti_garg_subramaniam"]


def variants():
    yield "no fluid block", ""
    yield "drag (schiller_naumann) + pressure_gradient + viscous", FLUID.format(
        drag="schiller_naumann", forces=", ".join(BASE))
    for f in EXTRA:
        yield f"  + {f}", FLUID.format(drag="schiller_naumann", forces=", ".join(BASE + [f]))
    for law in LAWS[1:]:
        yield f"drag law {law}", FLUID.format(drag=law, forces=", ".join(BASE))


def cpu_of(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--build", default=os.environ.get("GRAINFLOW_BUILD_DIR", os.path.join(ROOT, "build")))
    ap.add_argument("--out")
    args = ap.parse_args()
    grain = os.path.join(args.build, "bin", "grain")
    work = tempfile.mkdtemp(prefix="fluid_forces_cost.")
    end = args.steps * 1e-5
    cases = list(variants())
    files = []
    for k, (name, fluid) in enumerate(cases):
        path = os.path.join(work, f"scene_{k}.yaml")
        with open(path, "w") as f:
            f.write(SCENE.format(end=end, out=os.path.join(work, f"out_{k}"), fluid=fluid))
        files.append(path)
    times = {k: [] for k in range(len(cases))}
    for r in range(args.rounds):
        order = range(len(cases)) if r % 2 == 0 else reversed(range(len(cases)))
        for k in order:
            times[k].append(cpu_of([grain, "run", files[k]]))
    base = statistics.median(times[0])
    lines = ["| effect | CPU s (median of %d) | relative to no fluid |" % args.rounds, "|---|---|---|"]
    for k, (name, _) in enumerate(cases):
        t = statistics.median(times[k])
        lines.append(f"| {name} | {t:.2f} | {t / base:.3f} |")
    text = "\n".join(lines)
    print(f"fluid forces, 4000 beads, {args.steps} steps:\n{text}")
    if args.out:
        with open(args.out, "w") as f:
            f.write(text + "\n")


if __name__ == "__main__":
    main()
