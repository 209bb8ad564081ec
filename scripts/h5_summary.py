#!/usr/bin/env python3
"""Print what grainflow particle snapshots and checkpoints hold: time, step, count, bounds.

    scripts/h5_summary.py out/particles_000010.h5 [more files or output folders ...]

A file argument is summarised whatever its name: a snapshot (particles_*.h5) or a checkpoint
(checkpoint_*.h5, whose particles are stored under /particles/).

An output folder argument summarises the snapshots of the run that wrote it, the ones its
particles.xdmf lists, in its order. Other particles_*.h5 files in the folder are counted and
named in a note, not summarised: those that cannot be read as damaged or truncated (such as a
gap a restart reported), the others as left over from an earlier run in the same folder.
Without a readable particles.xdmf (missing, or damaged: said in a note, with the remedy) the
snapshots are those carrying the scene_fingerprint of the newest readable file, in number
order while their step increases, up to the last complete row of the folder's log.csv (the
last run's log); snapshots past it are named as ones it cannot tell apart (this run's, if it
was killed after them, or an earlier, longer run's of the same scene), and without log.csv
the note says that runs of one scene cannot be told apart. The folder's checkpoints are
summarised after them; one whose stored log is not the start of the folder's log.csv is
marked as left over from another run. A folder without any .h5 file is an error.

Material indices are printed as the snapshot's material names (root attribute
material_names; for a checkpoint, its stored scene). Coarse-grained parcels (an insertion's
coarse_grain: k) are counted as the run counts them, one per parcel, and beside that the
real particles they stand for (the real_count dataset, k^3 each) and the real particles'
radius (parcel radius / k): docs/models/coarse-graining.md "Output".

Material indices present are looked up one by one; an index outside material_names is
printed as such ("material 7 (not in material_names)").

Exit status: 0, or 1 when a file cannot be read, is neither a snapshot nor a checkpoint, or
holds impossible values (a coarse_grain k or a real_count not positive: a one-line message
naming the file and dataset), or a folder holds no .h5 file; 2 for usage.
Needs h5py and numpy (Debian: python3-h5py python3-numpy).
"""
import argparse
import os
import pathlib
import re
import signal
import sys
import xml.etree.ElementTree as ET

try:
    import h5py
    import numpy as np
except ImportError:  # this python3 lacks them: scripts/python.sh finds one that has them
    if os.environ.get("GRAINFLOW_PYTHON_CHOSEN"):
        raise
    _helper = os.path.join(os.path.dirname(os.path.realpath(__file__)), "python.sh")
    os.execv(_helper, [_helper, os.path.abspath(__file__), *sys.argv[1:]])

SNAPSHOT = re.compile(r"particles_(\d+)\.h5$")
CHECKPOINT = re.compile(r"checkpoint_\d+\.h5$")


class Unreadable(Exception):
    """A file or folder that cannot be summarised; the message names it."""



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

def attr(f, name, default=None):
    v = f.attrs.get(name, default)
    if isinstance(v, bytes):
        return v.decode("utf-8", "replace")
    return v.item() if hasattr(v, "item") and np.ndim(v) == 0 else v


def snapshot_head(path):
    """(time, step, scene_fingerprint) of a snapshot, or None when it cannot be read (a file
    damaged or truncated, or without the time and step attributes every snapshot carries)."""
    try:
        with h5py.File(path, "r") as f:
            return float(attr(f, "time")), int(attr(f, "step")), attr(f, "scene_fingerprint")
    except (OSError, KeyError, ValueError, TypeError):
        return None


def log_end(log):
    """(time, step) of the last complete row of a log table (log.csv), or None when it is
    missing or holds none. A last row without its newline (cut short by a killed run, or read
    while the run writes it) and a row that is not a number in every column are passed over,
    as plot_log.py does."""
    try:
        with open(log, "rb") as f:
            text = f.read().decode("utf-8-sig", "replace")
    except OSError:
        return None
    lines = text.splitlines()
    if not text.endswith(("\n", "\r")):
        lines = lines[:-1]
    header = lines[0].split(",") if lines else []
    if "time_s" not in header or "step" not in header:
        return None
    for line in reversed(lines[1:]):
        fields = line.split(",")
        try:
            row = [float(v) for v in fields]
        except ValueError:
            continue
        if len(row) == len(header):
            return row[header.index("time_s")], row[header.index("step")]
    return None


def xdmf_files(index):
    """The snapshot files particles.xdmf lists, in its order: the temporal collection's time
    steps are named after their files' stems (an empty snapshot has no DataItem). Raises
    ET.ParseError for an index that is not XML (damaged)."""
    try:
        root = ET.parse(index).getroot()
    except OSError as e:
        raise Unreadable(f"{index}: cannot read the snapshot index: {e.strerror or e}")
    series = root.find("Domain/Grid")
    if series is None:
        raise Unreadable(f"{index}: not a grainflow snapshot index (no Domain/Grid)")
    return [g.get("Name", "") + ".h5" for g in series.findall("Grid")]


def unindexed_run(folder, snapshots, heads, notes):
    """(chosen, left over, why) without a readable particles.xdmf: the snapshots with the
    newest readable one's scene_fingerprint, in number order while their step increases (a
    series that starts over is an earlier run's later files), and not past the last complete
    row of the folder's log.csv, the last run's log (an earlier, longer run of the same scene
    left its later snapshots beyond it). Those past it cannot be told from this run's own
    written after its last log row (a killed run): named in a note, not summarised.
    tutorials/run_index.py chooses the same way (keep the two alike)."""
    readable = [p for p in snapshots if heads[p] is not None]
    if not readable:
        return [], [], ""
    newest = max(readable, key=lambda p: p.stat().st_mtime)
    mark = heads[newest][2]
    chosen, leftover, over = [], [], []
    for p in readable:
        if heads[p][2] != mark:
            leftover.append(p)
        elif over or (chosen and heads[p][1] <= heads[chosen[-1]][1]):
            over.append(p)
        else:
            chosen.append(p)
    log = folder / "log.csv"
    end = log_end(log)
    if end is None:
        notes.append(f"{log} is missing or holds no complete row: snapshots an earlier run of "
                     "the same scene left in the folder cannot be told from this run's; all "
                     f"{len(chosen)} with the newest snapshot's scene_fingerprint are summarised")
        past = []
    else:
        past = [p for p in chosen if heads[p][1] > end[1]]
        chosen = [p for p in chosen if heads[p][1] <= end[1]]
    state = ("damaged particles.xdmf" if (folder / "particles.xdmf").exists()
             else "no particles.xdmf")
    notes.insert(0, f"{folder}: {state}; {len(chosen)} snapshot(s) with the "
                    f"scene_fingerprint of the newest one ({newest.name})"
                    + (f", up to the end of log.csv (step {end[1]:.0f}, t = {end[0]:.6g} s)"
                       if end else ""))
    if over:
        notes.append(f"{len(over)} particles_*.h5 file(s) in {folder} of the same scene are "
                     f"left over from an earlier run, not summarised: from {over[0].name} on "
                     "the step starts over (an earlier, longer run's later files): "
                     + ", ".join(p.name for p in over))
    if past:
        notes.append(f"cannot tell whether {len(past)} snapshot(s) of the same scene past the "
                     f"end of {log} are this run's (written after its last log row, if it was "
                     "killed) or left over from an earlier, longer run in the same folder; not "
                     "summarised (give them as file arguments): "
                     + ", ".join(p.name for p in past))
    return chosen, leftover, "another scene_fingerprint"


def folder_files(folder):
    """(files to summarise, notes) for an output folder."""
    notes = []
    h5 = sorted(p for p in folder.iterdir() if p.name.endswith(".h5") and p.is_file())
    if not h5:
        raise Unreadable(f"{folder}: no .h5 file in this folder (no snapshot or checkpoint)")
    snapshots = [p for p in h5 if SNAPSHOT.match(p.name)]
    checkpoints = [p for p in h5 if CHECKPOINT.match(p.name)]
    others = [p for p in h5 if p not in snapshots and p not in checkpoints]
    if not snapshots and not checkpoints:
        raise Unreadable(f"{folder}: no snapshot (particles_*.h5) or checkpoint in this folder; "
                         f"other .h5 files: {', '.join(p.name for p in others)} (give them as "
                         "file arguments)")
    index = folder / "particles.xdmf"
    listed = None
    if index.exists():
        try:
            listed = [folder / n for n in xdmf_files(index)]
        except ET.ParseError as e:
            notes.append(f"{index} cannot be read ({e}): damaged, e.g. by a power loss or an "
                         "operating-system crash during an append (docs/reliability.md); the "
                         "snapshots are chosen as without it. " + restart_advice(folder))
    # Files listed are summarised whatever their state (an error each if damaged); of the
    # others, the unreadable ones are said to be so, not taken for another run's.
    heads = {p: snapshot_head(p) for p in snapshots if listed is None or p not in listed}
    unreadable = [p for p in heads if heads[p] is None]
    if listed is not None:
        missing = [p for p in listed if not p.exists()]
        if missing:
            notes.append(f"{index} lists {len(missing)} snapshot(s) missing from the folder: "
                         + ", ".join(p.name for p in missing))
        chosen = [p for p in listed if p.exists()]
        leftover = [p for p in snapshots if p not in listed and p not in unreadable]
        notes.insert(0, f"{folder}: {len(chosen)} snapshot(s) listed in particles.xdmf")
        why = "not listed in particles.xdmf"
    else:
        chosen, leftover, why = unindexed_run(folder, snapshots, heads, notes)
    if unreadable:
        numbers = sorted(int(SNAPSHOT.match(p.name).group(1)) for p in chosen)
        inside = [p for p in unreadable
                  if numbers and numbers[0] < int(SNAPSHOT.match(p.name).group(1))
                  < numbers[-1]]
        notes.append(f"{len(unreadable)} particles_*.h5 file(s) in {folder} cannot be read "
                     "(damaged or truncated), not summarised: "
                     + ", ".join(p.name for p in unreadable)
                     + (f" ({len(inside)} of them inside the numbers of the series summarised: "
                        "a gap in it)" if inside else ""))
    if leftover:
        notes.append(f"{len(leftover)} other particles_*.h5 file(s) in {folder} are left over "
                     f"from other runs ({why}), not summarised: "
                     + ", ".join(p.name for p in leftover))
    if others:
        notes.append(f"{len(others)} other .h5 file(s) in {folder}, not part of a run's "
                     "series, not summarised (give them as file arguments): "
                     + ", ".join(p.name for p in others))
    return chosen + checkpoints, notes


def material_labels(f, group, indices):
    """{index: label} for the material indices present (and only those: an index may be any
    int32, so no list of every name up to the largest is built). A name from the root
    attribute material_names (for a checkpoint, its stored scene); an index outside the
    materials named is said to be so; without any names, the index itself."""
    indices = [int(m) for m in indices]
    names = attr(f, "material_names")
    if isinstance(names, str) and names:
        parts = names.split(",")
        return {m: parts[m] if 0 <= m < len(parts) else f"material {m} (not in material_names)"
                for m in indices}
    if group is not f and "scene/model" in f:  # a checkpoint: its scene's materials
        model = bytes(f["scene/model"][...]).decode("utf-8", "replace")
        listed = dict(re.findall(r"^materials\[(\d+)\]\.name = (.*)$", model, re.M))
        ks = np.atleast_1d(f.attrs.get("material_coarse_grain", []))
        real = np.atleast_1d(f.attrs.get("material_real", []))
        out = {}
        for i in indices:
            if 0 <= i < len(real) and str(int(real[i])) in listed:
                base = listed[str(int(real[i]))]
                k = ks[i] if i < len(ks) else 1
                out[i] = base if k == 1 else f"{base}[k={k:g}]"
            elif 0 <= i and str(i) in listed:
                out[i] = listed[str(i)]
            elif listed:
                out[i] = f"material {i} (not in the stored scene's materials)"
            else:
                out[i] = str(i)
        return out
    return {m: str(m) for m in indices}


def checkpoint_left_over(path, group_file):
    """Whether a checkpoint in a folder is another run's: its stored log is not the start of
    the folder's log.csv (a run's checkpoints keep its log up to their step)."""
    log = path.parent / "log.csv"
    if "log/table" not in group_file or not log.exists():
        return False
    table = bytes(group_file["log/table"][...])
    with open(log, "rb") as f:
        return f.read(len(table)) != table


def summarise(path, in_folder=False):
    with h5py.File(path, "r") as f:
        checkpoint = "particles" in f and isinstance(f["particles"], h5py.Group)
        snapshot = not checkpoint and (
            any(a in f.attrs for a in ("time", "step", "count"))
            or any(isinstance(f.get(d), h5py.Dataset) for d in ("id", "position")))
        if not snapshot and not checkpoint:
            raise Unreadable(f"{path}: neither a grainflow snapshot (no root attribute time, "
                             "step or count, no id or position dataset) nor a checkpoint "
                             "(no /particles group)")
        g = f["particles"] if checkpoint else f
        where = "/particles/" if checkpoint else "/"
        stored = g["id"].shape[0] if "id" in g else 0
        n = stored if checkpoint else int(attr(f, "count", stored))
        kind = "checkpoint" if checkpoint else "snapshot"
        mat = g["material"][...] if "material" in g and n > 0 else None
        # Coarse graining: each particle's k and the real particles it stands for.
        k = None
        if "coarse_grain" in g:
            k = g["coarse_grain"][...]
            k_from = f"dataset {where}coarse_grain"
        elif mat is not None and "material_coarse_grain" in f.attrs:
            ks = np.atleast_1d(f.attrs["material_coarse_grain"])
            bad = mat[(mat < 0) | (mat >= len(ks))]
            if len(bad):
                raise Unreadable(f"{path}: dataset {where}material holds index {int(bad[0])}, "
                                 f"outside the {len(ks)} entries of the root attribute "
                                 "material_coarse_grain")
            k = ks[mat]
            k_from = "root attribute material_coarse_grain"
        if k is not None and n > 0 and np.any(~(k > 0)):
            raise Unreadable(f"{path}: {k_from} holds {np.min(k):g}: a coarse-graining "
                             "factor k must be positive")
        if "real_count" in g:
            real = g["real_count"][...]
            if n > 0 and np.any(~(real > 0)):
                bad = np.flatnonzero(~(real > 0))
                raise Unreadable(f"{path}: dataset {where}real_count holds {real[bad[0]]:g} "
                                 f"(at {len(bad)} of its {real.size} entries, the first at "
                                 f"index {bad[0]}): each particle stands for at least one "
                                 "real particle")
        else:
            real = k**3 if k is not None else None
        parcels = k is not None and n > 0 and np.any(k != 1)
        print(f"{path}")
        if checkpoint and in_folder and checkpoint_left_over(path, f):
            print("  note: left over from another run (its stored log is not the start of "
                  "this folder's log.csv)")
        line = (f"  time {attr(f, 'time', float('nan')):.9g} s  step {attr(f, 'step', -1)}  "
                f"particles {n}")
        if parcels:
            line += (f" ({int((k != 1).sum())} parcels among them; together "
                     f"{real.sum():.12g} real particles)")
        if kind == "checkpoint":
            line += "  (checkpoint)"
        print(line)
        if n == 0:
            print("  (no particles)")
            return
        x = g["position"][...]
        lo, hi = x.min(axis=0), x.max(axis=0)
        print("  position min [m]  " + "  ".join(f"{c:.6g}" for c in lo))
        print("  position max [m]  " + "  ".join(f"{c:.6g}" for c in hi))
        r = g["radius"][...] if "radius" in g else None
        if r is not None:
            print(f"  radius [m]  min {r.min():.6g}  mean {r.mean():.6g}  max {r.max():.6g}"
                  + ("  (parcels as simulated)" if parcels else ""))
            if parcels:
                rr = r / k
                print(f"  real radius [m]  min {rr.min():.6g}  "
                      f"mean {np.average(rr, weights=real):.6g}  max {rr.max():.6g}  "
                      "(radius / k, mean over the real particles)")
        if "velocity" in g:
            speed = np.linalg.norm(g["velocity"][...], axis=1)
            print(f"  speed [m/s]  mean {speed.mean():.6g}  max {speed.max():.6g}")
        if mat is not None:
            mats, counts = np.unique(mat, return_counts=True)
            names = material_labels(f, g, mats)
            print("  materials  " + "  ".join(f"{names[int(m)]}:{c}"
                                              for m, c in zip(mats, counts)))
        if parcels:
            for kv in np.unique(k):
                if kv == 1:
                    continue
                sel = k == kv
                sizes = "" if r is None else (
                    f"; radius [m] parcels {r[sel].min():.6g} to {r[sel].max():.6g}, "
                    f"real particles {r[sel].min() / kv:.6g} to {r[sel].max() / kv:.6g}")
                print(f"  coarse grain k {kv:g}: {int(sel.sum())} parcels stand for "
                      f"{real[sel].sum():.12g} real particles ({kv**3:.12g} each){sizes}")


def main():
    ap = argparse.ArgumentParser(
        description=__doc__.splitlines()[0],
        epilog="A folder: the snapshots its particles.xdmf lists, then its checkpoints; "
               "files left over from other runs are named, not summarised.")
    ap.add_argument("paths", nargs="+", help="snapshot or checkpoint files (*.h5), or output folders")
    args = ap.parse_args()
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # `| head` ends the output quietly
    status = 0
    for a in args.paths:
        p = pathlib.Path(a)
        try:
            if p.is_dir():
                files, notes = folder_files(p)
                for note in notes:
                    print(f"note: {note}")
                items = [(q, True) for q in files]
            elif not p.exists():
                raise Unreadable(f"{p}: no such file or folder")
            else:
                items = [(p, False)]
        except (Unreadable, OSError) as e:
            print(f"h5_summary.py: {e}", file=sys.stderr)
            status = 1
            continue
        for q, in_folder in items:
            try:
                summarise(q, in_folder)
            except Unreadable as e:
                sys.stdout.flush()
                print(f"h5_summary.py: {e}", file=sys.stderr)
                status = 1
            except (OSError, KeyError, ValueError, TypeError, IndexError) as e:
                sys.stdout.flush()
                print(f"h5_summary.py: {q}: cannot read as a grainflow snapshot or checkpoint: "
                      f"{e}", file=sys.stderr)
                status = 1
    return status


if __name__ == "__main__":
    sys.exit(main())
