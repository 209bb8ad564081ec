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
