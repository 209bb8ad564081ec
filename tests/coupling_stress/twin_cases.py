#!/usr/bin/env python3
"""Twin coupled cases: a random coupled case turned or moved must run as the case itself
(docs/stability.md, "Twin scenes").

    twin_cases.py --foam-env scripts/foam_env.sh --solver bin/grainFoam --grain bin/grain
                  --lib-dir <lib> --cases tests/coupling_stress/cases --work <scratch>
                  --seeds 0:8 [--twins turn1,turn2,shift]

Each seed draws the case random_coupled.py draws (gravity along -z, the mesh's corner at the
origin) and runs it as drawn and as its twins (tests/stress/hard_scenes/twin_scenes.py): the
axes cycled once or twice (turn1, turn2: mesh vertices, the inlet's velocity table, the
decomposition, and every point and vector of the DEM scene turn together, so gravity points
along -x or -y), or everything moved by 0.01-10 m per axis (shift). The fill's particles are
first inserted by `grain run` (the DEM scene alone, to its t = 0 snapshot), and each case
starts from that snapshot, turned or moved. Both cases solve the fluid to 1e-15 (PCG, no
relative tolerance): an iterative solver stopped at a looser tolerance ends wherever its
round-off takes it, which would hide an asymmetry under the solver's own error.

A twin passes when grainFoam exits as for the drawn case and, after a stop, with the same
message (numbers and axis letters set aside); after a run, every snapshot holds the same
particles, each within 1e-6 of a particle diameter of the drawn case's, mapped back. Beyond
that, a chaotic case is judged against the drawn case started with each particle's x one ulp
larger (the nudge, twin_scenes.judge): a twin's fluid differs by round-off in every fluid
step, so it may deviate 1000 x (fluid steps so far) times as far as the nudge; once the nudge
reaches 0.01 d, later snapshots are not compared.

Needs numpy, h5py, yaml (scripts/python.sh finds a Python that has them).
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time

import numpy as np
import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "stress", "hard_scenes"))
import random_coupled as rc  # noqa: E402
from grainfoam_driver import snapshots  # noqa: E402  (tests/support, via random_coupled)
from twin_scenes import CHAOS_EVERY_STEP, TOLERANCE, Twin, judge, same_stop  # noqa: E402

TOLERANCE_D = 1e-6
TRIPLE = re.compile(r"\(\s*([-+0-9.eE]+)\s+([-+0-9.eE]+)\s+([-+0-9.eE]+)\s*\)")
TIGHT = {"solver GAMG; smoother DIC; tolerance 1e-8; relTol 0.01;":
         "solver PCG; preconditioner DIC; tolerance 1e-15; relTol 0; maxIter 5000;",
         "tolerance 1e-9; relTol 0;": "tolerance 1e-15; relTol 0; maxIter 5000;"}


def edit(path, change):
    with open(path) as f:
        text = f.read()
    new = change(text)
    with open(path, "w") as f:
        f.write(new)


def tighten(case):
    def change(text):
        for old, new in TIGHT.items():
            if old not in text:
                raise RuntimeError(f"twin_cases: no '{old}' in {case}/system/fvSolution")
            text = text.replace(old, new)
        return text
    edit(os.path.join(case, "system", "fvSolution"), change)


def start_from_snapshot(grain, case):
    """Replace the case's fill by the t = 0 snapshot `grain run` makes of it."""
    path = os.path.join(case, "particles.yaml")
    with open(path) as f:
        scene = yaml.safe_load(f)
    fill = scene["insert"][0]
    alone = json.loads(json.dumps(scene))
    alone.pop("fluid")
    alone.pop("heat", None)
    for m in alone["materials"]:
        m.pop("heat_capacity", None)
        m.pop("conductivity", None)
    alone["insert"][0].pop("temperature", None)
    alone["output"] = {"snapshot_interval": alone["time"]["end"], "directory": "out"}
    folder = os.path.join(case, "fill")
    os.makedirs(folder)
    with open(os.path.join(folder, "scene.yaml"), "w") as f:
        yaml.safe_dump(alone, f)
    p = subprocess.run([grain, "run", "scene.yaml", "--no-progress", "--allow-large-dt"],
                       cwd=folder, capture_output=True, text=True)
    first = os.path.join(folder, "out", "particles_000000.h5")
    if not os.path.exists(first):
        raise RuntimeError(f"twin_cases: the fill inserted nothing: {p.stdout[-300:]}")
    shutil.copy(first, os.path.join(case, "filled.h5"))
    shutil.rmtree(folder)
    insertion = {"type": "snapshot", "file": "filled.h5"}
    if "temperature" in fill:
        insertion["temperature"] = fill["temperature"]
    scene["insert"] = [insertion]
    with open(path, "w") as f:
        yaml.safe_dump(scene, f, default_flow_style=None, sort_keys=False)


def make_twin(twin, drawn, case):
    shutil.rmtree(case, ignore_errors=True)
    shutil.copytree(drawn, case)

    def triples(text, point):
        def one(m):
            v = twin.turn([m.group(k) for k in (1, 2, 3)])  # as written: labels stay labels
            if point:  # blockMesh vertices are in mm (scale 0.001)
                v = [repr(float(v[a]) + 1000 * twin.offset[a]) for a in range(3)]
            return "(" + " ".join(v) + ")"
        return TRIPLE.sub(one, text)

    def mesh(text):
        i, j = text.index("vertices"), text.index("blocks")
        return text[:i] + triples(text[i:j], True) + text[j:]
    edit(os.path.join(case, "system", "blockMeshDict"), mesh)
    edit(os.path.join(case, "0", "U"), lambda t: triples(t, False))
    if os.path.exists(os.path.join(case, "system", "decomposeParDict")):
        edit(os.path.join(case, "system", "decomposeParDict"), lambda t: triples(t, False))
    path = os.path.join(case, "particles.yaml")
    with open(path) as f:
        scene = yaml.safe_load(f)
    with open(path, "w") as f:
        yaml.safe_dump(twin.scene(scene), f, default_flow_style=None, sort_keys=False)
    twin.snapshot(os.path.join(drawn, "filled.h5"), os.path.join(case, "filled.h5"))


def run(runner, args, case, ranks):
    code, out = runner.run(case, "blockMesh", "blockMesh")
    if code != 0:
        return "blockMesh", out
    if ranks == 2:
        code, out = runner.run(case, "decomposePar", "decomposePar")
        if code != 0:
            return "decomposePar", out
    return runner.run(case, "grainFoam", args.solver, ranks=ranks)


def deviations(twin, c, drawn, other):
    """Per snapshot (time, the largest position deviation in diameters, 0), mapped back; or
    a failure text."""
    if [t for t, _ in other] != [t for t, _ in drawn]:
        return None, "snapshots at other times"
    out = []
    for (t, a), (_, b) in zip(drawn, other):
        if not np.array_equal(a["id"], b["id"]):
            return None, f"t = {t}: other particle ids"
        dev = np.abs(twin.difference(b["position"], a["position"], t)).max() / c["d"]
        out.append((t, float(dev), 0.0))
    return out, None


def stop_message(log):
    return rc.refusal(log) or " | ".join(log.strip().split("\n")[-3:])


def check_seed(runner, args, seed, names):
    c = rc.draw(seed)
    work = os.path.join(args.work, f"seed_{seed}")
    shutil.rmtree(work, ignore_errors=True)
    drawn = os.path.join(work, "drawn")
    rc.make_case(c, os.path.join(args.cases, "dense_bed"), drawn)
    tighten(drawn)
    start_from_snapshot(args.grain, drawn)
    for name in names + ["nudge"]:  # before the drawn case runs: its inputs only
        make_twin(Twin(name, seed, max(c["size"])), drawn, os.path.join(work, name))
    code, log = run(runner, args, drawn, c["ranks"])
    if code not in (0, 1):
        return False, f"the drawn case: exit {code}: {stop_message(log)}", work
    first = snapshots(drawn) if code == 0 else None
    notes = []
    nudge = []

    def nudged():
        """The deviations of the drawn case started with each particle's x one ulp larger."""
        if not nudge:
            twin, case = Twin("nudge", seed), os.path.join(work, "nudge")
            ncode, nlog = run(runner, args, case, c["ranks"])
            devs, failure = deviations(twin, c, first, snapshots(case)) if ncode == 0 else \
                (None, stop_message(nlog))
            if failure:
                raise RuntimeError(f"the nudged case does not compare: {failure}")
            nudge.append(devs)
        return nudge[0]

    for name in names:
        twin, case = Twin(name, seed, max(c["size"])), os.path.join(work, name)
        tcode, tlog = run(runner, args, case, c["ranks"])
        if tcode != code:
            return False, (f"{name}: exit {tcode}, the drawn case {code}\n  drawn: "
                           f"{stop_message(log)}\n  twin:  {stop_message(tlog)}"), work
        if code != 0:
            if not same_stop(stop_message(log), stop_message(tlog)):
                return False, (f"{name}: another stop\n  drawn: {stop_message(log)}\n  twin:  "
                               f"{stop_message(tlog)}"), work
            notes.append(f"{name} stopped alike")
            continue
        devs, failure = deviations(twin, c, first, snapshots(case))
        chaotic = None
        if not failure:
            # A twin's fluid differs by round-off in every fluid step (cell volumes, centres
            # and face areas are summed in another order, or at other magnitudes), and the
            # DEM's by an ulp of the offset in every DEM step when moved.
            chaos = CHAOS_EVERY_STEP
            steps = (lambda when: max(1.0, when / c["dt_f"]))  # noqa: E731
            if twin.offset.any():
                chaos *= 1 + np.abs(twin.offset).max() / max(c["size"])
                steps = (lambda when: max(1.0, when / c["dt_dem"]))  # noqa: E731
            failure, chaotic = judge(name, devs, nudged, chaos, steps, TOLERANCE_D)
        if failure:
            return False, f"{name}: {failure}", work
        notes.append(f"{name} {max(v[1] for v in devs):.2g} d"
                     + (f" (chaotic: the nudge {max(v[1] for v in nudge[0]):.2g} d"
                        + (f", compared until t = {chaotic:.3g} s" if chaotic else "") + ")"
                        if nudge else ""))
    return True, ("ran; " if code == 0 else "stopped; ") + ", ".join(notes), work


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--foam-env", required=True)
    ap.add_argument("--solver", required=True)
    ap.add_argument("--grain", required=True)
    ap.add_argument("--lib-dir", default="")
    ap.add_argument("--cases", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--mpiexec", default="mpiexec")
    ap.add_argument("--seeds", type=rc.parse_seeds, required=True)
    ap.add_argument("--twins", default="turn1,turn2,shift")
    ap.add_argument("--timeout", type=float, default=600, help="per run [s]")
    ap.add_argument("--keep", action="store_true")
    args = ap.parse_args()
    names = args.twins.split(",")
    for name in names:
        if name not in TOLERANCE:
            ap.error(f"--twins: unknown twin '{name}'; allowed: {', '.join(TOLERANCE)}")
    for attr in ("foam_env", "solver", "grain", "cases", "work"):
        setattr(args, attr, os.path.abspath(getattr(args, attr)))
    runner = rc.Runner(args)
    failed = []
    start = time.monotonic()
    for seed in args.seeds:
        t0 = time.monotonic()
        try:
            ok, note, work = check_seed(runner, args, seed, names)
        except (RuntimeError, OSError, ValueError, KeyError) as e:
            ok, note, work = False, f"{type(e).__name__}: {e}", None
        print(f"seed {seed:5d} {time.monotonic() - t0:7.1f} s  {'ok' if ok else 'FAIL'} ({note})",
              flush=True)
        if ok and work and not args.keep:
            shutil.rmtree(work, ignore_errors=True)
        if not ok:
            failed.append(seed)
    print(f"\n{len(args.seeds)} seeds in {time.monotonic() - start:.1f} s, {len(failed)} failed"
          + (f": {' '.join(map(str, failed))} (folders under {args.work})" if failed else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
