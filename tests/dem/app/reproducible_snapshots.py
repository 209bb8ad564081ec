#!/usr/bin/env python3
"""`parallel: {reproducible: true}` through the command line: the same scene run by
`grain run` on 1, 2 and 3 ranks writes snapshots that are equal bit for bit (every snapshot,
sorted by id: ids, positions, velocities, spins, and temperatures when the scene has heat
transfer), and the 1-rank run's first checkpoint
continued with `grain run --restart` on 3 ranks writes the same last snapshot.

    reproducible_snapshots.py GRAIN SCENE WORKDIR MPIEXEC

Reference: exact equality (docs/parallel.md, "Reproducible results"). Exit 1 on any
difference, naming the snapshot and the field.
"""
import pathlib
import shutil
import subprocess
import sys

import h5py
import numpy as np

FIELDS = ("id", "position", "velocity", "angular_velocity")
OPTIONAL = ("temperature",)  # compared when the snapshots hold it


def run(grain, scene, out, mpiexec, ranks, extra=()):
    cmd = [mpiexec, "-np", str(ranks), "--oversubscribe", grain, "run", scene, "--output", str(out),
           "--no-progress", *extra]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        sys.exit(f"failed ({res.returncode}): {' '.join(cmd)}\n{res.stdout[-2000:]}\n{res.stderr[-2000:]}")
    return res.stdout


def snapshot(path):
    with h5py.File(path, "r") as f:
        order = np.argsort(f["id"][...], kind="stable")
        return {k: f[k][...][order] for k in FIELDS + OPTIONAL if k in f}


def compare(a_path, b_path):
    a, b = snapshot(a_path), snapshot(b_path)
    if a.keys() != b.keys():
        sys.exit(f"error: {b_path} holds {sorted(b)}, {a_path} {sorted(a)}")
    for k in a:
        if a[k].shape != b[k].shape or a[k].tobytes() != b[k].tobytes():
            diff = np.max(np.abs(a[k] - b[k])) if a[k].shape == b[k].shape else "shape"
            sys.exit(f"error: {b_path} differs from {a_path} in '{k}' (largest difference {diff})")


def main():
    grain, scene, work, mpiexec = sys.argv[1:5]
    work = pathlib.Path(work)
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    outs = {n: work / f"np{n}" for n in (1, 2, 3)}
    for n, out in outs.items():
        text = run(grain, scene, out, mpiexec, n)
        if n == 1 and "canonical order" not in text:
            sys.exit("error: the run's report does not say that force sums are in canonical order:\n" + text)
    snaps = sorted(p.name for p in outs[1].glob("particles_*.h5"))
    if len(snaps) < 5:
        sys.exit(f"error: only {len(snaps)} snapshots in {outs[1]}")
    heat = any(line.startswith("heat:") for line in pathlib.Path(scene).read_text().splitlines())
    if heat:
        first = snapshot(outs[1] / snaps[0])
        if "temperature" not in first:
            sys.exit(f"error: the scene has heat transfer but {snaps[0]} holds no temperature")
        last = snapshot(outs[1] / snaps[-1])["temperature"]
        if np.all(last == first["temperature"]):
            sys.exit("error: no heat flowed: the temperature comparison would prove nothing")
    for n in (2, 3):
        for s in snaps:
            compare(outs[1] / s, outs[n] / s)
    print(f"{len(snaps)} snapshots equal bit for bit on 1, 2 and 3 ranks", flush=True)
    checkpoints = sorted(outs[1].glob("checkpoint_*.h5"))
    if not checkpoints:
        sys.exit(f"error: no checkpoint in {outs[1]}")
    restart = work / "restart_np3"
    run(grain, scene, restart, mpiexec, 3, ["--restart", str(checkpoints[0])])
    # The restart numbers its snapshots from 0 in its own directory: compare the last ones,
    # which must be of the same step.
    last = sorted(restart.glob("particles_*.h5"))[-1]
    with h5py.File(outs[1] / snaps[-1], "r") as f, h5py.File(last, "r") as g:
        if f.attrs["step"] != g.attrs["step"]:
            sys.exit(f"error: {last} is of step {g.attrs['step']}, {snaps[-1]} of {f.attrs['step']}")
    compare(outs[1] / snaps[-1], last)
    print(f"the 1-rank checkpoint {checkpoints[0].name} continued on 3 ranks: its last snapshot "
          f"{last.name} equals {snaps[-1]} bit for bit")


if __name__ == "__main__":
    main()
