#!/usr/bin/env python3
"""Twin coupled cases: a random coupled case turned, moved or scaled must run as the case
itself (docs/stability.md, "Twin scenes").

    twin_cases.py --foam-env scripts/foam_env.sh --solver bin/grainFoam --grain bin/grain
                  --lib-dir <lib> --cases tests/coupling_stress/cases --work <scratch>
                  --seeds 0:8 [--twins turn1,turn2,shift,scale]

Each seed draws the case random_coupled.py draws (gravity along -z, the mesh's corner at the
origin) and runs it as drawn and as its twins (tests/stress/hard_scenes/twin_scenes.py): the
axes cycled once or twice (turn1, turn2: mesh vertices, the inlet's velocity table, the
decomposition, and every point and vector of the DEM scene turn together, so gravity points
along -x or -y), or everything moved by 0.01-10 m per axis (shift).
  * scale (asked for by name): the case in other units, lengths times 2^a, times 2^b, masses
    2^c (twin_scenes.Scale: its exponents, its scene and snapshot), every number of the
    OpenFOAM files converted by its dimension (FOAM_DIMENSIONS: the mesh's scale, the fields
    by their `dimensions`, the inlet's table of times and velocities, rho, nu, Cp, kappa,
    diffusionBandwidth, the controlDict's times); a number of no known dimension stops it.
    Snapshot times and positions are mapped back; a length or time written into the code
    (an absolute tolerance, a default in metres) is what makes it differ.
The fill's particles are first inserted by `grain run` (the DEM scene alone, to its t = 0
snapshot), and each case starts from that snapshot, turned, moved or scaled. Both cases solve
the fluid to 1e-15 (PCG, no relative tolerance): an iterative solver stopped at a looser
tolerance ends wherever its round-off takes it, which would hide an asymmetry under the
solver's own error.

A twin passes when grainFoam exits as for the drawn case and, after a stop, with the same
message (numbers and axis letters set aside); after a run, every snapshot holds the same
particles, each within 1e-6 of a particle diameter of the drawn case's, mapped back. Beyond
that, a chaotic case is judged against the drawn case started with each particle's x one ulp
larger (the nudge, twin_scenes.judge): a twin's fluid differs by round-off in every fluid
step, so it may deviate 1000 x (fluid steps so far) times as far as the nudge; once the nudge
reaches 0.01 d, later snapshots are not compared.

Needs numpy, h5py, yaml (scripts/python.sh finds a Python that has them).
"""
import argparse
import fnmatch
import json
import os
import re
import shutil
import subprocess
import sys
import time

import numpy as np
import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "stress", "hard_scenes"))
import random_coupled as rc  # noqa: E402
from grainfoam_driver import snapshots  # noqa: E402  (tests/support, via random_coupled)
from twin_scenes import (CHAOS_EVERY_STEP, TOLERANCE, Scale, Twin, judge,  # noqa: E402
                         same_stop)

TOLERANCE_D = 1e-6
TRIPLE = re.compile(r"\(\s*([-+0-9.eE]+)\s+([-+0-9.eE]+)\s+([-+0-9.eE]+)\s*\)")
TIGHT = {"solver GAMG; smoother DIC; tolerance 1e-8; relTol 0.01;":
         "solver PCG; preconditioner DIC; tolerance 1e-15; relTol 0; maxIter 5000;",
         "tolerance 1e-9; relTol 0;": "tolerance 1e-15; relTol 0; maxIter 5000;"}


def edit(path, change):
    with open(path) as f:
        text = f.read()
    new = change(text)
    with open(path, "w") as f:
        f.write(new)


def tighten(case):
    def change(text):
        for old, new in TIGHT.items():
            if old not in text:
                raise RuntimeError(f"twin_cases: no '{old}' in {case}/system/fvSolution")
            text = text.replace(old, new)
        return text
    edit(os.path.join(case, "system", "fvSolution"), change)


def start_from_snapshot(grain, case):
    """Replace the case's fill by the t = 0 snapshot `grain run` makes of it."""
    path = os.path.join(case, "particles.yaml")
    with open(path) as f:
        scene = yaml.safe_load(f)
    fill = scene["insert"][0]
    alone = json.loads(json.dumps(scene))
    alone.pop("fluid")
    alone.pop("heat", None)
    for m in alone["materials"]:
        m.pop("heat_capacity", None)
        m.pop("conductivity", None)
    alone["insert"][0].pop("temperature", None)
    alone["output"] = {"snapshot_interval": alone["time"]["end"], "directory": "out"}
    folder = os.path.join(case, "fill")
    os.makedirs(folder)
    with open(os.path.join(folder, "scene.yaml"), "w") as f:
        yaml.safe_dump(alone, f)
    p = subprocess.run([grain, "run", "scene.yaml", "--no-progress", "--allow-large-dt"],
                       cwd=folder, capture_output=True, text=True)
    first = os.path.join(folder, "out", "particles_000000.h5")
    if not os.path.exists(first):
        raise RuntimeError(f"twin_cases: the fill inserted nothing: {p.stdout[-300:]}")
    shutil.copy(first, os.path.join(case, "filled.h5"))
    shutil.rmtree(folder)
    insertion = {"type": "snapshot", "file": "filled.h5"}
    if "temperature" in fill:
        insertion["temperature"] = fill["temperature"]
    scene["insert"] = [insertion]
    with open(path, "w") as f:
        yaml.safe_dump(scene, f, default_flow_style=None, sort_keys=False)


def make_twin(twin, drawn, case):
    shutil.rmtree(case, ignore_errors=True)
    shutil.copytree(drawn, case)

    def triples(text, point):
        def one(m):
            v = twin.turn([m.group(k) for k in (1, 2, 3)])  # as written: labels stay labels
            if point:  # blockMesh vertices are in mm (scale 0.001)
                v = [repr(float(v[a]) + 1000 * twin.offset[a]) for a in range(3)]
            return "(" + " ".join(v) + ")"
        return TRIPLE.sub(one, text)

    def mesh(text):
        i, j = text.index("vertices"), text.index("blocks")
        return text[:i] + triples(text[i:j], True) + text[j:]
    edit(os.path.join(case, "system", "blockMeshDict"), mesh)
    edit(os.path.join(case, "0", "U"), lambda t: triples(t, False))
    if os.path.exists(os.path.join(case, "system", "decomposeParDict")):
        edit(os.path.join(case, "system", "decomposeParDict"), lambda t: triples(t, False))
    path = os.path.join(case, "particles.yaml")
    with open(path) as f:
        scene = yaml.safe_load(f)
    with open(path, "w") as f:
        yaml.safe_dump(twin.scene(scene), f, default_flow_style=None, sort_keys=False)
    twin.snapshot(os.path.join(drawn, "filled.h5"), os.path.join(case, "filled.h5"))


# The scale twin's OpenFOAM files: the dimension (length, time, mass exponents, as
# twin_scenes.DIMENSIONS) of every number, by the file and the number's key path (dictionary
# keys joined by dots, list entries dropped; fnmatch patterns, the first that matches). FIELD
# is the field's own `dimensions` (0/); a function of the number and its file (Entry, Foam)
# returns a dimension or None. The numbers of a dimension set [M L T ...] stay, so does a
# list's size. A number under no pattern, or that its function cannot tell, stops the twin.
LENGTH, TIME, ONE = (1, 0, 0), (0, 1, 0), (0, 0, 0)
FIELD = "field"


def field_gradient(number, foam):
    return None if foam.field is None else (foam.field[0] - 1,) + foam.field[1:]


def function_of_time(number, foam):
    """A Function1 of time (superficialVelocityInlet's superficialVelocity): a table's times
    and values, or a constant."""
    kind = number.words[0] if number.words else "constant"
    if kind == "table" and len(number.index) >= 2:
        return TIME if number.index[1] == 0 else foam.field
    return foam.field if kind == "constant" else None


def write_interval(number, foam):
    """In the unit of controlDict's writeControl: seconds of simulated time, or steps; never
    seconds of wall-clock or CPU time (no twin of those)."""
    control = foam.words.get("writeControl", ["timeStep"])[0]
    return {"runTime": TIME, "adjustableRunTime": TIME, "timeStep": ONE}.get(control)


FOAM_DIMENSIONS = {
    "0/*": [
        ("internalField", FIELD), ("boundaryField.*.value", FIELD),
        ("boundaryField.*.inletValue", FIELD), ("boundaryField.*.refValue", FIELD),
        ("boundaryField.*.gradient", field_gradient),
        ("boundaryField.*.refGradient", field_gradient),
        ("boundaryField.*.valueFraction", ONE),
        ("boundaryField.*.superficialVelocity", function_of_time),
        ("boundaryField.*.minVoidFraction", ONE)],
    "constant/g": [("value", FIELD)],
    # grainFoam reads rho [kg/m^3], nu [m^2/s], Cp [J/(kg K)], kappa [W/(m K)].
    "constant/transportProperties": [
        ("rho", (-3, 0, 1)), ("nu", (2, -1, 0)), ("mu", (-1, -1, 1)), ("Cp", (2, -2, 0)),
        ("kappa", (1, -3, 1))],
    "constant/couplingProperties": [
        ("minVoidFraction", ONE), ("dividedResolution", ONE), ("smoothingFactor", ONE),
        ("diffusionBandwidth", LENGTH)],
    # The vertices are in the unit `scale` gives in metres: the scale converts.
    "system/blockMeshDict": [
        ("scale", LENGTH), ("convertToMeters", LENGTH), ("vertices", ONE), ("blocks", ONE),
        ("boundary.*", ONE), ("patches", ONE), ("edges", ONE)],
    "system/controlDict": [
        ("startTime", TIME), ("endTime", TIME), ("deltaT", TIME), ("maxDeltaT", TIME),
        ("writeInterval", write_interval), ("purgeWrite", ONE), ("writePrecision", ONE),
        ("timePrecision", ONE), ("maxCo", ONE)],
    "system/fvSchemes": [("*Schemes.*", ONE)],  # limiter and blending coefficients
    # OpenFOAM normalises the residuals its tolerances bound: numbers.
    "system/fvSolution": [
        ("solvers.*.tolerance", ONE), ("solvers.*.relTol", ONE), ("solvers.*.maxIter", ONE),
        ("solvers.*.minIter", ONE), ("solvers.*.nSweeps", ONE), ("PIMPLE.n*", ONE),
        ("PIMPLE.pRefCell", ONE), ("PIMPLE.pRefValue", (2, -2, 0)),
        ("PIMPLE.residualControl.*", ONE), ("relaxationFactors.*", ONE)],
    "system/decomposeParDict": [
        ("numberOfSubdomains", ONE), ("coeffs.n", ONE), ("simpleCoeffs.n", ONE),
        ("coeffs.delta", ONE), ("simpleCoeffs.delta", ONE)],
}
FOAM_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?=[\s{}()\[\];]|$)")


def foam_tokens(text):
    """(kind, start, end) of each token of an OpenFOAM dictionary file, comments left out:
    kind is 'number', 'word', 'string' or the punctuation itself. A word holds balanced
    parentheses (div(phi,U)), as OpenFOAM reads it."""
    out, i, n = [], 0, len(text)
    while i < n:
        ch = text[i]
        if ch.isspace():
            i += 1
        elif text.startswith("//", i):
            i = text.find("\n", i)
            i = n if i < 0 else i
        elif text.startswith("/*", i):
            i = text.index("*/", i) + 2
        elif ch in "{}()[];":
            out.append((ch, i, i + 1))
            i += 1
        elif ch == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            if j >= n:
                raise RuntimeError("twin_cases: a string without its closing '\"'")
            out.append(("string", i, j + 1))
            i = j + 1
        elif FOAM_NUMBER.match(text, i):
            j = FOAM_NUMBER.match(text, i).end()
            out.append(("number", i, j))
            i = j
        else:
            j, depth = i, 0
            while j < n and not text[j].isspace() and text[j] not in '{};"[]':
                if text[j] == "(":
                    depth += 1
                elif text[j] == ")":
                    if depth == 0:
                        break
                    depth -= 1
                j += 1
            out.append(("word", i, j))
            i = j
    return out


class Entry:
    """A number of an OpenFOAM file: its token, key path, place in the entry's (nested) lists,
    the entry's words before it, and the entry's dimension set before it (or None)."""

    def __init__(self, token, path, index, words, dimensions):
        self.token, self.path, self.index = token, path, index
        self.words, self.dimensions = words, dimensions


class Foam:
    """An OpenFOAM dictionary file, parsed for its numbers (Entry) and each entry's words."""

    def __init__(self, path, text):
        self.path, self.text = path, text
        self.tokens = foam_tokens(text)
        self.numbers, self.words, self.sets = [], {}, {}
        if self.dictionary(0, [], False) != len(self.tokens):
            self.fail(len(self.tokens), "a '}' without its '{'")
        self.field = self.sets.get("dimensions")  # 0/ fields: the field's dimension

    def word(self, k):
        return self.text[self.tokens[k][1]:self.tokens[k][2]]

    def fail(self, k, what):
        line = self.text.count("\n", 0, self.tokens[min(k, len(self.tokens) - 1)][1]) + 1
        raise RuntimeError(f"twin_cases: {self.path}:{line}: cannot read the file: {what}")

    def dictionary(self, k, path, braced):
        while k < len(self.tokens):
            kind = self.tokens[k][0]
            if kind == "}":
                return k + 1 if braced else k
            if kind == ";":
                k += 1
                continue
            if kind not in ("word", "string") or self.word(k).startswith("#"):
                self.fail(k, f"'{self.word(k)}' where a key should stand")
            key = path + [self.word(k)]
            if k + 1 < len(self.tokens) and self.tokens[k + 1][0] == "{":
                k = self.dictionary(k + 2, key, True)
            else:
                k = self.entry(k + 1, key)
        if braced:
            self.fail(k, "a '{' without its '}'")
        return k

    def entry(self, k, path):
        """An entry's value up to its ';': numbers, words, (nested) lists, dimension sets,
        dictionaries inside lists (blockMeshDict's boundary)."""
        key, stack, words, dims, bracket = ".".join(path), [], [], None, None
        while k < len(self.tokens):
            kind = self.tokens[k][0]
            if kind == ";" and not stack and bracket is None:
                self.words[key] = words
                return k + 1
            if kind == "(":
                stack.append(0)
            elif kind == ")":
                if not stack:
                    self.fail(k, "a ')' without its '('")
                stack.pop()
                if stack:
                    stack[-1] += 1
            elif kind == "[":
                bracket = []
            elif kind == "]":
                if bracket is None or len(bracket) not in (5, 7):
                    self.fail(k, "a dimension set that is not 5 or 7 numbers")
                d = [float(self.word(j)) for j in bracket]
                dims = self.sets[key] = (d[1], d[2], d[0])  # [M L T ...]: kelvin stay
                bracket = None
            elif kind == "{":
                named = self.tokens[k - 1][0] in ("word", "string") and stack
                k = self.dictionary(k + 1, path + [self.word(k - 1)] if named else path, True)
                continue
            elif kind == "}":
                self.fail(k, f"'{key}' has no ';'")
            elif kind == "number" and bracket is not None:
                bracket.append(k)  # an exponent: stays
            elif kind == "number":
                before = self.word(k - 1) if self.tokens[k - 1][0] == "word" else ""
                if not before.startswith("List<"):  # after List<...>: the list's size
                    self.numbers.append(Entry(k, key, tuple(stack), list(words), dims))
                if stack:
                    stack[-1] += 1
            else:
                words.append(self.word(k))
                if stack:
                    stack[-1] += 1
            k += 1
        self.fail(k, f"'{key}' has no ';'")


def scale_foam_file(twin, relative, path):
    """Rewrites one OpenFOAM file of a case in the scale twin's units (FOAM_DIMENSIONS)."""
    kinds = [k for k in FOAM_DIMENSIONS if fnmatch.fnmatchcase(relative, k)]
    if not kinds:
        raise RuntimeError(f"twin_cases: {relative}: no dimensions known for this file; add it "
                           "to FOAM_DIMENSIONS")
    rules = [("FoamFile.version", ONE)] + FOAM_DIMENSIONS[kinds[0]]
    with open(path) as f:
        foam = Foam(relative, f.read())
    if relative == "system/blockMeshDict" and not {"scale", "convertToMeters"} & set(foam.words):
        raise RuntimeError(f"twin_cases: {relative}: no scale entry (its vertices would stay in "
                           "metres)")
    pieces, at = [], 0
    for number in foam.numbers:
        rule = next((dim for pattern, dim in rules
                     if fnmatch.fnmatchcase(number.path, pattern)), None)
        dim = rule(number, foam) if callable(rule) else foam.field if rule == FIELD else rule
        _, start, end = foam.tokens[number.token]
        text = foam.text[start:end]
        if dim is None:
            raise RuntimeError(f"twin_cases: {relative}: the number {text} of '{number.path}' "
                               "has no dimension; add it to FOAM_DIMENSIONS")
        if number.dimensions is not None and tuple(number.dimensions) != tuple(dim):
            raise RuntimeError(f"twin_cases: {relative}: '{number.path}' has the dimension set "
                               f"(L T M) {number.dimensions}, FOAM_DIMENSIONS {dim}")
        f = twin.factor(dim)
        if f != 1:
            pieces += [foam.text[at:start], repr(float(text) * f)]
            at = end
    with open(path, "w") as out:
        out.write("".join(pieces) + foam.text[at:])


def make_scaled(twin, drawn, case):
    """The drawn case in the scale twin's units: the scene through twin_scenes.Scale, every
    OpenFOAM file by FOAM_DIMENSIONS; any other file stops the twin."""
    shutil.rmtree(case, ignore_errors=True)
    shutil.copytree(drawn, case)
    for folder, _, files in os.walk(case):
        for name in files:
            path = os.path.join(folder, name)
            relative = os.path.relpath(path, case)
            if relative == "particles.yaml":
                with open(path) as f:
                    scene = yaml.safe_load(f)
                with open(path, "w") as f:
                    yaml.safe_dump(twin.scene(scene), f, default_flow_style=None,
                                   sort_keys=False)
            elif relative == "filled.h5":
                twin.snapshot(os.path.join(drawn, relative), path)
            else:
                scale_foam_file(twin, relative, path)


def run(runner, args, case, ranks):
    code, out = runner.run(case, "blockMesh", "blockMesh")
    if code != 0:
        return "blockMesh", out
    if ranks == 2:
        code, out = runner.run(case, "decomposePar", "decomposePar")
        if code != 0:
            return "decomposePar", out
    return runner.run(case, "grainFoam", args.solver, ranks=ranks)


def deviations(twin, c, drawn, other):
    """Per snapshot (time, the largest position deviation in diameters, 0), mapped back; or
    a failure text."""
    if len(other) != len(drawn) or any(abs(twin.time(b) - a) > 1e-9 * abs(a)
                                       for (a, _), (b, _) in zip(drawn, other)):
        return None, "snapshots at other times"
    out = []
    for (t, a), (_, b) in zip(drawn, other):
        if not np.array_equal(a["id"], b["id"]):
            return None, f"t = {t}: other particle ids"
        dev = np.abs(twin.difference(b["position"], a["position"], t)).max() / c["d"]
        out.append((t, float(dev), 0.0))
    return out, None


def stop_message(log):
    return rc.refusal(log) or " | ".join(log.strip().split("\n")[-3:])


def make(name, seed, c):
    """The twin `name` of case c."""
    return Scale(seed) if name == "scale" else Twin(name, seed, max(c["size"]))


def check_seed(runner, args, seed, names):
    c = rc.draw(seed)
    work = os.path.join(args.work, f"seed_{seed}")
    shutil.rmtree(work, ignore_errors=True)
    drawn = os.path.join(work, "drawn")
    rc.make_case(c, os.path.join(args.cases, "dense_bed"), drawn)
    tighten(drawn)
    start_from_snapshot(args.grain, drawn)
    for name in names + ["nudge"]:  # before the drawn case runs: its inputs only
        (make_scaled if name == "scale" else make_twin)(make(name, seed, c), drawn,
                                                        os.path.join(work, name))
    code, log = run(runner, args, drawn, c["ranks"])
    if code not in (0, 1):
        return False, f"the drawn case: exit {code}: {stop_message(log)}", work
    first = snapshots(drawn) if code == 0 else None
    notes = []
    nudge = []

    def nudged():
        """The deviations of the drawn case started with each particle's x one ulp larger."""
        if not nudge:
            twin, case = Twin("nudge", seed), os.path.join(work, "nudge")
            ncode, nlog = run(runner, args, case, c["ranks"])
            devs, failure = deviations(twin, c, first, snapshots(case)) if ncode == 0 else \
                (None, stop_message(nlog))
            if failure:
                raise RuntimeError(f"the nudged case does not compare: {failure}")
            nudge.append(devs)
        return nudge[0]

    for name in names:
        twin, case = make(name, seed, c), os.path.join(work, name)
        tcode, tlog = run(runner, args, case, c["ranks"])
        if tcode != code:
            return False, (f"{name}: exit {tcode}, the drawn case {code}\n  drawn: "
                           f"{stop_message(log)}\n  twin:  {stop_message(tlog)}"), work
        if code != 0:
            if not same_stop(stop_message(log), stop_message(tlog)):
                return False, (f"{name}: another stop\n  drawn: {stop_message(log)}\n  twin:  "
                               f"{stop_message(tlog)}"), work
            notes.append(f"{name} stopped alike")
            continue
        devs, failure = deviations(twin, c, first, snapshots(case))
        chaotic = None
        if not failure:
            # A twin's fluid differs by round-off in every fluid step (cell volumes, centres
            # and face areas are summed in another order, or at other magnitudes), and the
            # DEM's by an ulp of the offset in every DEM step when moved.
            chaos = CHAOS_EVERY_STEP
            steps = (lambda when: max(1.0, when / c["dt_f"]))  # noqa: E731
            if twin.offset.any():
                chaos *= 1 + np.abs(twin.offset).max() / max(c["size"])
                steps = (lambda when: max(1.0, when / c["dt_dem"]))  # noqa: E731
            failure, chaotic = judge(name, devs, nudged, chaos, steps, TOLERANCE_D)
        if failure:
            return False, f"{name}: {failure}", work
        notes.append(f"{name} {max(v[1] for v in devs):.2g} d"
                     + (f" (chaotic: the nudge {max(v[1] for v in nudge[0]):.2g} d"
                        + (f", compared until t = {chaotic:.3g} s" if chaotic else "") + ")"
                        if nudge else ""))
    return True, ("ran; " if code == 0 else "stopped; ") + ", ".join(notes), work


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--foam-env", required=True)
    ap.add_argument("--solver", required=True)
    ap.add_argument("--grain", required=True)
    ap.add_argument("--lib-dir", default="")
    ap.add_argument("--cases", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--mpiexec", default="mpiexec")
    ap.add_argument("--seeds", type=rc.parse_seeds, required=True)
    ap.add_argument("--twins", default="turn1,turn2,shift",
                    help="comma-separated: turn1, turn2, shift, scale")
    ap.add_argument("--timeout", type=float, default=600, help="per run [s]")
    ap.add_argument("--keep", action="store_true")
    args = ap.parse_args()
    names = args.twins.split(",")
    for name in names:
        if name not in TOLERANCE:
            ap.error(f"--twins: unknown twin '{name}'; allowed: {', '.join(TOLERANCE)}")
    for attr in ("foam_env", "solver", "grain", "cases", "work"):
        setattr(args, attr, os.path.abspath(getattr(args, attr)))
    runner = rc.Runner(args)
    failed = []
    start = time.monotonic()
    for seed in args.seeds:
        t0 = time.monotonic()
        try:
            ok, note, work = check_seed(runner, args, seed, names)
        except (RuntimeError, OSError, ValueError, KeyError) as e:
            ok, note, work = False, f"{type(e).__name__}: {e}", None
        print(f"seed {seed:5d} {time.monotonic() - t0:7.1f} s  {'ok' if ok else 'FAIL'} ({note})",
              flush=True)
        if ok and work and not args.keep:
            shutil.rmtree(work, ignore_errors=True)
        if not ok:
            failed.append(seed)
    print(f"\n{len(args.seeds)} seeds in {time.monotonic() - start:.1f} s, {len(failed)} failed"
          + (f": {' '.join(map(str, failed))} (folders under {args.work})" if failed else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
