#!/usr/bin/env python3
"""Whether two grain builds compute the same results to the last bit.

    compare_builds.py snapshots --base A/bin/grain --new B/bin/grain SCENE END INTERVAL RANKS...
    compare_builds.py restart   --base A/bin/grain --new B/bin/grain SCENE END INTERVAL RANKS...

`snapshots`: runs SCENE (time.end = END, a snapshot every INTERVAL s) with both builds on each
rank count and compares every snapshot's ids, positions, velocities and spins byte for byte
(sorted by id). `restart`: both builds run SCENE with a checkpoint every INTERVAL s; then each
build restarts from each build's last-but-one checkpoint, and every restarted run's last snapshot
must equal the uninterrupted run's byte for byte (checkpoints written by either build, read by
either). The scene's folder is copied (without output*) to --work/<label>/; exit code 1 when
anything differs. Used for the optimisations of docs/performance-history.md, which must not change a bit.
"""
import argparse
import glob
import os
import pathlib
import shutil
import subprocess
import sys

import h5py
import numpy as np
import yaml

FIELDS = ("id", "position", "velocity", "angular_velocity")


def prepare(src, case, end, edit):
    shutil.rmtree(case, ignore_errors=True)
    shutil.copytree(src.parent, case, ignore=shutil.ignore_patterns("output*"))
    s = yaml.safe_load(open(src))
    s["time"]["end"] = end
    s.setdefault("output", {}).update(directory="output", progress=False)
    edit(s)
    (case / "scene_compare.yaml").write_text(yaml.safe_dump(s))


def run(grain, case, ranks, extra=()):
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    cmd = ["mpirun", "-np", str(ranks), "--bind-to", "none", "--mca", "mpi_yield_when_idle", "1",
           str(grain), "run", "scene_compare.yaml", "--no-progress", *extra]
    r = subprocess.run(cmd, cwd=case, env=env, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"failed in {case}:\n{r.stdout[-2000:]}\n{r.stderr[-2000:]}")


def state(path):
    with h5py.File(path, "r") as f:
        order = np.argsort(f["id"][...], kind="stable")
        return {k: f[k][...][order].tobytes() for k in FIELDS}


def snapshots(case):
    return sorted(glob.glob(str(case / "output" / "particles_*.h5")))


def compare_snapshots(a, work, label):
    ok = True
    src = pathlib.Path(a.scene).resolve()
    for n in a.ranks:
        files = {}
        for tag, grain in (("base", a.base), ("new", a.new)):
            case = work / label / f"{tag}_np{n}"
            prepare(src, case, a.end, lambda s: s["output"].update(snapshot_interval=a.interval))
            run(grain, case, n)
            files[tag] = snapshots(case)
        differ = [os.path.basename(x) for x, y in zip(files["base"], files["new"]) if state(x) != state(y)]
        same = len(files["base"]) == len(files["new"]) > 0 and not differ
        ok &= same
        print(f"{label}, {n} rank(s): {len(files['base'])} snapshots, "
              + ("bit-identical" if same else f"DIFFERENT ({', '.join(differ) or 'snapshot counts'})"))
    return ok


def compare_restarts(a, work, label):
    ok = True
    src = pathlib.Path(a.scene).resolve()
    builds = {"base": a.base, "new": a.new}
    for n in a.ranks:
        full = {}
        for tag, grain in builds.items():
            case = work / label / f"{tag}_np{n}"
            prepare(src, case, a.end, lambda s: s["output"].update(
                snapshot_interval=a.end / 2, checkpoint_interval=a.interval, checkpoint_keep=1000))
            run(grain, case, n)
            full[tag] = case
        reference = state(snapshots(full["base"])[-1])
        same = state(snapshots(full["new"])[-1]) == reference
        ok &= same
        print(f"{label}, {n} rank(s): uninterrupted runs {'bit-identical' if same else 'DIFFERENT'}")
        for writer in builds:
            checkpoint = sorted(glob.glob(str(full[writer] / "output" / "checkpoint_*.h5")))[-2]
            for reader, grain in builds.items():
                case = work / label / f"{reader}_from_{writer}_np{n}"
                shutil.rmtree(case, ignore_errors=True)
                shutil.copytree(full[writer], case, ignore=shutil.ignore_patterns("output*"))
                run(grain, case, n, ["--restart", checkpoint])
                same = state(snapshots(case)[-1]) == reference
                ok &= same
                print(f"  {reader} restarted from {writer}'s {os.path.basename(checkpoint)}: "
                      + ("bit-identical to the uninterrupted run" if same else "DIFFERENT"))
    return ok


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mode", choices=("snapshots", "restart"))
    ap.add_argument("--base", required=True, help="the reference grain executable")
    ap.add_argument("--new", required=True, help="the grain executable to check")
    ap.add_argument("--work", default=str(pathlib.Path(__file__).resolve().parent / "output" / "compare"))
    ap.add_argument("--label", help="subfolder of --work (default: the scene's name)")
    ap.add_argument("scene")
    ap.add_argument("end", type=float, help="time.end [s]")
    ap.add_argument("interval", type=float, help="snapshot (or checkpoint) interval [s]")
    ap.add_argument("ranks", type=int, nargs="+")
    a = ap.parse_args()
    label = a.label or pathlib.Path(a.scene).stem
    check = compare_snapshots if a.mode == "snapshots" else compare_restarts
    return 0 if check(a, pathlib.Path(a.work), label) else 1


if __name__ == "__main__":
    sys.exit(main())
