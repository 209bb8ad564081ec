#!/usr/bin/env python3
"""Print what a grainflow particle snapshot holds: time, step, particle count, bounds.

    scripts/h5_summary.py out/particles_000010.h5 [more files or directories ...]

A directory argument summarises every *.h5 snapshot in it, in name order.
Needs h5py and numpy (Debian: python3-h5py python3-numpy).
"""
import argparse
import os
import pathlib
import sys

try:
    import h5py
    import numpy as np
except ImportError:  # this python3 lacks them: scripts/python.sh finds one that has them
    if os.environ.get("GRAINFLOW_PYTHON_CHOSEN"):
        raise
    _helper = os.path.join(os.path.dirname(os.path.realpath(__file__)), "python.sh")
    os.execv(_helper, [_helper, os.path.abspath(__file__), *sys.argv[1:]])


def files_from(args):
    for a in args:
        p = pathlib.Path(a)
        if p.is_dir():
            yield from sorted(p.glob("*.h5"))
        else:
            yield p


def attr(f, name, default=None):
    v = f.attrs.get(name, default)
    return v.item() if hasattr(v, "item") else v


def summarise(path):
    with h5py.File(path, "r") as f:
        n = int(attr(f, "count", f["id"].shape[0] if "id" in f else 0))
        print(f"{path}")
        print(f"  time {attr(f, 'time', float('nan')):.9g} s  step {attr(f, 'step', -1)}  "
              f"particles {n}")
        if n == 0:
            print("  (no particles)")
            return
        x = f["position"][...]
        lo, hi = x.min(axis=0), x.max(axis=0)
        print("  position min [m]  " + "  ".join(f"{c:.6g}" for c in lo))
        print("  position max [m]  " + "  ".join(f"{c:.6g}" for c in hi))
        if "radius" in f:
            r = f["radius"][...]
            print(f"  radius [m]  min {r.min():.6g}  mean {r.mean():.6g}  max {r.max():.6g}")
        if "velocity" in f:
            speed = np.linalg.norm(f["velocity"][...], axis=1)
            print(f"  speed [m/s]  mean {speed.mean():.6g}  max {speed.max():.6g}")
        if "material" in f:
            mats, counts = np.unique(f["material"][...], return_counts=True)
            print("  materials  " + "  ".join(f"{m}:{c}" for m, c in zip(mats, counts)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("paths", nargs="+", help="snapshot files (*.h5) or directories")
    args = ap.parse_args()
    status = 0
    for p in files_from(args.paths):
        try:
            summarise(p)
        except (OSError, KeyError) as e:
            print(f"{p}: cannot read snapshot: {e}", file=sys.stderr)
            status = 1
    return status


if __name__ == "__main__":
    sys.exit(main())
