#!/usr/bin/env python3
"""Every default of couplingProperties that docs/coupling.md states is what grainFoam does
(coupling.documented_defaults).

A default that never did what the docs say is a silent wrong answer: the user who leaves a
key out of constant/couplingProperties believes the documented value is in force. For every
row of the page's couplingProperties table (`| key | default | allowed | meaning |`, section
"A coupled case") with a stated default, this test runs one tiny coupled case three times:

- the key left out,
- the key written with the documented value,
- the key written with another value.

The first two must give the same outcome bit for bit: exit status, grainFoam's log (wall
clock, dates, host and process id removed), every file grainFoam writes (the time folders'
fields, uniform/ and grainflowChecksums, and every dataset and attribute of the particle
snapshots and checkpoints; not the checkpoint's byte checksum, which HDF5's object time
stamps change from run to run). The third must write other fields or particles, which shows
that the case depends on the key at all (a case in which the key changes nothing would make
the first comparison empty; the case is built so that none is: beads about a cell wide that
cut cell faces, a bed whose surface lies inside a cell, a horizontal flow through it).

The table is read from the page itself: every row whose default is not "required" must be
checked here or listed in SKIPPED with the reason, and the value a check writes must be the
page's literal, so a new row, or a default changed on the page only, makes this test fail.

Usage: documented_defaults.py --solver GRAINFOAM --foam-env FOAM_ENV --page COUPLING.md
                              --work WORK_DIR [--lib-dir DIR] [--only KEY] [--workers N]

The runs (25, about a second each: every distinct case is run once, the key left out once per
case) go through a pool of --workers threads (2); each case stays in WORK_DIR/runNN with its
log.grainFoam.
"""
import argparse
import concurrent.futures
import difflib
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import threading
import time

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "support"))
from singleton import isolated_singleton  # noqa: E402  (tests/support/singleton.py)


# ---------------------------------------------------------------- the page's table

def documented_rows(path):
    """(heading, key, default) of every row of a table whose first column is `key` and which
    has a `default` column (the couplingProperties table is indented under a list item)."""
    rows, heading, cols = [], None, None
    for line in open(path, encoding="utf-8"):
        text = line.strip()
        m = re.match(r"^#+\s+(.*)", line)
        if m:
            heading, cols = m.group(1), None
            continue
        if not text.startswith("|"):
            cols = None
            continue
        cells = [c.strip() for c in text.strip("|").split("|")]
        if cols is None:
            cols = [c.lower() for c in cells]
            continue
        if set(text) <= set("|-: "):
            continue
        if cols[0] == "key" and "default" in cols:
            m = re.fullmatch(r"`([A-Za-z_]+)`", cells[0])
            if m:
                rows.append((heading, m.group(1), cells[cols.index("default")]))
    return rows


def stated(default):
    """Whether a default cell states a value (not `required`)."""
    d = default.strip().lower()
    return not (d == "" or d.startswith("required") or d.startswith("—") or d.startswith("-"))


def literal(default):
    """The value a default cell gives (`divided` -> "divided", 5 -> 5, 0.2 -> 0.2), or None for
    a description."""
    m = re.fullmatch(r"`([^`]*)`", default.strip())
    text = m.group(1) if m else default.strip()
    try:
        return json.loads(text)
    except ValueError:
        return text if re.fullmatch(r"[A-Za-z_]+", text) else None


def foam_value(value):
    """A couplingProperties entry's value as written in the dictionary."""
    return value if isinstance(value, str) else repr(value)


# ---------------------------------------------------------------- the case

# 8 x 8 x 16 mm, cells of 2 mm (4 x 4 x 8 = 128), periodic along x and y, walls at the
# bottom and top. 64 beads of d = 1.8 mm (0.9 of a cell) on a lattice of 2 x 2 x 1.8 mm,
# four layers resting on the floor: the lattice is shifted by half a cell in x and y so
# that every bead cuts cell faces (voidFraction, dividedResolution, smoothingFactor change
# the footprint), and its layers (1.8 mm) are not the cells' (2 mm), so the bed's surface
# at 7.2 mm lies inside a cell between a denser and an empty one (dragVoidFraction,
# facePressure); the bed's void fraction, 0.52 to 0.75 by cell layer, is what
# minVoidFraction 0.7 clamps. Four more beads fall from 12 mm through water flowing at
# (0.05 0.02 0) m/s, so that the void fraction changes in time (ddtVoidFraction). One run of
# grainFoam takes about 1 s.
BOX = (0.008, 0.008, 0.016)
CELLS = (4, 4, 8)
R = 0.9e-3
DT_FLUID, STEPS = 1e-4, 5   # five fluid steps of ten DEM steps, written once at the end


def beads():
    rows = []
    for k in range(4):
        for j in range(4):
            for i in range(4):
                rows.append((0.0015 + 0.002 * i, 0.0015 + 0.002 * j, R + 2 * R * k))
    rows += [(0.002, 0.003, 0.012), (0.006, 0.005, 0.0125), (0.003, 0.006, 0.013),
             (0.005, 0.002, 0.0115)]
    return "x,y,z,radius\n" + "".join(f"{x!r},{y!r},{z!r},{R!r}\n" for x, y, z in rows)


def scene(gravity=(0, 0, -9.81)):
    return f"""\
domain: {{min: [0, 0, 0], max: [{BOX[0]}, {BOX[1]}, {BOX[2]}], periodic: [true, true, false]}}
gravity: [{gravity[0]}, {gravity[1]}, {gravity[2]}]
time: {{step: 1e-5, end: 1}}
materials:
  - {{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}}
interaction_defaults: {{restitution: 0.5, friction: 0.5}}
contact: {{normal: hertz}}
walls:
  - {{type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass}}
  - {{type: plane, name: lid, point: [0, 0, {BOX[2]}], normal: [0, 0, -1], material: glass}}
insert:
  - {{type: csv, file: beads.csv, material: glass}}
fluid:
  density: 1000
  viscosity: 1e-3
  drag: di_felice
  model: A
  pressure: {{hydrostatic: false}}
  forces: [drag, pressure_gradient, viscous, buoyancy]
output: {{fields: [id, position, velocity, angular_velocity, radius, force, fluid_force]}}
"""


HEADER = """FoamFile
{{
    version     2.0;
    format      ascii;
    class       {cls};
    object      {obj};
}}
"""


def foam_file(case, path, cls, text):
    full = os.path.join(case, path)
    os.makedirs(os.path.dirname(full), exist_ok=True)
    with open(full, "w") as out:
        out.write(HEADER.format(cls=cls, obj=os.path.basename(path)) + text)


def write_case(case, coupling, gravity=(0, 0, -9.81)):
    """The case's files; `coupling` is the couplingProperties entries besides `scene`."""
    mm = [1000 * b for b in BOX]
    foam_file(case, "system/blockMeshDict", "dictionary", f"""
scale 0.001;
vertices
(
    (0 0 0) ({mm[0]} 0 0) ({mm[0]} {mm[1]} 0) (0 {mm[1]} 0)
    (0 0 {mm[2]}) ({mm[0]} 0 {mm[2]}) ({mm[0]} {mm[1]} {mm[2]}) (0 {mm[1]} {mm[2]})
);
blocks ( hex (0 1 2 3 4 5 6 7) ({CELLS[0]} {CELLS[1]} {CELLS[2]}) simpleGrading (1 1 1) );
boundary
(
    left   {{ type cyclic; neighbourPatch right; faces ( (0 4 7 3) ); }}
    right  {{ type cyclic; neighbourPatch left;  faces ( (1 2 6 5) ); }}
    front  {{ type cyclic; neighbourPatch back;  faces ( (0 1 5 4) ); }}
    back   {{ type cyclic; neighbourPatch front; faces ( (3 7 6 2) ); }}
    walls  {{ type wall; faces ( (0 3 2 1) (4 5 6 7) ); }}
);
""")
    foam_file(case, "system/controlDict", "dictionary", f"""
application     grainFoam;
startFrom       startTime;
startTime       0;
stopAt          endTime;
endTime         {DT_FLUID * STEPS!r};
deltaT          {DT_FLUID!r};
writeControl    timeStep;
writeInterval   {STEPS};
purgeWrite      0;
writeFormat     ascii;
writePrecision  17;
writeCompression off;
timeFormat      general;
timePrecision   6;
runTimeModifiable false;
adjustTimeStep  no;
""")
    foam_file(case, "system/fvSchemes", "dictionary", """
ddtSchemes      { default Euler; }
gradSchemes     { default Gauss linear; }
divSchemes
{
    default         none;
    div(phi,U)      Gauss limitedLinearV 1;
    div(((c*nu)*dev2(T(grad(U))))) Gauss linear;
}
laplacianSchemes { default Gauss linear corrected; }
interpolationSchemes { default linear; }
snGradSchemes   { default corrected; }
""")
    foam_file(case, "system/fvSolution", "dictionary", """
solvers
{
    p      { solver GAMG; smoother DIC; tolerance 1e-8; relTol 0.01; }
    pFinal { $p; relTol 0; }
    "(U|UFinal)" { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-9; relTol 0; }
}
PIMPLE
{
    nOuterCorrectors 1;
    nCorrectors 2;
    nNonOrthogonalCorrectors 0;
    momentumPredictor yes;
    pRefCell 0;
    pRefValue 0;
}
""")
    foam_file(case, "0/U", "volVectorField", """
dimensions      [0 1 -1 0 0 0 0];
internalField   uniform (0.05 0.02 0);
boundaryField
{
    ".*"   { type cyclic; }
    walls  { type noSlip; }
}
""")
    foam_file(case, "0/p", "volScalarField", """
dimensions      [0 2 -2 0 0 0 0];
internalField   uniform 0;
boundaryField
{
    ".*"   { type cyclic; }
    walls  { type zeroGradient; }
}
""")
    foam_file(case, "constant/transportProperties", "dictionary",
              "\nrho     1000;\nnu      1e-6;\n")  # = the scene's fluid density, viscosity
    entries = "".join(f"{k} {foam_value(v)};\n" for k, v in coupling)
    foam_file(case, "constant/couplingProperties", "dictionary",
              '\nscene "particles.yaml";\n' + entries)
    with open(os.path.join(case, "particles.yaml"), "w") as out:
        out.write(scene(gravity))
    with open(os.path.join(case, "beads.csv"), "w") as out:
        out.write(beads())


# ---------------------------------------------------------------- runs and their outcome

def normalised_log(text, case):
    """grainFoam's log without what changes from run to run of the same case: the header's
    date, time, host and process id, OpenFOAM's ExecutionTime/ClockTime, grainFoam's time
    splits (wall clock and CPU), and the case's own folder (each run has its own)."""
    out = []
    for line in text.replace(case, "<case>").splitlines():
        if re.match(r"^(Date|Time|Host|PID)\s+:", line) or line.startswith("ExecutionTime ="):
            continue
        if line.startswith("grainFoam time split") or line.startswith("grainFoam CPU time split"):
            continue
        out.append(line)
    return "\n".join(out)


def digest_h5(path):
    """Every group's, dataset's and attribute's name and value (not the file's bytes: HDF5
    stamps its objects with the time they were written)."""
    h = hashlib.sha256()

    def attrs(obj):
        for k in sorted(obj.attrs):
            h.update(k.encode() + repr(np.asarray(obj.attrs[k]).tolist()).encode())

    def visit(name, obj):
        h.update(name.encode())
        attrs(obj)
        if isinstance(obj, h5py.Dataset):
            h.update(str(obj.dtype).encode() + repr(obj.shape).encode())
            h.update(np.ascontiguousarray(obj[()]).tobytes())

    with h5py.File(path, "r") as f:
        attrs(f)
        f.visititems(visit)
    return h.hexdigest()


# Lines that carry the checkpoint's byte checksum (its HDF5 time stamps, see digest_h5):
# uniform/grainflowCheckpoint's checkpointChecksum and grainflowChecksums' line for that file.
VOLATILE = re.compile(r"^\s*(checkpointChecksum\s|\"uniform/grainflowCheckpoint\"\s)")


def digest_text(path):
    with open(path, "rb") as f:
        lines = f.read().decode("utf-8", "replace").splitlines()
    kept = "\n".join(line for line in lines if not VOLATILE.match(line))
    return hashlib.sha256(kept.encode()).hexdigest()


# What a run starts from (written by write_case or blockMesh), not what grainFoam wrote.
INPUTS = {"0", "constant", "system", "particles.yaml", "beads.csv", "log.grainFoam"}


def written_files(case):
    """{relative path: digest} of every file grainFoam wrote: the time folders after 0
    (fields, uniform/, grainflowChecksums) and the particle folder (snapshots, checkpoint,
    particles.xdmf)."""
    out = {}
    for top in sorted(os.listdir(case)):
        if top in INPUTS:
            continue
        for dirpath, _, files in os.walk(os.path.join(case, top)):
            for name in sorted(files):
                full = os.path.join(dirpath, name)
                rel = os.path.relpath(full, case)
                out[rel] = digest_h5(full) if name.endswith(".h5") else digest_text(full)
    return out


class Runner:
    def __init__(self, args):
        self.foam_env, self.solver, self.work = args.foam_env, args.solver, args.work
        self.env = dict(os.environ)
        if args.lib_dir:
            self.env["LD_LIBRARY_PATH"] = os.pathsep.join(
                p for p in (args.lib_dir, os.environ.get("LD_LIBRARY_PATH", "")) if p)
        self.mesh = None
        self.runs, self.lock = {}, threading.Lock()

    def make_mesh(self):
        """blockMesh once: every run has the same mesh (a copy of constant/polyMesh)."""
        case = os.path.join(self.work, "mesh")
        shutil.rmtree(case, ignore_errors=True)
        write_case(case, [])
        r = subprocess.run([self.foam_env, "blockMesh", "-case", case], env=self.env,
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                           timeout=300)
        if r.returncode != 0:
            raise RuntimeError(f"blockMesh failed (exit {r.returncode}):\n{r.stdout[-3000:]}")
        self.mesh = os.path.join(case, "constant", "polyMesh")

    def outcome(self, coupling, gravity):
        """The outcome of the case with these couplingProperties entries and gravity, run once
        per distinct configuration (the threads asking for the same one wait for it)."""
        key = json.dumps([coupling, gravity])
        with self.lock:
            mine = key not in self.runs
            if mine:
                self.runs[key] = threading.Event()
                folder = os.path.join(self.work, "run%02d" % len(self.runs))
            event = self.runs[key]
        if mine:
            try:
                event.result = self.run(folder, coupling, gravity)
            except Exception as e:  # the threads waiting for it fail too, not hang
                event.result = e
            event.set()
        event.wait()
        if isinstance(event.result, Exception):
            raise event.result
        return event.result

    def run(self, case, coupling, gravity):
        shutil.rmtree(case, ignore_errors=True)
        write_case(case, coupling, gravity)
        shutil.copytree(self.mesh, os.path.join(case, "constant", "polyMesh"))
        # One rank without Open MPI's daemon: the same program, 0.2 s less per run.
        with isolated_singleton(self.env) as env:
            r = subprocess.run([self.foam_env, self.solver, "-case", case], cwd=case, env=env,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                               timeout=300)
        with open(os.path.join(case, "log.grainFoam"), "w") as f:
            f.write(r.stdout)
        result = {"status": r.returncode, "log": normalised_log(r.stdout, case)}
        result.update(written_files(case))
        result["case"] = case
        return result


# ---------------------------------------------------------------- the checks

class Check:
    """`key` left out, written as `default`, written as `other`, on the case with the
    couplingProperties entries `base` (besides the key) and gravity `gravity`."""

    def __init__(self, key, default, other, base=(), gravity=(0, 0, -9.81)):
        self.key, self.default, self.other = key, default, other
        self.base, self.gravity = list(base), list(gravity)


CHECKS = [
    Check("voidFraction", "divided", "centre"),
    Check("dividedResolution", 5, 3),
    # smoothingFactor only shapes the smoothed footprint.
    Check("smoothingFactor", 2, 1.5, base=[("voidFraction", "smoothed")]),
    Check("sampling", "cell", "cellPoint"),
    # The bed's cell layers have a void fraction of 0.52 to 0.75 (none below 0.2): 0.7
    # clamps most of them.
    Check("minVoidFraction", 0.2, 0.7),
    Check("ddtVoidFraction", "on", "off"),
    Check("undisturbedVelocity", "off", "oseenBrinkman"),
    # suspensionWeight is refused unless the domain is periodic along gravity: here gravity
    # points along x, periodic (the walls at the bottom and top do not face it).
    Check("meanPressureGradient", "off", "suspensionWeight", gravity=(-9.81, 0, 0)),
    Check("dragVoidFraction", "cell", "sharpInterface"),
    # 3 mm: wider than a cell (2 mm), so the averaging reaches the neighbours.
    Check("diffusionBandwidth", 0, 3e-3),
    Check("facePressure", "linear", "dragSeries"),
]

# Rows with a stated default that no run above can write down, and why.
SKIPPED = {
    "allowLargeTimeStep": "acts only on a DEM step the time-step check refuses, where the "
                          "run with the key left out stops at start-up (nothing to compare); "
                          "coupling.refuses_bad_setup runs that case left out (refused) and "
                          "with `yes` (it starts)",
}

# Everything of an outcome that two runs must share to count as the same.
IGNORED = {"case"}


def differences(a, b):
    return sorted(k for k in (set(a) | set(b)) - IGNORED if a.get(k) != b.get(k))


def log_diff(a, b, limit=12):
    lines = list(difflib.unified_diff(a.splitlines(), b.splitlines(), lineterm="", n=0))
    return "\n".join(lines[2:2 + limit])


def check_one(runner, c):
    left_out = runner.outcome(c.base, c.gravity)
    given = runner.outcome(c.base + [(c.key, c.default)], c.gravity)
    changed = runner.outcome(c.base + [(c.key, c.other)], c.gravity)
    what = f"{c.key}: default {foam_value(c.default)}"
    for name, o in (("left out", left_out), (f"{foam_value(c.other)}", changed)):
        if o["status"] != 0:  # a refused case shows nothing about the key
            return False, (f"{what}: the run with the key {name} exits {o['status']} "
                           f"({o['case']}/log.grainFoam):\n" + o["log"][-2000:])
    diff = differences(left_out, given)
    if diff:
        detail = (f"\n{log_diff(left_out['log'], given['log'])}" if "log" in diff else "")
        return False, (f"{what}: leaving the key out differs from writing the documented "
                       f"default, in {diff} ({left_out['case']} against {given['case']}){detail}")
    # The log names most settings: only what grainFoam computed shows that the key acts.
    diff = [k for k in differences(given, changed) if k not in ("status", "log")]
    if not diff:
        return False, (f"{what}: the case does not depend on the key ({foam_value(c.other)} "
                       f"writes the same files), so the check shows nothing")
    return True, f"{what} ({foam_value(c.other)} changes {', '.join(map(os.path.basename, diff))})"


def uncovered_rows(page):
    """The table's rows with a stated default that no check covers, or that the checks write
    as another value than the page's, and the checks of keys the page does not list."""
    out, listed = [], set()
    for heading, key, default in documented_rows(page):
        listed.add(key)
        if not stated(default):
            continue
        covering = [c for c in CHECKS if c.key == key]
        if covering:
            value = literal(default)
            if not any(c.default == value for c in covering):
                out.append(f"{heading} / {key}: the page states {default}, the check writes "
                           f"{foam_value(covering[0].default)}")
        elif key not in SKIPPED:
            out.append(f"{heading} / {key} (default {default}): no check")
    for c in CHECKS:
        if c.key not in listed:
            out.append(f"{c.key}: checked here, but the page's table has no row for it")
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--solver", required=True)
    parser.add_argument("--foam-env", required=True)
    parser.add_argument("--page", required=True, help="docs/coupling.md (or a copy)")
    parser.add_argument("--work", required=True)
    parser.add_argument("--lib-dir", default="")
    parser.add_argument("--only", help="check only keys containing this (no coverage check)")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    # The runs start in their case folders.
    for name in ("work", "solver", "foam_env", "page", "lib_dir"):
        if getattr(args, name):
            setattr(args, name, os.path.abspath(getattr(args, name)))
    os.makedirs(args.work, exist_ok=True)
    t0 = time.monotonic()
    uncovered = uncovered_rows(args.page)  # before the runs: a page error shows at once
    runner = Runner(args)
    runner.make_mesh()
    chosen = [c for c in CHECKS if not args.only or args.only in c.key]
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.workers) as pool:
        results = list(pool.map(lambda c: check_one(runner, c), chosen))
    failures = [text for ok, text in results if not ok]
    for ok, text in results:
        print(("ok   " if ok else "FAIL ") + text)
    if args.only:
        uncovered = []
    for u in uncovered:
        print("FAIL a documented default no check covers, or checks as another value: " + u)
    for k, why in SKIPPED.items():
        print(f"skip {k}: {why}")
    print(f"coupling.documented_defaults: {len(chosen)} documented defaults checked in "
          f"{len(runner.runs)} runs of grainFoam, {len(failures)} failed; {len(uncovered)} rows "
          f"uncovered or stated otherwise; {time.monotonic() - t0:.1f} s")
    return 1 if failures or uncovered else 0


if __name__ == "__main__":
    sys.exit(main())
