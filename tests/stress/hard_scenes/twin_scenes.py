#!/usr/bin/env python3
"""Twin scenes: a hard scene turned, moved or rescaled must run as the scene itself
(docs/stability.md).

    twin_scenes.py --grain build/bin/grain --seeds 0:24
    twin_scenes.py --grain build/bin/grain --family thermal --seeds 0:16 --twins turn1,shift
    twin_scenes.py --grain build/bin/grain --scene tutorials/dem/hopper/fill.yaml --end 0.02
    twin_scenes.py --grain build/bin/grain --seeds 0:24 --jobs 2  # seeds side by side, 2 cores

The physics knows neither which way the axes point nor where the origin lies; the scenes of
the other tests all have gravity along -z and the domain's corner at the origin. Each seed's
scene (drawn by hard_scenes.py, every family) is run as drawn and as its twins:
  * turn1, turn2: the axes cycled (x -> y -> z -> x once or twice), the proper rotations by
    120 and 240 degrees about (1, 1, 1). Every point and vector of the scene turns with it:
    gravity, the domain and its periodic axes, walls, mesh vertices, mesh rotations and
    translations, wall motions, insertion regions and faces, velocities, the fluid's velocity,
    shear and pressure gradient, the processor grid. A turned scene does the same arithmetic
    on permuted components, so it must end where the drawn one does to round-off.
  * shift: every point moved by 1 to 100 of the domain's largest side along each axis,
    either sign (a part in an assembly's coordinates); each coordinate is then rounded
    differently, so its particles must end where the drawn scene's do to 1e-6 of their
    radius.
  * boost (asked for by name): the scene seen from a frame moving along a periodic axis at a
    twentieth of the smallest radius per step (particles, walls and the fluid all faster by
    that velocity), where that is a symmetry (boost_axis()); positions to 1e-6 of the radius
    after taking the frame's motion back.
  * scale: the scene in other units, lengths times 2^a, times 2^b, masses 2^c (a, b, c even,
    nonzero, |a|, |b|, |c| <= 12, drawn per seed): every number of the scene, of its CSV and
    STL files and of its snapshots converted by its dimension (DIMENSIONS, COLUMNS,
    DATASETS); a default with a unit (expected_max_speed) is written out first. Powers of two
    convert exactly, so a scene whose physics is written in dimensionless groups does the
    same arithmetic and must end where the drawn one does to 1e-9 of a radius (fifth roots,
    as in the Hooke stiffness from a characteristic velocity, round otherwise); a length,
    time or speed written into the code makes it differ.
  * ranks: the scene as drawn (its fills included) with parallel: {reproducible: true}, on its
    drawn ranks and on another count and grid (2 or 3 ranks for a 1-rank scene, 1 or 3 for a
    2-rank one; a grid along a drawn axis or the default rule, balanced or not): the mode
    promises the same bits on any ranks (docs/parallel.md), so every dataset of every
    snapshot (the owner rank aside) must be equal; and the drawn run's checkpoint continued
    (grain run --restart) on the twin's ranks and grid must end with the drawn run's bits;
    not compared when the twin's grid is refused as thinner than the interaction range.
--scene FILE twins a scene file instead of drawn ones (tests/data/scenes/twins/resting_bed.yaml
is written for the boost).
A fill draws its random positions axis by axis, so a turned region holds other particles:
the fills are therefore run to their t = 0 snapshot first (with --allow-large-dt, so that
a refused step still inserts), and the drawn scene and each twin start from that snapshot
(turned or moved). Other insertions (CSV files, streams through a face) are turned or moved
as written; a CSV file's columns are renamed (turn) or its positions moved (shift).

A twin passes when it exits as the drawn scene did and
  * after a stop: the message is the same with its numbers and axis letters set aside;
  * after a run: every snapshot holds the same particle ids, each particle's position mapped
    back lies within the twin's tolerance times its radius of the drawn scene's (turned or
    rescaled 1e-9, shifted 1e-6), each temperature within 1e-9 relative (shifted: 1e-2, see
    T_TOLERANCE); the summaries (steps, particles, removed) are equal. Beyond the
    tolerance, a chaotic scene is judged against a nudge of one ulp (judge()).
A failing seed keeps its folder under --work: drawn/, the twins' and nudge/ (when run).

Needs numpy, h5py and yaml (scripts/python.sh finds a Python that has them).
"""
import argparse
import json
import os
import random
import re
import shutil
import sys
import time

try:
    import h5py
    import numpy as np
    import yaml
except ImportError:  # this python3 lacks them: scripts/python.sh finds one that has them
    if os.environ.get("GRAINFLOW_PYTHON_CHOSEN"):
        raise
    _helper = os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "..", "..",
                           "scripts", "python.sh")
    os.execv(_helper, [_helper, os.path.abspath(__file__), *sys.argv[1:]])

sys.path.insert(0, os.path.dirname(os.path.realpath(__file__)))
import hard_scenes as hs  # noqa: E402

# Scene keys whose 3-lists are points (moved by a shift) and vectors or per-axis lists (only
# turned). A 3-list under any other key (none exists today) stops the generator.
POINTS = {"min", "max", "point", "axis_point", "base", "centre", "origin", "translate"}
VECTORS = {"gravity", "normal", "axis", "velocity", "surface_velocity", "u", "flow_direction",
           "gradient_direction", "gradient", "periodic", "grid"}
LISTS = {"values", "weights"}  # radius distributions: numbers, not coordinates
TOLERANCE = {"turn1": 1e-9, "turn2": 1e-9, "shift": 1e-6, "boost": 1e-6, "scale": 1e-9,
             "ranks": 0.0}
# Temperatures, relative. A shift rounds each overlap differently by an ulp of the moved
# coordinates, and conduction goes as the contact radius sqrt(R* overlap), whose sensitivity
# is unbounded at zero overlap: beads that touch (the thermal family's blocks, written with
# 17 digits) conduct through overlaps of a few ulps or none, and with the generator's largest
# conductivities (1e5 W/(m K)) that moved a cold bead's temperature by 0.17 K of 268 K in
# 0.4 ms (thermal seed 90 moved by 0.01 m; its positions agreed to 6e-8 r).
T_TOLERANCE = {"turn1": 1e-9, "turn2": 1e-9, "shift": 1e-2, "boost": 1e-6, "scale": 1e-9,
               "ranks": 0.0}
# How far a twin may deviate beyond its tolerance, in units of the nudge's deviation at the
# same snapshot (judge()). These bound round-off growth, which cannot be derived exactly: a
# turn's round-off differs once per sum, CHAOS; a shift's or a boost's in every step, whose
# differences also start contacts a step apart, CHAOS_EVERY_STEP per step. Thermal seed 107,
# shifted, needed 106 (a bead 1.8e-5 r off after 0.0023 s, the nudge 1.8e-13 r).
CHAOS = 100
CHAOS_EVERY_STEP = 1000
SATURATED = 1e-2
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def add_to_cell(cells, header, column, value, nudge=False):
    """Add `value` to a CSV row's cell of `column` (then one ulp up with `nudge`); a row
    without that cell, or with a cell that is not a number, stays as it is (hostile rows
    stay hostile)."""
    if column not in header or header.index(column) >= len(cells):
        return
    j = header.index(column)
    if not value and not nudge:
        return
    try:
        v = float(cells[j]) + value
    except ValueError:
        return
    cells[j] = repr(float(np.nextafter(v, np.inf)) if nudge else v)


class Twin:
    """A proper rotation that cycles the axes s times, or a shift by an offset."""

    def __init__(self, name, seed, size=1.0):
        """`size`: the domain's largest side; a shift moves the scene 1 to 100 of it along
        each axis, either sign (a part placed in an assembly's coordinates)."""
        self.name = name
        self.s = {"turn1": 1, "turn2": 2}.get(name, 0)
        rng = random.Random(7919 * seed + 3)
        self.offset = np.zeros(3)
        if name == "shift":
            self.offset = np.array([rng.choice((-1, 1)) * size * 10 ** rng.uniform(0, 2)
                                    for _ in range(3)])

    def turn(self, v):
        out = [None] * 3
        for a in range(3):
            out[(a + self.s) % 3] = v[a]
        return out

    def point(self, p):
        q = self.turn(p)
        return [float(q[a] + self.offset[a]) if self.offset[a] else q[a] for a in range(3)]

    def back(self, x):
        """Rows of twin coordinates mapped back to the drawn scene's frame."""
        x = x - self.offset
        return np.stack([x[:, (a + self.s) % 3] for a in range(3)], axis=1)

    def difference(self, x, drawn, time):
        """A twin's positions mapped back, minus the drawn scene's."""
        return self.back(x) - drawn

    def time(self, t):
        """A twin's time in the drawn scene's unit."""
        return t

    def attribute(self, name, value):
        """A snapshot's root attribute as the twin holds it."""
        return value

    def scene(self, x, key=None):
        if isinstance(x, dict):
            if x.get("type") == "mesh" and "translate" not in x:
                x = dict(x, translate=[0, 0, 0])  # the shift moves a mesh by its translate
            return {k: self.scene(v, k) for k, v in x.items()}
        if isinstance(x, list) and len(x) == 3 and key not in LISTS and all(
                isinstance(v, (int, float)) for v in x):
            if key in POINTS:
                return self.point(x)
            if key in VECTORS:
                return self.turn(x)
            raise RuntimeError(f"twin_scenes: a 3-list under key '{key}' is neither a point nor "
                               "a vector; add the key to POINTS or VECTORS")
        if isinstance(x, list):
            return [self.scene(v) for v in x]
        return x

    def stl(self, text):
        out = []
        for line in text.splitlines():
            m = re.match(r"(\s*)(facet normal|vertex)\s+(\S+)\s+(\S+)\s+(\S+)\s*$", line)
            if m:
                v = [float(m.group(k)) for k in (3, 4, 5)]
                # The mesh's own translate carries the shift: vertices only turn.
                v = self.turn(v)
                line = f"{m.group(1)}{m.group(2)} {v[0]!r} {v[1]!r} {v[2]!r}"
            out.append(line)
        return "\n".join(out) + "\n"

    def csv(self, text):
        """A particle file as the twin holds it: its header and each row through the hooks
        csv_header() and csv_row(); comments and blank lines as written."""
        lines = text.splitlines()
        header = None
        for i, line in enumerate(lines):
            if not line.strip() or line.startswith("#"):
                continue
            if header is None:
                header = [c.strip() for c in line.split(",")]
                lines[i] = ",".join(self.csv_header(header))
            else:
                lines[i] = ",".join(self.csv_row(header, line.split(",")))
        return "\n".join(lines) + "\n"

    def csv_header(self, header):
        """Columns renamed: the drawn axis a is the twin's (a + s) % 3."""
        names = {}
        for trip in (("x", "y", "z"), ("vx", "vy", "vz"), ("wx", "wy", "wz")):
            for a in range(3):
                names[trip[a]] = trip[(a + self.s) % 3]
        return [names.get(c, c) for c in header]

    def csv_row(self, header, cells):
        """Positions moved (the renamed columns hold the turn), or x nudged by one ulp."""
        for a, name in enumerate("xyz"):
            nudge = self.name == "nudge" and name == "x"
            add_to_cell(cells, header, name, self.offset[(a + self.s) % 3], nudge)
        return cells

    def dataset(self, name, data):
        """A snapshot dataset as the twin holds it: vectors turned, positions moved."""
        if data.ndim == 2 and data.shape[1] == 3:
            data = np.stack(self.turn([data[:, 0], data[:, 1], data[:, 2]]), axis=1)
            if name == "position":
                data = data + self.offset
                if self.name == "nudge":
                    data[:, 0] = np.nextafter(data[:, 0], np.inf)
        return data

    def snapshot(self, src, dst):
        """A copy of a snapshot with every dataset as the twin holds it (checksummed)."""
        with h5py.File(src, "r") as f, h5py.File(dst, "w") as g:
            for k, v in f.attrs.items():
                g.attrs[k] = self.attribute(k, v)
            for name in f:
                ds = f[name]
                h = g.create_dataset(name, data=self.dataset(name, ds[...]), chunks=ds.chunks,
                                     fletcher32=ds.fletcher32)
                for k, v in ds.attrs.items():
                    h.attrs[k] = v

    def files(self, files):
        return {n: self.stl(t) if n.endswith(".stl") else self.csv(t) if n.endswith(".csv")
                else t for n, t in files.items()}


def domain_size(scene):
    return max(hi - lo for lo, hi in zip(scene["domain"]["min"], scene["domain"]["max"]))


def boost_axis(scene):
    """A periodic axis along which the scene is the same after any translation (its walls
    reach along it, its fluid does not vary along it), so that a boost along it is a
    symmetry; None when there is none (why, as a second value)."""
    text = json.dumps(scene)
    if '"stream"' in text or '"mesh"' in text:
        return None, "streams or meshes"
    fluid = scene.get("fluid", {})
    if not isinstance(fluid.get("void_fraction", 1.0), (int, float)):
        return None, "a computed void fraction (its grid does not move with the particles)"
    for a in range(3):
        if not scene["domain"].get("periodic", [False] * 3)[a]:
            continue
        along = [1 if k == a else 0 for k in range(3)]

        def across(v):  # the part of direction v across the axis
            return any(abs(v[k]) > 0 for k in range(3) if k != a)
        ok = not ("shear" in fluid and fluid["shear"]["gradient_direction"][a] != 0)
        for w in scene.get("walls", []):
            m = w.get("motion", {})
            if m.get("angular_velocity", 0) and across(m["axis"]):
                ok = False
            if w["type"] == "plane" and w["normal"][a] != 0:
                ok = False
            if w["type"] == "cylinder" and across(w["axis"]):
                ok = False
        if ok:
            return a, along
    return None, "no periodic axis along which the walls and the fluid are uniform"


class Boost(Twin):
    """The drawn scene seen from a frame moving at -V along a periodic axis: every particle,
    wall and the fluid move V faster along it (Galilean invariance: contacts, dashpots,
    friction, rolling, drag and heat see relative velocities only)."""

    def __init__(self, seed, axis, speed, domain):
        super().__init__("boost", seed)
        self.axis = axis
        self.v = np.zeros(3)
        self.v[axis] = speed * random.Random(7919 * seed + 5).choice((-1, 1))
        self.period = domain["max"][axis] - domain["min"][axis]

    def scene(self, x, key=None):
        x = json.loads(json.dumps(x))
        if "fluid" in x:
            u = x["fluid"].get("velocity", [0, 0, 0])
            x["fluid"]["velocity"] = [float(u[k] + self.v[k]) for k in range(3)]
        for w in x.get("walls", []):
            m = w.setdefault("motion", {})
            u = m.get("velocity", [0, 0, 0])
            m["velocity"] = [float(u[k] + self.v[k]) for k in range(3)]
        return x

    def stl(self, text):
        return text

    def csv_header(self, header):
        return header if "vx" in header else header + ["vx", "vy", "vz"]

    def csv_row(self, header, cells):
        if "vx" not in header:
            return cells + [repr(float(v)) for v in self.v]
        for k, name in enumerate(("vx", "vy", "vz")):
            add_to_cell(cells, header, name, self.v[k])
        return cells

    def dataset(self, name, data):
        return data + self.v if name == "velocity" else data

    def difference(self, x, drawn, time):
        d = x - self.v * time - drawn
        a = self.axis
        d[:, a] -= self.period * np.round(d[:, a] / self.period)  # the periodic image
        return d


# Dimensions (length, time, mass exponents) of every number a scene may hold, by its key path
# (list entries dropped from the path); temperatures are kept in kelvin. A number under any
# other path stops the scale twin: a new key must be classified here.
L, T, M, ONE = (1, 0, 0), (0, 1, 0), (0, 0, 1), (0, 0, 0)
SPEED, RATE, DENSITY, PRESSURE = (1, -1, 0), (0, -1, 0), (-3, 0, 1), (-1, -2, 1)
CONDUCTIVITY, HEAT_CAPACITY = (1, -3, 1), (2, -2, 0)  # W/(m K), J/(kg K)
DIMENSIONS = {
    "gravity": (1, -2, 0), "domain.min": L, "domain.max": L, "domain.periodic": ONE,
    "time.end": T, "time.step": T, "time.expected_max_speed": SPEED, "time.max_overlap": ONE,
    "time.rayleigh_fraction": ONE, "time.min_steps_per_contact": ONE,
    "time.max_step_travel": ONE,
    "contact.epsd.damping_ratio": ONE, "contact.hooke.characteristic_velocity": SPEED,
    "contact.hooke.stiffness.normal": (0, -2, 1), "contact.hooke.stiffness.tangential": (0, -2, 1),
    "fluid.conductivity": CONDUCTIVITY, "fluid.density": DENSITY,
    "fluid.heat_capacity": HEAT_CAPACITY, "fluid.pressure.gradient": (-2, -2, 1),
    "fluid.shear.flow_direction": ONE, "fluid.shear.gradient_direction": ONE,
    "fluid.shear.origin": L, "fluid.shear.rate": RATE, "fluid.temperature": ONE,
    "fluid.velocity": SPEED, "fluid.virtual_mass_coefficient": ONE,
    "fluid.viscosity": (-1, -1, 1), "fluid.void_fraction": ONE,
    "fluid.void_fraction.cell_size": L, "fluid.void_fraction.minimum": ONE,
    "insert.coarse_grain": ONE, "insert.count": ONE, "insert.count_rate": RATE,
    "insert.mass_rate": (0, -1, 1), "insert.seed": ONE, "insert.temperature": ONE,
    "insert.velocity": SPEED, "insert.face.rectangle.centre": L,
    "insert.face.rectangle.normal": ONE, "insert.face.rectangle.size": L,
    "insert.face.rectangle.u": ONE, "insert.radius.max": L, "insert.radius.mean": L,
    "insert.radius.min": L, "insert.radius.stddev": L, "insert.radius.value": L,
    "insert.radius.values": L, "insert.radius.weights": ONE, "insert.region.box.min": L,
    "insert.region.box.max": L, "insert.region.cylinder.axis": ONE,
    "insert.region.cylinder.base": L, "insert.region.cylinder.height": L,
    "insert.region.cylinder.radius": L,
    "interaction_defaults.cohesion_energy_density": PRESSURE,
    "interaction_defaults.friction": ONE, "interaction_defaults.restitution": ONE,
    "interaction_defaults.rolling_friction": ONE,
    "interactions.cohesion_energy_density": PRESSURE, "interactions.friction": ONE,
    "interactions.restitution": ONE, "interactions.rolling_friction": ONE,
    "materials.conductivity": CONDUCTIVITY, "materials.density": DENSITY,
    "materials.heat_capacity": HEAT_CAPACITY, "materials.heat_source": (2, -3, 0),  # W/kg
    "materials.poisson_ratio": ONE, "materials.real_youngs_modulus": PRESSURE,
    "materials.youngs_modulus": PRESSURE,
    "output.checkpoint_interval": T, "output.checkpoint_keep": ONE,
    "output.snapshot_interval": T, "output.log_interval": T,
    "parallel.grid": ONE,
    "walls.angular_velocity": RATE, "walls.axis": ONE, "walls.axis_point": L,
    "walls.heat_flux": (0, -3, 1), "walls.motion.angular_velocity": RATE,
    "walls.motion.axis": ONE, "walls.motion.axis_point": L, "walls.motion.velocity": SPEED,
    "walls.normal": ONE, "walls.point": L, "walls.radius": L, "walls.rotate.angle": ONE,
    "walls.rotate.axis": ONE, "walls.surface_velocity": SPEED, "walls.temperature": ONE,
    "walls.translate": L,
}
# Snapshot datasets and CSV columns.
DATASETS = {"id": ONE, "position": L, "velocity": SPEED, "angular_velocity": RATE,
            "radius": L, "diameter": L, "mass": M, "material": ONE, "force": (1, -2, 1),
            "torque": (2, -2, 1), "coordination": ONE, "fluid_force": (1, -2, 1),
            "overlap_max": ONE, "temperature": ONE, "coarse_grain": ONE, "real_count": ONE}
COLUMNS = {"x": L, "y": L, "z": L, "radius": L, "vx": SPEED, "vy": SPEED, "vz": SPEED,
           "wx": RATE, "wy": RATE, "wz": RATE, "material": None, "T": ONE}


class Scale(Twin):
    """The drawn scene in other units: lengths times 2^a, times 2^b, masses 2^c (a, b, c
    even, drawn per seed), every number converted by its dimension (DIMENSIONS). Physics
    written in dimensionless groups does the same arithmetic on scaled numbers, exactly
    (powers of two; even ones keep square roots exact): a length, time or speed written into
    the code (an absolute tolerance, a default in metres) is what makes a scaled twin differ
    -- a powder of 10 um beads or a bed of boulders running otherwise."""

    def __init__(self, seed):
        super().__init__("scale", seed)
        rng = random.Random(7919 * seed + 11)
        self.exponents = [2 * rng.choice([k for k in range(-6, 7) if k]) for _ in range(3)]

    def factor(self, dim):
        return float(2.0 ** sum(e * d for e, d in zip(self.exponents, dim)))

    def scene(self, x, key=None):
        x = json.loads(json.dumps(x))
        # A default in metres per second is written out, so that it converts.
        x.setdefault("time", {}).setdefault("expected_max_speed", 1.0)
        return self.convert(x, "")

    def convert(self, x, path):
        if isinstance(x, dict):
            return {k: self.convert(v, f"{path}.{k}" if path else k) for k, v in x.items()}
        if isinstance(x, list):
            return [self.convert(v, path) for v in x]
        if isinstance(x, bool) or not isinstance(x, (int, float)):
            return x
        if path not in DIMENSIONS:
            raise RuntimeError(f"twin_scenes: the number under '{path}' has no dimension in "
                               "DIMENSIONS; add it")
        f = self.factor(DIMENSIONS[path])
        return x if f == 1 else float(x * f)

    def back(self, x):
        return x / self.factor(L)

    def time(self, t):
        return t / self.factor(T)

    def stl(self, text):
        f = self.factor(L)
        out = []
        for line in text.splitlines():
            m = re.match(r"(\s*)vertex\s+(\S+)\s+(\S+)\s+(\S+)\s*$", line)
            if m:
                v = [float(m.group(k)) * f for k in (2, 3, 4)]
                line = f"{m.group(1)}vertex {v[0]!r} {v[1]!r} {v[2]!r}"
            out.append(line)
        return "\n".join(out) + "\n"

    def csv_header(self, header):
        for c in header:
            if c not in COLUMNS:
                raise RuntimeError(f"twin_scenes: CSV column '{c}' has no dimension in COLUMNS")
        return header

    def csv_row(self, header, cells):
        for j, c in enumerate(header):
            if j < len(cells) and COLUMNS[c] is not None and COLUMNS[c] != ONE:
                try:
                    cells[j] = repr(float(cells[j]) * self.factor(COLUMNS[c]))
                except ValueError:
                    pass  # a hostile cell stays hostile
        return cells

    def dataset(self, name, data):
        if name not in DATASETS:
            raise RuntimeError(f"twin_scenes: snapshot dataset '{name}' has no dimension")
        f = self.factor(DATASETS[name])
        return data if f == 1 else data * f

    def attribute(self, name, value):
        return value * self.factor(T) if name == "time" else value


def write_case(folder, scene, files):
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    with open(os.path.join(folder, "scene.yaml"), "w") as f:
        yaml.safe_dump(scene, f, default_flow_style=None, sort_keys=False, width=100)
    for name, text in files.items():
        os.makedirs(os.path.dirname(os.path.join(folder, name)), exist_ok=True)
        with open(os.path.join(folder, name), "w") as f:
            f.write(text)


def snapshot_files(folder, out="out"):
    out = os.path.join(folder, out)
    if not os.path.isdir(out):
        return []
    return [os.path.join(out, n) for n in sorted(os.listdir(out))
            if n.startswith("particles_") and n.endswith(".h5")]


def template(message):
    """A message with its numbers and axis letters set aside."""
    return re.sub(r"\b[xyz]\b", "?", NUMBER.sub("#", message))


def same_stop(a, b):
    """Two stop messages alike, numbers and axis letters aside (the shorter may be cut)."""
    ta, tb = template(a), template(b)
    n = min(len(ta), len(tb))
    return n > 0 and ta[:n] == tb[:n]


def summary(out):
    m = re.search(r"done: (\d+) steps, (\d+) particles \((\d+) removed\)", out)
    return m.groups() if m else None


def start_from_snapshot(args, d, scene, work):
    """The scene with its fills replaced by their t = 0 snapshot: (scene, snapshot path), or
    (None, output) when the fills insert nothing."""
    if not any(i["type"] == "fill" for i in scene.get("insert", [])):
        return scene, None
    fills = json.loads(json.dumps(scene))
    fills["insert"] = [i for i in fills["insert"] if i["type"] == "fill"]
    out = fills.setdefault("output", {})
    out.pop("checkpoint_interval", None)
    out.pop("checkpoint_keep", None)
    out["snapshot_interval"] = fills["time"]["end"]
    folder = os.path.join(work, "fills")
    write_case(folder, fills, d.files)
    code, text, _ = hs.run_grain(args, d.ranks, "scene.yaml", folder, args.timeout,
                                 extra=("--allow-large-dt",))
    snaps = snapshot_files(folder)
    if not snaps:
        return None, text
    with h5py.File(snaps[0], "r") as f:
        if float(f.attrs["time"]) != 0:
            return None, f"the fills' first snapshot is at t = {f.attrs['time']}"
    started = json.loads(json.dumps(scene))
    started["insert"] = [{"type": "snapshot", "file": "filled.h5"}] + \
        [i for i in started["insert"] if i["type"] != "fill"]
    return started, snaps[0]


def read_run(folder):
    snaps = []
    for path in snapshot_files(folder):
        with h5py.File(path, "r") as f:
            order = np.argsort(f["id"][...])
            snaps.append({"time": float(f.attrs["time"]), "id": f["id"][...][order],
                          "position": f["position"][...][order],
                          "radius": f["radius"][...][order],
                          "temperature": f["temperature"][...][order]
                          if "temperature" in f else None})
    return snaps


def deviations(twin, drawn, other):
    """Per snapshot, the twin's largest position deviation in radii and temperature deviation
    (relative), mapped back; or a failure text when the runs hold other particles."""
    if len(drawn) != len(other):
        return None, f"{len(drawn)} snapshots, the twin {len(other)}"
    out = []
    for a, b in zip(drawn, other):
        if abs(a["time"] - twin.time(b["time"])) > 1e-9 * max(abs(a["time"]), 1e-30):
            return None, f"snapshot at t = {a['time']}, the twin's at {twin.time(b['time'])}"
        if not np.array_equal(a["id"], b["id"]):
            return None, f"t = {a['time']}: the twin holds other particle ids"
        dx = dt = 0.0
        if len(a["id"]):
            dx = float((np.abs(twin.difference(b["position"], a["position"], a["time"]))
                        .max(axis=1) / a["radius"]).max())
            if a["temperature"] is not None:
                dt = float((np.abs(b["temperature"] - a["temperature"])
                            / a["temperature"]).max())
        out.append((a["time"], dx, dt))
    return out, None


def judge(name, devs, nudged, chaos, steps, tolerance=None):
    """A failure text, or None. Beyond its tolerance a twin is judged against the nudged run
    (`nudged`, called when needed), the drawn scene started with each particle's x one ulp
    larger: in a chaotic scene any round-off grows to a visible difference. A turned twin's
    round-off differs from the drawn scene's by a few ulps per step, so it may deviate
    `chaos` times as far as the nudge; a shifted twin's by an ulp of the offset in every
    step, so `chaos` times (offset / domain corner) times the steps so far (each step's
    round-off grows at most as the nudge has since t = 0). Once the nudge itself reaches
    SATURATED radii the drawn scene is not reproducible to round-off: later snapshots are
    not compared. Returns (failure, time from which the comparison stopped). `tolerance`
    replaces the twin's position tolerance (in the unit of `devs`)."""
    tol = TOLERANCE[name] if tolerance is None else tolerance
    limits = None
    for i, (t, dx, dT) in enumerate(devs):
        if limits is not None and limits[i][1] >= SATURATED:
            return None, t
        if dx <= tol and dT <= T_TOLERANCE[name]:
            continue
        if limits is None:
            limits = nudged()
        _, nx, nT = limits[i]
        if nx >= SATURATED:
            return None, t
        factor = chaos * steps(t)
        if dx > max(tol, factor * nx):
            return (f"t = {t}: a particle is {dx:.3g} from where the drawn scene has it "
                    f"(tolerance {tol:g}; a one-ulp nudge moves it {nx:.2g}, "
                    f"times {factor:.3g})"), None
        if dT > max(T_TOLERANCE[name], factor * nT):
            return (f"t = {t}: a temperature differs by {dT:.3g} relative (tolerance "
                    f"{T_TOLERANCE[name]:g}; a one-ulp nudge changes it {nT:.2g}, times "
                    f"{factor:.3g})"), None
    return None, None


def numbers(x):
    """A scene read by PyYAML with the numbers it leaves as strings (YAML 1.1 wants a dot in
    5.0e6; grain reads 5e6 too) made numbers, so that the twins turn, move and scale them."""
    if isinstance(x, dict):
        return {k: numbers(v) for k, v in x.items()}
    if isinstance(x, list):
        return [numbers(v) for v in x]
    if isinstance(x, str) and NUMBER.fullmatch(x.strip()):
        return float(x)
    return x


class SceneFile:
    """A scene file (--scene) in place of a drawn scene: its mesh and CSV files are read as
    text (ASCII STL), its snapshot insertions copied, turned or moved."""

    family = "scene"

    def __init__(self, path, ranks, end):
        folder = os.path.dirname(os.path.abspath(path))
        with open(path) as f:
            self.scene = numbers(yaml.safe_load(f))
        time_ = self.scene["time"]
        if end:
            time_["end"] = end
        out = self.scene.setdefault("output", {})
        for key in ("checkpoint_interval", "checkpoint_keep", "directory", "start", "stop"):
            out.pop(key, None)
        out["snapshot_interval"] = time_["end"] / 10
        self.ranks = ranks or 1
        self.files, self.snapshot_files = {}, {}
        for w in self.scene.get("walls", []):
            if w.get("type") == "mesh":
                with open(os.path.join(folder, w["file"]), "rb") as f:
                    raw = f.read()
                if not raw.lstrip().startswith(b"solid") or b"facet" not in raw:
                    raise RuntimeError(f"{w['file']}: only ASCII STL files can be turned")
                self.files[w["file"]] = raw.decode()
        for i in self.scene.get("insert", []):
            if i["type"] == "csv":
                with open(os.path.join(folder, i["file"])) as f:
                    self.files[i["file"]] = f.read()
            elif i["type"] == "snapshot":
                self.snapshot_files[i["file"]] = os.path.join(folder, i["file"])


def copy_snapshots(d, folder, twin=None):
    """The scene's own snapshot insertions into a case folder, turned or moved by `twin`."""
    for name, src in getattr(d, "snapshot_files", {}).items():
        dst = os.path.join(folder, name)
        os.makedirs(os.path.dirname(dst), exist_ok=True)
        if twin is None:
            shutil.copy(src, dst)
        else:
            twin.snapshot(src, dst)



# The ranks twin compares every per-particle dataset of every snapshot but the owner rank.
RANKS_SKIP = {"rank"}
# A twin's decomposition refused because the domain is too thin for it: no comparison.
TOO_THIN = "thinner than the interaction range"


def ranks_layout(seed, ranks):
    """The ranks twin's rank count and `parallel` block: 2 or 3 ranks for a 1-rank scene, 1 or
    3 for a 2-rank one; a grid along a drawn axis (or the default rule), balanced or not."""
    rng = random.Random(7877 * seed + 3)
    n = rng.choice([2, 3]) if ranks == 1 else rng.choice([1, 3])
    block = {"reproducible": True}
    if n > 1 and rng.random() < 0.7:
        grid = [1, 1, 1]
        grid[rng.randrange(3)] = n
        block["grid"] = grid
        if rng.random() < 0.5:
            block["balance"] = True
    return n, block


def read_datasets(folder, out="out"):
    snaps = []
    for path in snapshot_files(folder, out):
        with h5py.File(path, "r") as f:
            order = np.argsort(f["id"][...])
            data = {k: f[k][...][order] for k in f.keys()
                    if k not in RANKS_SKIP and isinstance(f[k], h5py.Dataset)
                    and f[k].shape[:1] == order.shape}
            snaps.append((float(f.attrs["time"]), data))
    return snaps


def check_ranks(args, seed, d, scene, work):
    """The drawn scene (its fills included) with parallel.reproducible on its drawn ranks and
    on another count and grid (ranks_layout): (failure or None, note). The mode promises the
    same bits (docs/parallel.md), so every dataset must be equal, the summaries and stops
    alike."""
    runs = []
    n, block = ranks_layout(seed, d.ranks)
    drawn_block = dict(scene.get("parallel", {}), reproducible=True)
    for name, ranks, parallel in (("ranks_drawn", d.ranks, drawn_block), ("ranks", n, block)):
        s = json.loads(json.dumps(scene))
        s["parallel"] = parallel
        folder = os.path.join(work, name)
        write_case(folder, s, d.files)
        copy_snapshots(d, folder)
        code, out, _ = hs.run_grain(args, ranks, "scene.yaml", folder, args.timeout)
        runs.append((code, out, folder))
    (code, out, f0), (tcode, tout, f1) = runs
    how = f"ranks {d.ranks} -> {n}" + (f" {block['grid']}" if "grid" in block else "") + \
        (" balanced" if block.get("balance") else "")
    if tcode != 0 and TOO_THIN in hs.error_line(tout):
        return None, f"{how} not run (the domain is too thin for it)"
    if tcode != code or (code != 0 and not same_stop(hs.error_line(out), hs.error_line(tout))):
        return (f"{how}: exit {tcode}, on the drawn ranks {code}\n  drawn: "
                f"{hs.error_line(out)}\n  twin:  {hs.error_line(tout)}"), None
    if code != 0:
        return None, f"{how} stopped alike"
    if summary(out) != summary(tout):
        return f"{how}: summary {summary(tout)}, on the drawn ranks {summary(out)}", None
    a, b = read_datasets(f0), read_datasets(f1)
    if len(a) != len(b):
        return f"{how}: {len(b)} snapshots, on the drawn ranks {len(a)}", None
    failure = same_datasets(how, a, b)
    if failure:
        return failure, None
    # The drawn ranks' checkpoint continued on the twin's ranks and grid must end as the
    # drawn run did (docs/parallel.md: "after a restart from a checkpoint on another rank
    # count").
    cps = sorted(n for n in os.listdir(os.path.join(f0, "out"))
                 if n.startswith("checkpoint_") and n.endswith(".h5"))
    if not cps:
        return None, f"{how} bit for bit ({len(a)} snapshots; no checkpoint to restart)"
    shutil.copy(os.path.join(f0, "out", cps[-1]), os.path.join(f1, "restart.h5"))
    rcode, rout, _ = hs.run_grain(args, n, "scene.yaml", f1, args.timeout,
                                  extra=("--restart", "restart.h5"), output="out_restart")
    with open(os.path.join(f1, "restart.out"), "w") as f:
        f.write(rout)
    if rcode != 0:
        return (f"{how}: the restart of {cps[-1]} (written on {d.ranks} rank(s)) on the twin's "
                f"ranks: exit {rcode}: {hs.error_line(rout)}"), None
    if summary(rout) != summary(out):
        return (f"{how}: the restart of {cps[-1]} on the twin's ranks: summary "
                f"{summary(rout)}, the run's {summary(out)}"), None
    r = read_datasets(f1, "out_restart")
    if not r or r[-1][0] != a[-1][0]:
        return (f"{how}: the restart of {cps[-1]} on the twin's ranks ends at "
                f"t = {r[-1][0] if r else None}, the run at {a[-1][0]}"), None
    failure = same_datasets(f"{how}, restarted from {cps[-1]}", a[-1:], r[-1:])
    if failure:
        return failure, None
    return None, f"{how} bit for bit ({len(a)} snapshots; restarted from {cps[-1]} alike)"


def same_datasets(how, a, b):
    """None when the snapshots a and b (read_datasets) hold the same bits, else what differs."""
    for (t, x), (_, y) in zip(a, b):
        for key, values in x.items():
            if key not in y or values.shape != y[key].shape:
                return f"{how}: t = {t}: dataset {key} missing or of another shape"
            if not np.array_equal(values, y[key], equal_nan=True):
                bad = np.nonzero(np.any((values != y[key]).reshape(len(values), -1), axis=1))[0]
                return (f"{how}: t = {t}: {key} differs in {len(bad)} particles (first id "
                        f"{x['id'][bad[0]]}: {values[bad[0]]} against {y[key][bad[0]]})")
    return None


def check_seed(args, seed, twins):
    d, scene = hs.draw(seed, args.family)
    if args.ranks:
        d.ranks = args.ranks
    return check(args, seed, d, scene, twins,
                 os.path.abspath(os.path.join(args.work, f"seed_{seed}")))


def seed_ranks(args, seed):
    """The ranks a seed runs on (--jobs counts them before it starts)."""
    try:
        ranks = args.ranks or hs.draw(seed, args.family)[0].ranks
    except Exception:  # a generator fault: check_seed names it as the seed's failure
        return 1
    if "ranks" in args.twins.split(","):
        ranks = max(ranks, ranks_layout(seed, ranks)[0])
    return ranks


def check(args, seed, d, scene, twins, work):
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    ranks_note = None
    if "ranks" in twins:
        failure, ranks_note = check_ranks(args, seed, d, scene, work)
        if failure:
            return False, failure, work
        twins = [t for t in twins if t != "ranks"]
        if not twins:
            return True, ranks_note, work
    started, snap = start_from_snapshot(args, d, scene, work)
    results = []
    if started is None:
        # The fills themselves are refused: the twins' fills must be refused alike.
        base_msg = hs.error_line(snap)
        if "could place only" in base_msg:  # random placement saturated: a turned region
            return True, "fills saturated (a turned region draws other positions)" + \
                (f"; {ranks_note}" if ranks_note else ""), work
        for name in twins:
            t = Scale(seed) if name == "scale" else Twin(name, seed, domain_size(scene))
            folder = os.path.join(work, name)
            write_case(folder, t.scene(scene), t.files(d.files))
            copy_snapshots(d, folder, t)
            code, out, _ = hs.run_grain(args, d.ranks, "scene.yaml", folder, args.timeout,
                                        extra=("--allow-large-dt",))
            msg = hs.error_line(out)
            if code == 0 or not same_stop(msg, base_msg):
                return False, f"{name}: the drawn fills stop with '{base_msg}', the twin's " \
                              f"with exit {code}: '{msg}'", work
            results.append(f"{name} refused alike")
        return True, "fills refused; " + ", ".join(results + ([ranks_note] if ranks_note else [])), work
    folder = os.path.join(work, "drawn")
    write_case(folder, started, d.files)
    copy_snapshots(d, folder)
    if snap:
        shutil.copy(snap, os.path.join(folder, "filled.h5"))
    code, out, _ = hs.run_grain(args, d.ranks, "scene.yaml", folder, args.timeout)
    if code not in (0, 1, 2):
        return False, f"the drawn scene ended with exit {code}: {hs.error_line(out)}", work
    drawn = read_run(folder) if code == 0 else None
    nudge, nudge_run = [], []

    def nudge_exit():
        """(exit code, output) of the drawn scene started with every x one ulp larger."""
        if not nudge_run:
            t = Twin("nudge", seed)
            tf = os.path.join(work, "nudge")
            write_case(tf, started, t.files(d.files))
            copy_snapshots(d, tf, t)
            if snap:
                t.snapshot(snap, os.path.join(tf, "filled.h5"))
            nudge_run.append(hs.run_grain(args, d.ranks, "scene.yaml", tf, args.timeout)[:2])
        return nudge_run[0]

    def nudged():
        """The deviations of the nudged run from the drawn one."""
        if not nudge:
            ncode, nout = nudge_exit()
            devs, failure = (deviations(Twin("nudge", seed), drawn,
                                        read_run(os.path.join(work, "nudge")))
                             if ncode == 0 else (None, nout))
            if failure:
                raise RuntimeError(f"the nudged run does not compare: {failure[-300:]}")
            nudge.append(devs)
        return nudge[0]

    def chaotic_stop():
        """Whether one ulp changes how the drawn scene ends (then a twin may end otherwise)."""
        ncode, nout = nudge_exit()
        return ncode != code or not same_stop(hs.error_line(out), hs.error_line(nout))

    for name in twins:
        t = Scale(seed) if name == "scale" else Twin(name, seed, domain_size(started))
        if name == "boost":
            axis, why = boost_axis(started)
            dt = hs.startup_dt(out)
            if axis is None or dt is None or drawn is None:
                results.append(f"boost not drawn ({why if axis is None else 'no run'})")
                continue
            # A twentieth of the smallest radius per step: well within the travel guard.
            r_min = min(float(s["radius"].min()) for s in drawn if len(s["radius"]))
            t = Boost(seed, axis, 0.05 * r_min / dt, started["domain"])
        tf = os.path.join(work, name)
        write_case(tf, t.scene(started), t.files(d.files))
        copy_snapshots(d, tf, t)
        if snap:
            t.snapshot(snap, os.path.join(tf, "filled.h5"))
        tcode, tout, _ = hs.run_grain(args, d.ranks, "scene.yaml", tf, args.timeout)
        if tcode != code or (code != 0 and not same_stop(hs.error_line(out),
                                                         hs.error_line(tout))):
            if chaotic_stop():
                results.append(f"{name} ended otherwise (chaotic: so does the nudge)")
                continue
            return False, (f"{name}: exit {tcode}, the drawn scene {code}\n  drawn: "
                           f"{hs.error_line(out)}\n  twin:  {hs.error_line(tout)}"), work
        if code != 0:
            results.append(f"{name} stopped alike")
            continue
        if summary(out) != summary(tout):
            return False, f"{name}: summary {summary(tout)}, the drawn scene's {summary(out)}", work
        devs, failure = deviations(t, drawn, read_run(tf))
        chaos, steps = CHAOS, (lambda _: 1)
        if t.offset.any() or name == "boost":
            # Round-off in every step: an ulp of the offset against one of the domain (shift),
            # or of the positions, moved at other speeds (boost).
            chaos = CHAOS_EVERY_STEP
            if t.offset.any():
                extent = max(abs(v) for v in started["domain"]["min"] + started["domain"]["max"])
                chaos *= 1 + np.abs(t.offset).max() / extent
            n, t_end = int(summary(out)[0]), drawn[-1]["time"]
            steps = (lambda when: max(1.0, n * when / t_end))  # noqa: E731
        chaotic = None
        if not failure:
            failure, chaotic = judge(name, devs, nudged, chaos, steps)
        if failure:
            return False, f"{name}: {failure}", work
        dx, dT = max(v[1] for v in devs), max(v[2] for v in devs)
        results.append(f"{name} {dx:.2g} r" + (f" T {dT:.2g}" if dT else "")
                       + (f" (chaotic: the nudge {max(v[1] for v in nudge[0]):.2g} r"
                          + (f", compared until t = {chaotic:.3g} s" if chaotic else "") + ")"
                          if nudge else ""))
    how = "ran" if code == 0 else "stopped"
    return True, f"{how}; " + ", ".join(results + ([ranks_note] if ranks_note else [])), work


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grain", required=True)
    ap.add_argument("--mpiexec", default="mpiexec")
    ap.add_argument("--seeds", type=hs.parse_seeds,
                    help="ranges A:B (B excluded) and seeds, comma-separated: 0:16,608")
    ap.add_argument("--scene", action="append", default=[],
                    help="a scene file instead of drawn ones (repeatable); its meshes must "
                         "be ASCII STL")
    ap.add_argument("--end", type=float, help="with --scene: time.end instead of the file's")
    ap.add_argument("--family", choices=hs.EXTRA_FAMILIES,
                    help="draw this extra family's scene for every seed (thermal)")
    ap.add_argument("--twins", default="turn1,turn2,shift",
                    help="comma-separated: turn1, turn2, shift, boost, scale, ranks")
    ap.add_argument("--ranks", type=int, choices=[1, 2], help="instead of the drawn count")
    ap.add_argument("--timeout", type=float, default=60, help="per run [s]")
    ap.add_argument("--work", default="twin_scenes_work")
    ap.add_argument("--keep", action="store_true", help="keep the folders of passing seeds")
    ap.add_argument("--jobs", type=int, default=1, metavar="N",
                    help="run seeds (and scene files) side by side on N cores, the running "
                         "ones' ranks summing to at most N (one of more ranks runs alone); "
                         "result lines print as they end (default 1)")
    args = ap.parse_args()
    if args.jobs < 1:
        ap.error(f"--jobs: {args.jobs} is not a count of cores >= 1")
    twins = args.twins.split(",")
    for name in twins:
        if name not in TOLERANCE:
            ap.error(f"--twins: unknown twin '{name}'; allowed: {', '.join(TOLERANCE)}")
    if os.sep in args.grain:
        args.grain = os.path.abspath(args.grain)
    if not args.seeds and not args.scene:
        ap.error("give --seeds or --scene")
    if args.end is not None and args.end <= 0:
        ap.error(f"--end: {args.end} is not a time > 0")
    os.makedirs(args.work, exist_ok=True)
    start = time.monotonic()

    def check_file(k, path):
        """A --scene file: (its result line, its path when it failed, else None)."""
        t0 = time.monotonic()
        work = os.path.abspath(os.path.join(args.work, f"scene_{k}"))
        try:
            d = SceneFile(path, args.ranks, args.end)
            ok, note, _ = check(args, k, d, d.scene, twins, work)
        except (OSError, RuntimeError, KeyError, yaml.YAMLError) as e:
            ok, note = False, f"{type(e).__name__}: {e}"
        text = f"scene {path} {time.monotonic() - t0:6.2f} s  {'ok' if ok else 'FAIL'} ({note})"
        if ok and not args.keep:
            shutil.rmtree(work, ignore_errors=True)
        return text, None if ok else path

    def check_drawn(seed):
        """A drawn seed: (its result line, the seed when it failed, else None)."""
        t0 = time.monotonic()
        try:
            ok, note, work = check_seed(args, seed, twins)
        except Exception as e:  # a generator fault is a failure of the seed, named
            ok, note, work = False, f"{type(e).__name__}: {e}", None
        family = args.family or hs.FAMILIES[seed % len(hs.FAMILIES)]
        text = (f"seed {seed:5d} {family:13s} {time.monotonic() - t0:6.2f} s  "
                f"{'ok' if ok else 'FAIL'} ({note})")
        if ok and work and not args.keep:
            shutil.rmtree(work, ignore_errors=True)
        return text, None if ok else seed

    # (ranks, work folder, run) of the scene files, then of the seeds; the ranks only count
    # with --jobs (hard_scenes.run_concurrently).
    tasks = [(args.ranks or 1, f"scene_{k}", lambda k=k, path=path: check_file(k, path))
             for k, path in enumerate(args.scene)]
    tasks += [(seed_ranks(args, seed) if args.jobs > 1 else 1, f"seed_{seed}",
               lambda seed=seed: check_drawn(seed)) for seed in args.seeds or []]
    results = {}
    if args.jobs > 1:
        def ended(i, result):
            results[i] = result
            print(result[0], flush=True)
        hs.run_concurrently(args.jobs, tasks, lambda: True, ended)
    else:
        for i, (_, _, run) in enumerate(tasks):
            results[i] = run()
            print(results[i][0], flush=True)
    failed = [results[i][1] for i in sorted(results) if results[i][1] is not None]
    print(f"\n{len(args.seeds or []) + len(args.scene)} scenes in "
          f"{time.monotonic() - start:.1f} s, {len(failed)} failed"
          + (f": {' '.join(map(str, failed))} (folders under {args.work})" if failed else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
