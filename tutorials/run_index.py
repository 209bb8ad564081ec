"""The snapshots and the log table of the run that wrote an output folder, for the tutorials'
analyse.py.

A folder may also hold snapshots an earlier run left there (a longer run's later files): the
run's own index, particles.xdmf, lists only its own (docs/scene-reference.md, "One run per
output folder"). Without a readable index the snapshots are chosen the way
scripts/h5_summary.py chooses them (keep the two alike): the newest readable snapshot's
scene_fingerprint, in number order while the step increases, and not past the last complete
row of the folder's log.csv (the last run's log; an earlier, longer run of the same scene left
its later files beyond it). Notes go to stderr.
"""
import csv
import os
import re
import sys
import xml.etree.ElementTree as ET

SNAPSHOT = re.compile(r"particles_(\d+)\.h5$")



def restart_advice(folder):
    """How to have a folder's particles.xdmf rewritten: a restart of the run that wrote it.
    A grainFoam case's folder (system/controlDict beside or above it) is restarted by
    grainFoam; `grain run --restart` would run its scene without the fluid over its files."""
    folder = os.path.abspath(str(folder))
    for up in (folder, os.path.dirname(folder), os.path.dirname(os.path.dirname(folder))):
        if os.path.isfile(os.path.join(up, "system", "controlDict")):
            return ("A restart of grainFoam (startFrom latestTime in system/controlDict of " + up
                    + ") from a time before the run's end rewrites the index from the snapshot "
                    "files (and runs on from there); not grain run --restart, which would run "
                    "the coupled scene without its fluid over these files")
    return ("A restart (grain run --restart) from one of the folder's checkpoints before the "
            "run's end rewrites the index from the snapshot files (and runs on from there)")

def note(message):
    print(f"analyse.py: note: {message}", file=sys.stderr)


def read_log(path):
    """(header, rows, skipped) of a grainflow log table (log.csv): rows is a list of lists of
    floats, one per complete row; skipped lists (line number, reason) of each row left out: a
    row that is not a number in every column, and a last row without its newline (cut short by
    a killed run, or read while the run writes it: its last field may have lost digits), as
    scripts/plot_log.py does. Raises OSError when the file cannot be read, ValueError when its
    first line is not a log header."""
    with open(path, "rb") as f:
        text = f.read().decode("utf-8-sig", "replace")
    lines = text.splitlines()
    header = next(csv.reader([lines[0]])) if lines else []
    if "time_s" not in header or "step" not in header:
        raise ValueError(f"{path}: the first line is not a grainflow log header (time_s,step,...)")
    rows, skipped = [], []
    for number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        fields = next(csv.reader([line]))
        cut = number == len(lines) and not text.endswith(("\n", "\r"))
        try:
            row = [float(v) for v in fields]
        except ValueError:
            row = None
        if cut or row is None or len(row) != len(header):
            skipped.append((number, "cut short (no newline at its end: a run killed while "
                                    "writing it, or a log read while the run writes it)" if cut
                            else f"{len(fields)} fields, not {len(header)} numbers"))
            continue
        rows.append(row)
    return header, rows, skipped


def log_columns(folder, *names):
    """{name: list of floats} of the complete rows of folder/log.csv; each row left out is
    named in a note (file:line and why). Exits with a message when the log cannot be read,
    lacks a column or holds no complete row."""
    log = os.path.join(folder, "log.csv")
    try:
        header, rows, skipped = read_log(log)
    except OSError as e:
        sys.exit(f"analyse.py: cannot read {log}, the run's log table: {e.strerror or e}")
    except ValueError as e:
        sys.exit(f"analyse.py: {e}")
    missing = [n for n in names if n not in header]
    if missing:
        sys.exit(f"analyse.py: {log} has no column {', '.join(missing)} (columns: "
                 f"{', '.join(header)})")
    for number, reason in skipped:
        note(f"{log}:{number}: row left out: {reason}")
    if not rows:
        sys.exit(f"analyse.py: {log} holds no complete row")
    return {n: [r[header.index(n)] for r in rows] for n in names}


def _head(path):
    """(time, step, scene_fingerprint) of a snapshot, or None when it cannot be read."""
    import h5py  # only without an index: reading particles.xdmf needs no h5py

    try:
        with h5py.File(path, "r") as f:
            fp = f.attrs.get("scene_fingerprint")
            fp = fp.decode() if isinstance(fp, bytes) else (None if fp is None else str(fp))
            return float(f.attrs["time"]), int(f.attrs["step"]), fp
    except (OSError, KeyError, ValueError, TypeError):
        return None


def _without_index(folder, index, why):
    """The run's snapshots chosen without its index (module docstring), with notes."""
    found = sorted((int(m.group(1)), name) for name in os.listdir(folder)
                   for m in [SNAPSHOT.match(name)] if m)
    heads = {name: _head(os.path.join(folder, name)) for _, name in found}
    unreadable = [name for _, name in found if heads[name] is None]
    readable = [name for _, name in found if heads[name] is not None]
    if unreadable:
        note(f"{len(unreadable)} snapshot(s) in {folder} cannot be read (damaged or truncated), "
             "left out: " + ", ".join(unreadable))
    if not readable:
        sys.exit(f"analyse.py: {index} {why}, and {folder} holds no readable particles_*.h5")
    newest = max(readable, key=lambda n: os.path.getmtime(os.path.join(folder, n)))
    mark = heads[newest][2]
    series, other, over = [], [], False
    for name in readable:
        # A step not after the one before: the numbering starts over, an earlier run's
        # later files from here on.
        over = over or bool(heads[name][2] == mark and series
                            and heads[name][1] <= heads[series[-1]][1])
        (other if over or heads[name][2] != mark else series).append(name)
    log = os.path.join(folder, "log.csv")
    try:
        header, rows, _ = read_log(log)
        end = (rows[-1][header.index("time_s")], rows[-1][header.index("step")]) if rows else None
    except (OSError, ValueError):
        end = None
    past = []
    if end is None:
        note(f"{log} is missing or holds no complete row: snapshots an earlier run of the same "
             "scene left in the folder cannot be told from this run's; all with the newest "
             "snapshot's scene_fingerprint are used")
    else:
        past = [n for n in series if heads[n][1] > end[1]]
        series = [n for n in series if heads[n][1] <= end[1]]
    note(f"{index} {why}; using the {len(series)} snapshot(s) {series[0] if series else ''}"
         f"{' ... ' + series[-1] if len(series) > 1 else ''} chosen without it (the scene_"
         f"fingerprint of the newest snapshot{', up to the end of log.csv' if end else ''}). "
         + restart_advice(folder))
    if other:
        note(f"{len(other)} snapshot(s) in {folder} are left over from other runs (another "
             "scene_fingerprint, or a series that starts over), not used: " + ", ".join(other))
    if past:
        note(f"cannot tell whether {len(past)} snapshot(s) past the end of {log} (step "
             f"{end[1]:.0f}, t = {end[0]:.6g} s) are this run's (written after its last log "
             "row, if it was killed) or left over from an earlier, longer run of the same "
             "scene; not used: " + ", ".join(past))
    if not series:
        sys.exit(f"analyse.py: no snapshot of the run that wrote {folder} could be chosen "
                 f"without {index} (notes above)")
    return [os.path.join(folder, n) for n in series]


def run_snapshots(folder):
    """The snapshot files of the run that wrote `folder`, in time order, from the run's own
    index particles.xdmf: snapshots an earlier run left in the folder are not listed there.
    A missing or unreadable index: chosen without it (module docstring), with notes."""
    index = os.path.join(folder, "particles.xdmf")
    if not os.path.isdir(folder):
        sys.exit(f"analyse.py: no output folder {folder}")
    if not os.path.exists(index):
        return _without_index(folder, index, "is missing")
    try:
        steps = ET.parse(index).getroot().find("Domain/Grid")
    except ET.ParseError as e:
        return _without_index(folder, index, f"cannot be read ({e}: damaged, e.g. by a power "
                                             "loss or an operating-system crash during an "
                                             "append, docs/reliability.md)")
    except OSError as e:
        sys.exit(f"analyse.py: cannot read {index}, the run's list of its snapshots: "
                 f"{e.strerror or e}")
    files = [] if steps is None else \
        [os.path.join(folder, g.get("Name", "") + ".h5") for g in steps.findall("Grid")]
    if not files:
        sys.exit(f"analyse.py: {index} lists no snapshot")
    missing = [f for f in files if not os.path.isfile(f)]
    if missing:
        sys.exit(f"analyse.py: {missing[0]}, a snapshot {index} lists, is missing"
                 + (f" ({len(missing)} of its {len(files)} are)" if len(missing) > 1 else ""))
    return files


if __name__ == "__main__":  # a check by hand: the files chosen for a folder
    for path in run_snapshots(sys.argv[1] if len(sys.argv) > 1 else "output"):
        print(path)
