"""Reading a grainFoam tutorial case's OpenFOAM output: dictionary entries and the
surfaceFieldValue series the tutorials' analyse.py scripts plot (shared by fluidisedBed,
heatedBed and largeBed)."""
import glob
import os
import re
import sys

import numpy as np


def foam_entry(path, key):
    """The value of the first `key value;` entry of an OpenFOAM dictionary (a string)."""
    text = open(path).read()
    m = re.search(r"^\s*" + key + r"\s+([^;]+);", text, re.M)
    if not m:
        sys.exit(f"analyse.py: no '{key}' in {path}")
    return m.group(1).strip().strip('"')


def series(case, name):
    """(time, value, area) of the surfaceFieldValue function object `name` in `case`;
    restarts are appended (a repeated time is kept once); area from the file's header, or None."""
    files = sorted(glob.glob(f"{case}/postProcessing/{name}/*/surfaceFieldValue*.dat"),
                   key=lambda f: float(os.path.basename(os.path.dirname(f))))
    if not files:
        sys.exit(f"analyse.py: no {case}/postProcessing/{name}/*/surfaceFieldValue.dat; "
                 "has grainFoam run?")
    area = None
    data = []
    for f in files:
        for line in open(f):
            if line.startswith("# Area"):
                area = float(line.split(":")[1])
            elif line.strip() and not line.startswith("#"):
                data.append([float(v) for v in line.split()[:2]])
    d = np.array(data)
    _, keep = np.unique(d[:, 0], return_index=True)
    return d[keep, 0], d[keep, 1], area


WALL_LOADS = re.compile(r"^grainFoam wall loads over the last (\S+) s \(mean force of the particles "
                        r"on each wall, N\):(.*); all walls carry (\S+) of the particles' "
                        r"buoyant weight", re.M)


def wall_load_shares(log_path):
    """The walls' share of the particles' buoyant weight from grainFoam's `wall loads` lines
    (scene key output.wall_loads): an array of rows (end time [s], interval [s], share), one
    per write time; empty without such lines. The end time is that of the `Time = ` line
    before each."""
    if not os.path.exists(log_path):
        return np.zeros((0, 3))
    rows, now = [], None
    for line in open(log_path):
        if line.startswith("Time = "):
            now = float(line.split()[2])
        elif line.startswith("grainFoam wall loads") and now is not None:
            m = WALL_LOADS.match(line)
            if m:
                rows.append((now, float(m.group(1)), float(m.group(3))))
    return np.array(rows).reshape(-1, 3)


def mean_wall_share(log_path, t_from):
    """The walls' mean share of the buoyant weight over the write intervals that lie after
    t_from (weighted by their length), and the time span covered; (nan, 0) without lines."""
    rows = wall_load_shares(log_path)
    inside = rows[rows[:, 0] - rows[:, 1] >= t_from - 1e-9] if len(rows) else rows
    if not len(inside) or inside[:, 1].sum() <= 0:
        return float("nan"), 0.0
    return float(np.dot(inside[:, 1], inside[:, 2]) / inside[:, 1].sum()), float(inside[:, 1].sum())
