#!/usr/bin/env python3
"""Random single-bit flips of a real checkpoint and snapshot (docs/reliability.md, "What is
checked on read").

    bit_flips.py GRAIN SCENE WORKDIR [--seeds 0:40] [--kind checkpoint|snapshot|both]

SCENE (one with a checkpoint, e.g. tests/data/scenes/checkpointed_bed.yaml) runs once into
WORKDIR/base. For each seed one bit of the file, at a byte drawn uniformly over the whole file
(data, HDF5's records, attributes, padding), is flipped in a copy, and the copy is started from:
`grain run SCENE --restart COPY` for the checkpoint, a scene inserting `{type: snapshot, file:
COPY}` for the first snapshot. Each start must either be refused (exit code 1 or 2 with a line
naming the copy) or run to the end with every particle's id, position and velocity equal to
the intact file's run to the last bit (the flip hit bytes HDF5 does not use). A crash, a hang or
a run that ends with other values fails the seed.
"""
import argparse
import glob
import os
import random
import re
import shutil
import subprocess
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "..",
                                "support"))
from seeds import parse_seeds  # noqa: E402


def final_state(out):
    """(ids, positions, velocities) of the run's last snapshot, ordered by id."""
    last = sorted(glob.glob(os.path.join(out, "particles_*.h5")))[-1]
    with h5py.File(last, "r") as f:
        ids = f["id"][:]
        order = np.argsort(ids)
        return ids[order], f["position"][:][order], f["velocity"][:][order]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("grain")
    ap.add_argument("scene")
    ap.add_argument("work")
    ap.add_argument("--seeds", type=parse_seeds, default="0:40")
    ap.add_argument("--kind", choices=["checkpoint", "snapshot", "both"], default="both")
    args = ap.parse_args()
    grain, scene, work = (os.path.abspath(p) for p in (args.grain, args.scene, args.work))
    base = os.path.join(work, "base")
    shutil.rmtree(base, ignore_errors=True)
    os.makedirs(base)
    r = subprocess.run([grain, "run", scene, "--output", "out", "--no-progress"], cwd=base,
                       capture_output=True, text=True, timeout=120)
    if r.returncode != 0:
        print(r.stdout + r.stderr)
        print("FAIL: the run that makes the real files failed")
        return 1
    text = open(scene).read()
    files = {"checkpoint": sorted(glob.glob(os.path.join(base, "out", "checkpoint_*.h5")))[0],
             "snapshot": os.path.join(base, "out", "particles_000001.h5")}
    # The snapshot's scene: the same, inserting the file, run for a few milliseconds.
    snapshot_scene = re.sub(r"(?ms)^insert:.*?(?=^\S)",
                            "insert:\n  - {type: snapshot, file: FILE}\n", text)

    def start(kind, folder, name):
        if kind == "checkpoint":
            cmd = [grain, "run", scene, "--output", "out", "--no-progress", "--restart", name]
        else:
            with open(os.path.join(folder, "scene.yaml"), "w") as f:
                f.write(snapshot_scene.replace("FILE", name))
            cmd = [grain, "run", "scene.yaml", "--output", "out", "--no-progress"]
        try:
            r = subprocess.run(cmd, cwd=folder, capture_output=True, text=True, timeout=120)
            return r.returncode, r.stdout + r.stderr
        except subprocess.TimeoutExpired:
            return "timeout", ""

    kinds = ["checkpoint", "snapshot"] if args.kind == "both" else [args.kind]
    failures = 0
    for kind in kinds:
        data = open(files[kind], "rb").read()
        intact = os.path.join(work, kind + "_intact")
        shutil.rmtree(intact, ignore_errors=True)
        os.makedirs(intact)
        with open(os.path.join(intact, "file.h5"), "wb") as f:
            f.write(data)
        code, log = start(kind, intact, "file.h5")
        if code != 0:
            print(log)
            print(f"FAIL: {kind}: the intact file does not run")
            return 1
        reference = final_state(os.path.join(intact, "out"))
        tally = {}
        for seed in args.seeds:
            rnd = random.Random(seed)
            byte, bit = rnd.randrange(len(data)), rnd.randrange(8)
            folder = os.path.join(work, f"{kind}_{seed}")
            shutil.rmtree(folder, ignore_errors=True)
            os.makedirs(folder)
            flipped = bytearray(data)
            flipped[byte] ^= 1 << bit
            with open(os.path.join(folder, "file.h5"), "wb") as f:
                f.write(flipped)
            code, log = start(kind, folder, "file.h5")
            if code == "timeout":
                outcome = "FAIL: no end within 120 s"
            elif code in (1, 2):
                outcome = "refused" if "file.h5" in log and "error" in log else \
                    f"FAIL: exit {code} without a message naming the file"
            elif code != 0:
                outcome = f"FAIL: exit {code} (a crash)"
            else:
                got = final_state(os.path.join(folder, "out"))
                outcome = "identical" if all(np.array_equal(a, b) for a, b in zip(got, reference)) \
                    else "FAIL: ran to the end with other values"
            last = log.strip().splitlines()[-1][:240] if log.strip() else ""
            print(f"{kind} seed {seed}: byte {byte} bit {bit}: {outcome}"
                  + (f": {last}" if outcome != "identical" else ""))
            tally[outcome.split(":")[0]] = tally.get(outcome.split(":")[0], 0) + 1
            if outcome.startswith("FAIL"):
                failures += 1
            else:
                shutil.rmtree(folder, ignore_errors=True)
        print(f"{kind}: {len(args.seeds)} flips: " +
              ", ".join(f"{k} {v}" for k, v in sorted(tally.items())))
    print("PASS" if failures == 0 else f"FAIL: {failures} seed(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
