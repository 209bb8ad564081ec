#!/usr/bin/env python3
"""Every default docs/scene-reference.md states is what the code does (grain.documented_defaults).

A default that never did what the docs said is a silent wrong answer: the user who leaves a
key out believes the documented value is in force. For every row of the reference's tables
with a stated default, this test runs a small scene three times with `grain` (or asks
`grain check`, for keys that only change what it reports):

- the key left out,
- the key written with the documented value (computed, where the docs give a rule such as
  `end / 20` or `0.4 x the largest radius`),
- the key written with another value.

The first two must give the same outcome bit for bit: exit status, the printed report (wall
clock figures removed), every file of the output folder (log.csv without its wall_s column,
every dataset and attribute of every HDF5 file). The third must differ from them, which shows
that the scene depends on the key at all (a scene in which the key changes nothing would make
the first comparison empty).

The reference's tables are read from the page itself: every row whose default is not
"required" or "-" must be checked here or listed in SKIPPED with the reason, so a new row
makes this test fail until it is decided how to check it.

Usage: documented_defaults.py GRAIN REFERENCE.md WORK_DIR [--mpiexec MPIEXEC]
                              [--only KEY_SUBSTRING]
"""
import concurrent.futures
import copy
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import threading

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "..",
                                "support"))
from singleton import isolated_singleton  # noqa: E402  (tests/support/singleton.py)

grain, reference, work = (os.path.abspath(a) for a in sys.argv[1:4])
MPIEXEC = sys.argv[sys.argv.index("--mpiexec") + 1] if "--mpiexec" in sys.argv else "mpiexec"
only = sys.argv[sys.argv.index("--only") + 1] if "--only" in sys.argv else None
here = os.path.dirname(os.path.abspath(__file__))
data = os.path.normpath(os.path.join(here, "..", "..", "data"))


# ---------------------------------------------------------------- the reference's tables

def documented_rows(path):
    """(section, key, default) of every table row with a default column; `section` is the
    nearest heading, and for several tables under one heading the paragraph before the table."""
    rows, heading, cols, para, blank = [], None, None, "", True
    for line in open(path, encoding="utf-8"):
        line = line.rstrip("\n")
        starts, blank = blank, not line.strip()
        m = re.match(r"^#+\s+(.*)", line)
        if m:
            heading, cols, para = m.group(1), None, ""
            continue
        if line.startswith("|"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if cols is None:
                cols = [c.lower() for c in cells]
                continue
            if set(line) <= set("|-: "):
                continue
            if "default" in cols:
                keys = re.findall(r"`([a-z_]+)`", cells[0])
                default = cells[cols.index("default")]
                for k in keys[:1] if len(keys) == 1 else []:
                    rows.append((heading, para, k, default))
        else:
            cols = None
            if line.strip() and starts:
                para = line.strip()
    return rows


def literal(default):
    """The value a default cell writes literally (`0.5`, `[0, 0, 0]`, `history`, `true`), or
    None for a rule or a description (`end / 20`, `wall<i>`, `hydrostatic, no extra gradient`)."""
    m = re.fullmatch(r"`([^`]*)`(\s*\(.*\))?", default.strip())
    text = m.group(1) if m else default.strip()
    try:
        return json.loads(text)
    except ValueError:
        return text if re.fullmatch(r"[a-z_]+", text) and m else None


def stated(default):
    """Whether a default cell states a value (not a requirement or an absence)."""
    d = default.strip().lower()
    return not (d == "" or d.startswith("required") or d.startswith("—") or d.startswith("-"))


# ---------------------------------------------------------------- scenes and runs

BASE = {
    "domain": {"min": [0, 0, 0], "max": [0.01, 0.01, 0.02]},
    "gravity": [0, 0, -9.81],
    "time": {"rayleigh_fraction": 0.1, "end": 0.01},
    "materials": [{"name": "glass", "youngs_modulus": 5e6, "poisson_ratio": 0.3,
                   "density": 2500}],
    # Elastic (e = 1): the start-up then needs no search for the damping that gives e, which
    # takes a third of a second per restitution (dem/contact/restitution_mapping.cpp).
    "interactions": [{"materials": ["glass", "glass"], "restitution": 1.0, "friction": 0.5}],
    "contact": {"normal": "hertz"},
    "walls": [
        {"type": "plane", "name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1],
         "material": "glass"},
        {"type": "plane", "name": "left", "point": [0, 0, 0], "normal": [1, 0, 0],
         "material": "glass"},
        {"type": "plane", "name": "right", "point": [0.01, 0, 0], "normal": [-1, 0, 0],
         "material": "glass"},
        {"type": "plane", "name": "front", "point": [0, 0, 0], "normal": [0, 1, 0],
         "material": "glass"},
        {"type": "plane", "name": "back", "point": [0, 0.01, 0], "normal": [0, -1, 0],
         "material": "glass"},
    ],
    "insert": [{"type": "fill", "region": {"box": {"min": [0, 0, 0], "max": [0.01, 0.01, 0.01]}},
                "count": 40, "material": "glass",
                "radius": {"distribution": "uniform", "min": 4e-4, "max": 6e-4},
                "velocity": [0.2, 0.1, 0]}],
    "output": {"snapshot_interval": 0.0025},
}

HEAT = {"materials": [{"name": "glass", "youngs_modulus": 5e6, "poisson_ratio": 0.3,
                       "density": 2500, "heat_capacity": 840, "conductivity": 1.0}]}

MISSING = object()


def get(scene, path):
    node = scene
    for k in path:
        if isinstance(node, list):
            node = node[k]
        elif k in node:
            node = node[k]
        else:
            return MISSING
    return node


def put(scene, path, value):
    node = scene
    for k in path[:-1]:
        if isinstance(node, dict) and k not in node:
            node[k] = {}
        node = node[k]
    if value is MISSING:
        if isinstance(node, dict):
            node.pop(path[-1], None)
    else:
        node[path[-1]] = value


def normalised_report(text):
    out, progress = [], False
    for line in text.splitlines():
        if line.startswith("time: start-up") or "particle-steps/s" in line and line.startswith("t = "):
            if line.startswith("t = ") and not progress:
                out.append("<progress>")
            progress = line.startswith("t = ")
            continue
        progress = False
        line = re.sub(r", [0-9.e+-]+ s wall, [0-9.e+-]+ particle-steps/s", ", <wall>", line)
        # The particle files read, by their folder (each run has its own) and time written.
        line = re.sub(r"^(input: \S+ reads ).*/([^/]+) \(modified [^)]*\)$", r"\1\2", line)
        # A note's place in the file: a key written out moves the lines after it.
        line = re.sub(r"^scene\.yaml:\d+:\d+: note:", "scene.yaml:<line>: note:", line)
        out.append(line)
    return "\n".join(out)


def log_without_wall(text):
    """A log table's text without its wall-clock column."""
    rows = [row.split(",") for row in text.splitlines()]
    wall = rows[0].index("wall_s") if rows and "wall_s" in rows[0] else None
    return "\n".join(",".join(c for i, c in enumerate(row) if i != wall) for row in rows)


def digest_h5(path):
    h = hashlib.sha256()
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            h.update(name.encode())
            for k in sorted(obj.attrs):
                h.update(k.encode() + repr(np.asarray(obj.attrs[k]).tolist()).encode())
            if isinstance(obj, h5py.Dataset):
                data = np.ascontiguousarray(obj[()]).tobytes()
                if name == "log/table":  # a checkpoint's copy of log.csv: without wall_s
                    data = log_without_wall(data.decode()).encode()
                h.update(data)
        for k in sorted(f.attrs):
            # The scene's fingerprint hashes the insertions' keys as given (`stop` left out or
            # given as time.end): a name of the run, not something it computed.
            if k != "scene_fingerprint":
                h.update(k.encode() + repr(np.asarray(f.attrs[k]).tolist()).encode())
        f.visititems(visit)
    return h.hexdigest()


def outcome(folder, scene, command="run", extra_files=(), ranks=1):
    """Runs `grain command scene.yaml` in a fresh `folder`; returns what must match (and, as
    "radii", the radii of the first snapshot, to compute a default from)."""
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    for f in extra_files:
        shutil.copy(f, folder)
    with open(os.path.join(folder, "scene.yaml"), "w") as out:
        json.dump(scene, out, indent=1)  # JSON is YAML
    cmd = [grain, command, "scene.yaml"]
    if ranks > 1:
        cmd = [MPIEXEC, "-np", str(ranks), "--oversubscribe"] + cmd
        r = subprocess.run(cmd, cwd=folder, capture_output=True, text=True, timeout=300)
    else:  # a singleton without Open MPI's daemon: 0.2 s less per run, the same program
        with isolated_singleton() as env:
            r = subprocess.run(cmd, cwd=folder, capture_output=True, text=True, timeout=300,
                               env=env)
    result = {"status": r.returncode, "report": normalised_report(r.stdout + r.stderr)}
    inputs = {"scene.yaml"} | {os.path.basename(f) for f in extra_files}
    for dirpath, _, files in os.walk(folder):
        for name in sorted(files):
            full = os.path.join(dirpath, name)
            rel = os.path.relpath(full, folder)
            if rel in inputs:
                continue
            if name.endswith(".h5"):
                result[rel] = digest_h5(full)
                if name.startswith("particles_") and "radii" not in result:
                    with h5py.File(full, "r") as h:
                        result["radii"] = h["radius"][()] if "radius" in h else None
            elif name == "log.csv":  # without the wall-clock column
                result[rel] = hashlib.sha256(log_without_wall(open(full).read()).encode()).hexdigest()
            else:
                result[rel] = hashlib.sha256(open(full, "rb").read()).hexdigest()
    return result


# ---------------------------------------------------------------- the checks

class Check:
    def __init__(self, section, key, path, default, other, base=None, command="run",
                 files=(), ranks=1, other_base=None):
        self.section, self.key, self.path = section, key, path
        self.default, self.other = default, other
        self.base, self.command, self.files, self.ranks = base, command, list(files), ranks
        self.other_base = other_base  # applied to the scene with the other value only

    def scene(self):
        s = copy.deepcopy(BASE)
        if self.base:
            self.base(s)
        return s


def with_(**changes):
    """Sets keys of the scene: a__0__b is scene["a"][0]["b"]."""
    def apply(s):
        for k, v in changes.items():
            path = tuple(int(p) if p.isdigit() else p for p in k.split("__"))
            put(s, path, copy.deepcopy(v) if v is not MISSING else MISSING)
    return apply


def chain(*fs):
    def apply(s):
        for f in fs:
            f(s)
    return apply


def heat_on(s):
    s["materials"] = copy.deepcopy(HEAT["materials"])
    s["heat"] = {}
    s["insert"][0]["temperature"] = 300
    s["walls"][0]["temperature"] = 350  # the floor heats the beads


def no_walls_but_floor(s):
    s["walls"] = s["walls"][:1]


def drum(s):
    s["domain"] = {"min": [-0.006, -0.006, 0], "max": [0.006, 0.006, 0.01],
                   "periodic": [False, False, True]}
    s["gravity"] = [0, -9.81, 0]
    s["walls"] = [{"type": "cylinder", "axis_point": [0, 0, 0], "axis": [0, 0, 1],
                   "radius": 0.005, "material": "glass"}]
    s["insert"][0]["region"] = {"cylinder": {"base": [0, 0, 0], "axis": [0, 0, 1],
                                             "radius": 0.004, "height": 0.01}}


def stream(s):
    s["insert"] = [{"type": "stream", "face": {"disc": {"centre": [0.005, 0.005, 0.018],
                                                        "normal": [0, 0, -1], "radius": 0.003}},
                    "count_rate": 4000, "material": "glass",
                    "radius": {"distribution": "constant", "value": 5e-4},
                    "velocity": [0, 0, -0.5]}]


def one_way_fluid(s):
    s["fluid"] = {"density": 1000, "viscosity": 1e-3, "drag": "di_felice", "model": "B",
                  "forces": ["drag", "pressure_gradient", "viscous"]}


def tilted_plate(close=0.0):
    """plate.stl: a 1 cm square from z = 0 at x = 0 to z = 1 mm at x = 1 cm, as two triangles
    whose shared corner (0.01, 0.01) is written `close` apart in the second (a CAD seam)."""
    path = os.path.join(work, "plate.stl" if close == 0 else "seam.stl")
    c = 0.01 + close
    with open(path, "w") as out:
        out.write(f"""solid plate
facet normal 0 0 1
 outer loop
  vertex 0 0 0
  vertex 0.01 0 0.001
  vertex 0.01 0.01 0.001
 endloop
endfacet
facet normal 0 0 1
 outer loop
  vertex 0 0 0
  vertex {c!r} {c!r} 0.001
  vertex 0 0.01 0
 endloop
endfacet
endsolid plate
""")
    return path


def mesh_floor(name):
    def apply(s):
        s["walls"][0] = {"type": "mesh", "file": name, "material": "glass"}
    return apply


def floor_motion(**motion):
    def apply(s):
        s["walls"][0]["motion"] = dict(motion)
    return apply


def heat_quiet(s):
    """Heat on, every bead and wall at 300 K: the temperatures stay 300 K exactly."""
    heat_on(s)
    del s["walls"][0]["temperature"]


def snapshot_insert(name):
    def apply(s):
        s["insert"] = [{"type": "snapshot", "file": name}]
    return apply


def convection(s):
    heat_on(s)
    one_way_fluid(s)
    s["fluid"].update({"temperature": 400, "heat_capacity": 4180, "conductivity": 0.6})


PLAIN_FIELDS = ["id", "position", "velocity", "angular_velocity", "radius", "diameter", "mass",
                "material"]


def checks():
    plate = os.path.basename(tilted_plate())
    seam = os.path.basename(tilted_plate(close=1e-9))
    stl = [os.path.join(work, plate), os.path.join(work, seam)]
    # A snapshot of the base scene at 5 ms (and one of a heat run at 300 K throughout).
    snap = prepare_snapshot("snapshot", copy.deepcopy(BASE))
    hot = copy.deepcopy(BASE)
    heat_quiet(hot)
    snap_heat = prepare_snapshot("snapshot_heat", hot)
    end = BASE["time"]["end"]
    mesh = dict(base=mesh_floor(plate), files=stl)
    return [
        Check("Top level", "gravity", ("gravity",), [0, 0, 0], [0, 0, -9.81],
              base=with_(gravity=MISSING)),
        Check("`domain`", "periodic", ("domain", "periodic"), [False, False, False],
              [True, False, False], base=no_walls_but_floor),
        Check("`time`", "expected_max_speed", ("time", "expected_max_speed"), 1.0, 3.0,
              command="check"),
        Check("`time`", "max_overlap", ("time", "max_overlap"), 0.25, 0.001),
        Check("`time`", "min_steps_per_contact", ("time", "min_steps_per_contact"), 5, 100),
        Check("`time`", "max_step_travel", ("time", "max_step_travel"), 1, 0.001),
        Check("`materials`", "heat_source", ("materials", 0, "heat_source"), 0, 100.0,
              base=heat_on),
        Check("`interactions` entry", "friction", ("interactions", 0, "friction"), 0.5, 0.2,
              base=with_(interactions__0__friction=MISSING)),
        Check("`interactions` entry", "rolling_friction", ("interactions", 0, "rolling_friction"),
              0, 0.2, base=with_(contact={"normal": "hertz", "rolling": "cdt"})),
        Check("`interactions` entry", "cohesion_energy_density",
              ("interactions", 0, "cohesion_energy_density"), 0, 3e5,
              base=with_(contact={"normal": "hertz", "cohesion": "sjkr"})),
        # interaction_defaults: "the same keys" (the pair left to the defaults).
        Check("`interactions` entry", "friction", ("interaction_defaults", "friction"), 0.5, 0.2,
              base=with_(interactions=MISSING, interaction_defaults={"restitution": 1.0})),
        Check("`contact`", "tangential", ("contact", "tangential"), "history", "none"),
        Check("`contact`", "rolling", ("contact", "rolling"), "none", "cdt",
              base=with_(interactions__0__rolling_friction=0.2)),
        Check("`contact`", "cohesion", ("contact", "cohesion"), "none", "sjkr",
              base=with_(interactions__0__cohesion_energy_density=3e5)),
        Check("`contact`", "dashpot_velocity", ("contact", "dashpot_velocity"), "half_step",
              "predicted", base=with_(interactions__0__restitution=0.5)),
        Check("`contact.hooke`", "tangential", ("contact", "hooke", "stiffness", "tangential"),
              300.0, 100.0,
              base=with_(contact={"normal": "hooke", "hooke": {"stiffness": {"normal": 300.0}}},
                         time={"step": 2e-5, "end": end})),
        Check("`contact.epsd`", "damping_ratio", ("contact", "epsd", "damping_ratio"), 0.3, 0.9,
              base=chain(with_(contact={"normal": "hertz", "rolling": "epsd"}),
                         with_(interactions__0__rolling_friction=0.2))),
        Check("`neighbour`", "skin", ("neighbour", "skin"), "0.4 r_max", 2e-3),
        Check("Plane", "name", ("walls", 0, "name"), "wall0", "floor",
              base=with_(walls__0__name=MISSING, output__wall_loads=True)),
        Check("Cylinder", "name", ("walls", 0, "name"), "wall0", "drum",
              base=chain(drum, with_(output__wall_loads=True))),
        Check("Cylinder", "side", ("walls", 0, "side"), "inside", "outside", base=drum),
        Check("Cylinder", "angular_velocity", ("walls", 0, "angular_velocity"), 0, 20.0,
              base=drum),
        Check("Mesh", "name", ("walls", 0, "name"), "wall0", "plate",
              base=chain(mesh_floor(plate), with_(output__wall_loads=True)), files=stl),
        Check("Mesh", "scale", ("walls", 0, "scale"), 1, 1.5, **mesh),
        Check("Mesh", "rotate", ("walls", 0, "rotate"), {"axis": [0, 0, 1], "angle": 0},
              {"axis": [0, 0, 1], "angle": 10}, **mesh),
        Check("Mesh", "translate", ("walls", 0, "translate"), [0, 0, 0], [0, 0, 0.001], **mesh),
        Check("Mesh", "surface_velocity", ("walls", 0, "surface_velocity"), [0, 0, 0],
              [0.05, 0, 0], **mesh),
        Check("Mesh", "weld_tolerance", ("walls", 0, "weld_tolerance"), 1e-5, 0,
              base=mesh_floor(seam), files=stl),
        Check("Any wall may move", "velocity", ("walls", 0, "motion", "velocity"), [0, 0, 0],
              [0, 0, 0.01], base=floor_motion(angular_velocity=0)),
        Check("Any wall may move", "angular_velocity", ("walls", 0, "motion", "angular_velocity"), 0,
              5.0, base=floor_motion(axis=[0, 0, 1])),
        Check("Any wall may move", "axis_point", ("walls", 0, "motion", "axis_point"), [0, 0, 0],
              [0.005, 0.005, 0], base=floor_motion(axis=[0, 0, 1], angular_velocity=5.0)),
        Check("type: fill", "velocity", ("insert", 0, "velocity"), [0, 0, 0], [0.2, 0, 0]),
        Check("type: fill", "seed", ("insert", 0, "seed"), 1, 2),
        Check("type: fill", "coarse_grain", ("insert", 0, "coarse_grain"), 1, 1.5),
        Check("type: fill", "min", ("insert", 0, "radius", "min"), 5e-4 - 3 * 3e-5, 4.9e-4,
              base=with_(insert__0__radius={"distribution": "normal", "mean": 5e-4,
                                             "stddev": 3e-5})),
        Check("type: fill", "min", ("insert", 0, "radius", "min"), 5e-4 / 10, 4e-4,
              base=with_(insert__0__radius={"distribution": "normal", "mean": 5e-4,
                                             "stddev": 3e-4, "max": 6e-4})),
        Check("type: fill", "max", ("insert", 0, "radius", "max"), 5e-4 + 3 * 3e-5, 5.2e-4,
              base=with_(insert__0__radius={"distribution": "normal", "mean": 5e-4,
                                             "stddev": 3e-5})),
        Check("type: fill", "weights", ("insert", 0, "radius", "weights"), [1, 1], [1, 3],
              base=with_(insert__0__radius={"distribution": "discrete",
                                             "values": [4e-4, 6e-4]})),
        Check("type: stream", "start", ("insert", 0, "start"), 0, 0.002, base=stream),
        Check("type: stream", "stop", ("insert", 0, "stop"), end, 0.005, base=stream),
        Check("type: snapshot", "keep_velocity", ("insert", 0, "keep_velocity"), True, False,
              base=snapshot_insert(os.path.basename(snap)), files=[snap]),
        Check("type: snapshot", "temperature", ("insert", 0, "temperature"), 300, 320,
              base=chain(heat_quiet, snapshot_insert(os.path.basename(snap_heat))),
              files=[snap_heat]),
        Check("`output`", "directory", ("output", "directory"), "output", "elsewhere"),
        Check("`output`", "snapshot_interval", ("output", "snapshot_interval"), end / 20,
              end / 10, base=with_(output__snapshot_interval=MISSING)),
        Check("`output`", "log_interval", ("output", "log_interval"), end / 200, end / 100),
        Check("`output`", "progress", ("output", "progress"), True, False),
        Check("`output`", "checkpoint_keep", ("output", "checkpoint_keep"), 2, 3,
              base=with_(output__checkpoint_interval=end / 10)),
        Check("`output`", "fields", ("output", "fields"), PLAIN_FIELDS,
              PLAIN_FIELDS + ["force"]),
        Check("`output`", "fields", ("output", "fields"), PLAIN_FIELDS + ["temperature"],
              PLAIN_FIELDS, base=heat_on),
        Check("`output`", "fields", ("output", "fields"),
              PLAIN_FIELDS + ["coarse_grain", "real_count"], PLAIN_FIELDS,
              base=with_(insert__0__coarse_grain=1.5)),
        Check("`output`", "start", ("output", "start"), 0, 0.003),
        Check("`output`", "stop", ("output", "stop"), end, 0.005),
        Check("`output`", "contacts", ("output", "contacts"), False, True),
        Check("`output`", "wall_loads", ("output", "wall_loads"), False, True),
        Check("`parallel`", "balance", ("parallel", "balance"), False, True, ranks=2,
              base=with_(time__end=0.03, gravity=[0, 0, -98.1], insert__0__count=150,
                         insert__0__region={"box": {"min": [0, 0, 0],
                                                    "max": [0.01, 0.01, 0.02]}})),
        Check("`parallel`", "reproducible", ("parallel", "reproducible"), False, True),
        Check("`fluid`", "velocity", ("fluid", "velocity"), [0, 0, 0], [0, 0, 0.05],
              base=one_way_fluid),
        Check("`fluid`", "void_fraction", ("fluid", "void_fraction"), 1, 0.8,
              base=one_way_fluid),
        Check("`fluid`", "minimum", ("fluid", "void_fraction", "minimum"), 0.2, 0.95,
              base=chain(one_way_fluid, with_(fluid__void_fraction={"cell_size": 0.0025}))),
        Check("`fluid`", "pressure", ("fluid", "pressure"),
              {"hydrostatic": True, "gradient": [0, 0, 0]}, {"hydrostatic": False},
              base=one_way_fluid),
        Check("`fluid`", "virtual_mass_coefficient", ("fluid", "virtual_mass_coefficient"), 0.5,
              1.0, base=chain(one_way_fluid, with_(fluid__forces=["drag", "pressure_gradient",
                                                                  "viscous", "virtual_mass"]))),
        Check("`fluid`", "convection", ("fluid", "convection"), "ranz_marshall", "gunn",
              base=convection),
        Check("`heat`", "conduction", ("heat", "conduction"), "batchelor_obrien", "none",
              base=heat_on),
        Check("`heat`", "contact_radius", ("heat", "contact_radius"), "geometric",
              "morris_static", base=heat_on,
              other_base=with_(materials__0__real_youngs_modulus=6.3e10)),
    ]


# Rows with a stated default that no run above can write down, and why.
SKIPPED = {
    ("`output`", "checkpoint_interval"): "its default is no periodic checkpoints at all, which "
    "no value writes (absent: tests/dem/app checkpoint tests; any value writes checkpoints)",
    ("`parallel`", "grid"): "chosen at start-up from the particles: docs/parallel.md, tests "
    "DefaultGrid.* and default_grid_mpi_test",
    ("`fluid`", "shear"): "its default is no shear, which no value writes",
    ("`fluid`", "temperature"): "its default is no convection, which no value writes",
}


def prepare_snapshot(name, scene):
    """Runs `scene` to 5 ms and returns its last snapshot's path."""
    folder = os.path.join(work, name)
    s = copy.deepcopy(scene)
    s["time"]["end"] = 0.005
    outcome(folder, s)
    out = os.path.join(folder, "output")
    last = sorted(f for f in os.listdir(out) if f.startswith("particles_"))[-1]
    shutil.copy(os.path.join(out, last), os.path.join(work, name + ".h5"))
    return os.path.join(work, name + ".h5")


def check_one(c):
    scene = c.scene()
    put(scene, c.path, MISSING)
    left_out = outcome_cached(scene, c)
    default = c.default
    if default == "0.4 r_max":
        default = 0.4 * float(left_out["radii"].max())
    written = copy.deepcopy(scene)
    put(written, c.path, default)
    given = outcome_cached(written, c)
    other = copy.deepcopy(scene)
    put(other, c.path, c.other)
    if c.other_base:
        c.other_base(other)
    changed = outcome_cached(other, c)
    what = f"{c.section}: {'.'.join(str(p) for p in c.path)}: default {json.dumps(default)}"
    keys = (set(left_out) | set(given)) - {"radii"}
    diff = sorted(k for k in keys if left_out.get(k) != given.get(k))
    if diff:
        detail = "".join(f"\n--- left out, {k}:\n{left_out.get(k)}\n--- written:\n{given.get(k)}"
                         for k in diff if k in ("report", "status"))
        return False, (f"{what}: leaving the key out differs from writing the documented "
                       f"default, in {diff}{detail}")
    if all(changed.get(k) == given.get(k) for k in (keys | set(changed)) - {"radii"}):
        return False, (f"{what}: the scene does not depend on the key ({json.dumps(c.other)} "
                       f"gives the same outcome, status {given['status']}), so the check shows "
                       f"nothing" + (f"; its report:\n{given['report']}" if given["status"] else ""))
    return True, f"{what} (status {given['status']}; {json.dumps(c.other)} differs)"


_cache, _lock, _count = {}, threading.Lock(), [0]


def outcome_cached(scene, c):
    key = json.dumps([scene, c.command, c.files, c.ranks], sort_keys=True)
    with _lock:
        if key not in _cache:
            _cache[key] = threading.Event()
            mine = True
            _count[0] += 1
            folder = os.path.join(work, "run%03d" % _count[0])
        else:
            mine = False
        event = _cache[key]
    if mine:
        event.result = outcome(folder, scene, c.command, c.files, c.ranks)
        event.set()
    event.wait()
    return event.result


def main():
    os.makedirs(work, exist_ok=True)
    all_checks = checks()
    chosen = [c for c in all_checks if not only or only in c.key]
    with concurrent.futures.ThreadPoolExecutor(max_workers=4) as pool:
        results = list(pool.map(check_one, chosen))
    failures = [text for ok, text in results if not ok]
    for ok, text in results:
        print(("ok   " if ok else "FAIL ") + text)
    # Every stated default of the reference is checked above or skipped with a reason.
    uncovered = []
    for heading, para, key, default in documented_rows(reference):
        if not stated(default):
            continue
        where = heading + " " + para
        covering = [c for c in all_checks if c.key == key and c.section in where]
        if covering:
            # The value the checks write is the one the page states.
            value = literal(default)
            if value is not None and not any(c.default == value for c in covering):
                uncovered.append(f"{heading} / {key}: the page states {default}, the check "
                                 f"writes {json.dumps(covering[0].default)}")
            continue
        if any(s in where and k == key for s, k in SKIPPED):
            continue
        uncovered.append(f"{heading} / {key} (default {default})")
    for u in uncovered:
        print("FAIL a documented default no check covers, or checks as another value: " + u)
    for (s, k), why in SKIPPED.items():
        print(f"skip {s} {k}: {why}")
    print(f"{len(chosen)} documented defaults checked in {_count[0]} runs, {len(failures)} "
          f"failed; {len(uncovered)} rows uncovered or stated otherwise")
    return 1 if failures or (uncovered and not only) else 0


if __name__ == "__main__":
    sys.exit(main())
