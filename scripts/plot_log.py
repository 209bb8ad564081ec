#!/usr/bin/env python3
"""Plot columns of a grainflow log table (CSV) against time into a PNG.

    scripts/plot_log.py out/log.csv -c ke_trans_J ke_rot_J -o energy.png [--logy]

Each column gets its own panel (the columns have different units); all share the time axis.
A damaged row (not a number in every column) is left out and reported with its line number,
on stderr and in the closing "wrote" line; a last row cut short by a killed run likewise.
A missing, binary or non-log input, or an -o whose folder does not exist, whose extension
is not an image format matplotlib writes (.png, .pdf, .svg, ...), or that is the log itself,
is a one-line error, exit status 1 (2 for a usage error). A byte-order mark at the start of
the log is ignored. An -o without an extension writes <name>.png, and says so.
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


def fail(message):
    """A clear one-line error, exit status 1."""
    sys.exit(f"plot_log.py: {message}")


def read_table(path):
    """(header, data rows, skipped) from a log table; skipped lists (line number, reason) of
    each damaged row left out. A last row without its newline was cut short by a killed run."""
    if os.path.isdir(path):
        fail(f"{path} is a folder, not a log table (a run writes its table as "
             f"{os.path.join(path, 'log.csv')})")
    try:
        with open(path, "rb") as f:
            raw = f.read()
    except FileNotFoundError:
        fail(f"{path}: no such file")
    except OSError as e:
        fail(f"{path}: cannot read: {e.strerror or e}")
    if raw.startswith(b"\x89HDF") or b"\0" in raw[:65536]:
        fail(f"{path} is a binary file (an HDF5 snapshot or checkpoint?), not a CSV log table")
    try:
        text = raw.decode("utf-8-sig")  # a byte-order mark (an editor's) is not the header's
    except UnicodeDecodeError as e:
        fail(f"{path} is not a text CSV log table (byte {e.start} is not UTF-8)")
    lines = text.splitlines()
    # A log's fields are short numbers; a damaged one may be long (csv's default limit is
    # 131072 characters, past which it raises): allow any field the file can hold.
    csv.field_size_limit(max(len(text), csv.field_size_limit()))
    if not lines or not lines[0].strip():
        fail(f"{path}: empty file, expected a header line")
    header = next(csv.reader([lines[0]]))
    if "time_s" not in header and "step" not in header:
        fail(f"{path}: the first line is not a grainflow log header (time_s,step,...): "
             f"{lines[0][:60]!r}")
    values, skipped = [], []
    for number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        fields = next(csv.reader([line]))
        try:
            row = [float(v) for v in fields]
        except ValueError:
            row = None
        # Even a last row that parses may be cut short (its wall_s cut to fewer digits).
        cut = number == len(lines) and not text.endswith(("\n", "\r"))
        if cut or row is None or len(row) != len(header):
            reason = ("cut short (no newline at its end: a run killed while writing)" if cut
                      else f"{len(fields)} fields, not {len(header)} numbers")
            skipped.append((number, reason))
            continue
        values.append(row)
    data = np.array(values, dtype=float).reshape(-1, len(header))
    return header, data, skipped


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("log", help="log table written by the run (CSV)")
    ap.add_argument("-c", "--columns", nargs="+", default=DEFAULT_COLUMNS,
                    help=f"columns to plot (default: {' '.join(DEFAULT_COLUMNS)})")
    ap.add_argument("-x", default="time_s", help="column for the horizontal axis (default time_s)")
    ap.add_argument("-o", "--output", default="log.png", help="PNG file to write (default log.png)")
    ap.add_argument("--logy", action="store_true", help="logarithmic vertical axes")
    args = ap.parse_args()

    out_dir = os.path.dirname(os.path.abspath(args.output))
    if os.path.isdir(args.output):
        fail(f"-o {args.output} is a folder; give the PNG file's name")
    if not os.path.splitext(args.output)[1]:
        args.output += ".png"  # what matplotlib writes for a name without an extension
    if not os.path.isdir(out_dir):
        fail(f"-o {args.output}: no folder {out_dir} to write it in")
    if os.path.realpath(args.output) == os.path.realpath(args.log):
        fail(f"-o {args.output} is the log table itself ({args.log}); give another file "
             "name for the plot")
    ext = os.path.splitext(args.output)[1].lstrip(".").lower()
    formats = plt.gcf().canvas.get_supported_filetypes()
    plt.close("all")
    if ext and ext not in formats:
        fail(f"-o {args.output}: matplotlib cannot write .{ext} files; give a name ending in "
             + ", ".join("." + f for f in sorted(formats)))
    header, data, skipped = read_table(args.log)
    unknown = [c for c in [args.x] + args.columns if c not in header]
    if unknown:
        fail(f"{args.log}: no column {', '.join(unknown)}; valid columns: {', '.join(header)}")
    for number, reason in skipped:
        print(f"plot_log.py: {args.log}:{number}: damaged row skipped: {reason}",
              file=sys.stderr)
    if len(data) == 0:
        fail(f"{args.log}: no complete data row to plot")

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
    try:
        fig.savefig(args.output, dpi=120)
    except OSError as e:
        fail(f"-o {args.output}: cannot write: {e.strerror or e}")
    note = ""
    if skipped:
        note = (f"; skipped {len(skipped)} damaged row(s), line(s) "
                + ", ".join(str(n) for n, _ in skipped))
    print(f"wrote {args.output} ({len(x)} rows{note})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
