#!/usr/bin/env python3
"""Plot columns of a grainflow log table (CSV) against time into a PNG.

    scripts/plot_log.py out/log.csv -c ke_trans_J ke_rot_J -o energy.png [--logy]

Each column gets its own panel (the columns have different units); all share the time axis.
Needs matplotlib and numpy (Debian: python3-matplotlib); no display is required.
"""
import argparse
import csv
import os
import sys

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
except ImportError:  # this python3 lacks them: scripts/python.sh finds one that has them
    if os.environ.get("GRAINFLOW_PYTHON_CHOSEN"):
        raise
    _helper = os.path.join(os.path.dirname(os.path.realpath(__file__)), "python.sh")
    os.execv(_helper, [_helper, os.path.abspath(__file__), *sys.argv[1:]])

DEFAULT_COLUMNS = ["particles", "ke_trans_J", "ke_rot_J", "max_overlap_ratio"]


def read_table(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        sys.exit(f"{path}: empty file, expected a header line")
    header = rows[0]
    values = []
    for r in rows[1:]:
        try:
            values.append([float(v) for v in r])
        except ValueError:
            continue  # a last line cut short by a killed run
        if len(values[-1]) != len(header):
            values.pop()
    data = np.array(values, dtype=float).reshape(-1, len(header))
    return header, data


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("log", help="log table written by the run (CSV)")
    ap.add_argument("-c", "--columns", nargs="+", default=DEFAULT_COLUMNS,
                    help=f"columns to plot (default: {' '.join(DEFAULT_COLUMNS)})")
    ap.add_argument("-x", default="time_s", help="column for the horizontal axis (default time_s)")
    ap.add_argument("-o", "--output", default="log.png", help="PNG file to write (default log.png)")
    ap.add_argument("--logy", action="store_true", help="logarithmic vertical axes")
    args = ap.parse_args()

    header, data = read_table(args.log)
    unknown = [c for c in [args.x] + args.columns if c not in header]
    if unknown:
        sys.exit(f"{args.log}: no column {', '.join(unknown)}; valid columns: {', '.join(header)}")

    x = data[:, header.index(args.x)]
    fig, axes = plt.subplots(len(args.columns), 1, sharex=True, squeeze=False,
                             figsize=(7, 2.2 * len(args.columns) + 0.6))
    for ax, name in zip(axes[:, 0], args.columns):
        ax.plot(x, data[:, header.index(name)], lw=1.2)
        ax.set_ylabel(name)
        if args.logy:
            ax.set_yscale("log")
        ax.grid(True, alpha=0.3)
    axes[-1, 0].set_xlabel(args.x)
    fig.tight_layout()
    fig.savefig(args.output, dpi=120)
    print(f"wrote {args.output} ({len(x)} rows)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
