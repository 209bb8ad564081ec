#!/usr/bin/env python3
"""Random coupled scenes for grainFoam, each checked against invariants (docs/stability.md,
"Random coupled scenes").

    random_coupled.py --foam-env scripts/foam_env.sh --solver bin/grainFoam --lib-dir <lib>
                      --cases tests/coupling_stress/cases --work <scratch> --seeds 0:8
    random_coupled.py ... --seed 17 --keep        # one scene, reproducibly; keep its folder

Each seed draws one valid coupled case (numbers from Python's seeded random.Random(seed), so
a seed is the same case on every machine): a column of 2-5 x 2-5 x 6-14 cells of 1.5-4 mm,
each side axis periodic (cyclic patches) or walled (wall patches and DEM planes), a
distributor at the bottom (superficialVelocityInlet: at rest, or a step to 0-3 times the
particles' terminal velocity in the fluid) and a lid at the top; gas or liquid; beads of
0.15-1.2 cell sizes (particles larger than cells), overall solid fractions 0.02-0.25,
densities 1.05-3000 times the fluid's, one in three fills as coarse-grained parcels (k
1.2-2); any of the nine drag laws, model A or B, void fraction centre or divided, sampling
cell or cellPoint, minVoidFraction 0.2-0.45, diffusionBandwidth on or off, 1-12 DEM steps per
fluid step, 1 or 2 ranks. One case in three carries heat (its own random stream, so the
other draws stay as they were): particles, fluid and inlet at 280-500 K each, contact
conduction on or off, Ranz-Marshall or Gunn convection, no sources and adiabatic walls.

A case passes when grainFoam exits 0 and
  * the log holds no nan or inf; every printed void-fraction volume difference and
    exchange imbalance is below 1e-12 (round-off);
  * every `grainFoam particles:` line counts all the particles with none removed (the
    distributor and the lid are DEM planes; the sides are planes or periodic);
  * every snapshot is finite, holds all the particles, and every particle centre lies
    inside the domain and at least r (1 - time.max_overlap) from each wall plane;
  * every written void fraction lies within [minVoidFraction, 1];
  * with heat: every printed heat exchange imbalance is below 1e-12, and every particle
    temperature (snapshots) and fluid temperature (written T) lies within the starting
    and inlet temperatures (a maximum principle: no source, no flux), to 1e-3 of their range
    for the fluid's bounded but not monotone convection scheme;
  * stopped at a middle write and continued from it (startFrom latestTime, as many ranks),
    it ends with every particle's position and velocity (and temperature) equal to the
    run's to the last bit
    (--no-restarts leaves this out);
or when it exits non-zero with a message naming what to change (`error:` from the DEM
scene, with its file and key, or an OpenFOAM FatalError naming a dictionary key).
Anything else (a signal, a hang past --timeout, a crash without a message, a broken
invariant) fails the seed; its case folder is kept under --work.

Needs numpy, h5py (scripts/python.sh finds a Python that has them).
"""
import argparse
import math
import os
import random
import re
import shutil
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from seeds import parse_seeds  # noqa: E402
from grainfoam_driver import (ROUND_OFF, NAN_WORD, balance_lines, particle_lines,  # noqa: E402
                              read_scalar_field, snapshots, time_folders, void_lines)

DRAG_LAWS = ["schiller_naumann", "di_felice", "rong", "wen_yu", "ergun", "gidaspow",
             "koch_hill", "beetstra", "tenneti_garg_subramaniam"]
HEADER = """FoamFile
{{
    version     2.0;
    format      ascii;
    class       {cls};
    object      {obj};
}}
"""
# Acceptable refusals: a DEM scene error (file:line: error: ...) or an OpenFOAM fatal error
# that names what to change.
SCENE_ERROR = re.compile(r"particles\.yaml(:\d+)*: error: .+")
FOAM_FATAL = re.compile(r"--> FOAM FATAL (IO )?ERROR")


def terminal_velocity(d, rho_p, rho_f, mu, g=9.81):
    """Schiller-Naumann terminal velocity of one sphere (fixed-point iteration)."""
    v = (rho_p - rho_f) * g * d * d / (18 * mu)
    for _ in range(100):
        re_p = rho_f * v * d / mu
        cd = 24 / max(re_p, 1e-12) * (1 + 0.15 * re_p ** 0.687) if re_p < 1000 else 0.44
        v_new = math.sqrt(4 * (rho_p - rho_f) * g * d / (3 * rho_f * cd))
        if abs(v_new - v) < 1e-9 * v_new:
            break
        v = 0.5 * (v + v_new)
    return v


def rayleigh_time(r, rho, youngs, nu):
    shear = youngs / (2 * (1 + nu))
    return math.pi * r * math.sqrt(rho / shear) / (0.1631 * nu + 0.8766)


def draw(seed):
    """One case's parameters."""
    rnd = random.Random(seed)
    c = {"seed": seed}
    h = rnd.uniform(1.5e-3, 4e-3)
    c["h"] = h
    c["cells"] = [rnd.randint(2, 5), rnd.randint(2, 5), rnd.randint(6, 14)]
    c["periodic"] = [rnd.random() < 0.5, rnd.random() < 0.5]
    c["ranks"] = rnd.choice([1, 2])
    # Split along an axis whose cell count is even: `simple` splits by cell count, so an odd
    # count puts a shared layer between the ranks, not a grid of boxes (grainFoam refuses it).
    if c["ranks"] == 2:
        even = [a for a in (2, 2, 0, 1) if c["cells"][a] % 2 == 0]
        if not even:
            c["cells"][2] += 1
            even = [2]
        c["split"] = rnd.choice(even)
    else:
        c["split"] = None
    c["size"] = [n * h for n in c["cells"]]
    gas = rnd.random() < 0.6
    c["rho_f"], c["nu_f"] = (1.2, 1.5e-5) if gas else (1000.0, 1e-6)
    c["rho_p"] = c["rho_f"] * (rnd.uniform(400, 2500) if gas else rnd.uniform(1.05, 3.0))
    c["d"] = rnd.uniform(0.15, 1.2) * h
    c["k"] = rnd.uniform(1.2, 2.0) if rnd.random() < 1 / 3 else 1.0
    # Parcels of k d must fit the column's narrowest side several times.
    narrow = min(c["size"][:2])
    c["k"] = min(c["k"], max(1.0, narrow / (3 * c["d"])))
    # A periodic axis must be longer than twice the interaction range (2 r_max + skin; the
    # scene refuses it otherwise): wall it when it is not comfortably so.
    for axis in range(2):
        if c["periodic"][axis] and c["size"][axis] < 3 * c["k"] * c["d"]:
            c["periodic"][axis] = False
    # Each rank's half must be thicker than the interaction range (the scene refuses it
    # otherwise, "use fewer MPI ranks"): one rank when it is not comfortably so.
    if c["ranks"] == 2 and c["size"][c["split"]] / 2 < 1.5 * c["k"] * c["d"]:
        c["ranks"], c["split"] = 1, None
    c["phi"] = rnd.uniform(0.02, 0.25)
    volume = c["size"][0] * c["size"][1] * c["size"][2]
    parcel = math.pi / 6 * (c["k"] * c["d"]) ** 3
    c["count"] = int(max(5, min(1200, c["phi"] * volume / parcel)))
    c["youngs"] = 10 ** rnd.uniform(6, 8)
    c["poisson"] = rnd.uniform(0.2, 0.35)
    c["restitution"] = rnd.uniform(0.3, 0.95)
    c["friction"] = rnd.uniform(0.0, 0.6)
    c["drag"] = rnd.choice(DRAG_LAWS)
    c["model"] = rnd.choice(["A", "B"])
    c["void"] = rnd.choice(["centre", "divided"])
    c["resolution"] = rnd.choice([2, 3, 4])
    c["sampling"] = rnd.choice(["cell", "cellPoint"])
    c["min_eps"] = round(rnd.uniform(0.2, 0.45), 3)
    c["bandwidth"] = round(rnd.uniform(1, 3) * c["d"], 6) if rnd.random() < 0.3 else 0.0
    c["ddt"] = rnd.choice(["on", "off"])
    mu = c["rho_f"] * c["nu_f"]
    v_t = terminal_velocity(c["d"], c["rho_p"], c["rho_f"], mu)
    c["u_in"] = 0.0 if rnd.random() < 0.25 else rnd.uniform(0.2, 3.0) * v_t
    c["t_on"] = rnd.choice([0.0, 0.005])
    # DEM step: a fifth of the parcels' Rayleigh time at most (t_R grows as k); the fluid step
    # a whole number of DEM steps, within a Courant number of 0.5 at the largest of the inflow
    # (through the clamped void fraction) and the terminal velocity.
    t_r = rayleigh_time(0.5 * c["d"] * c["k"], c["rho_p"], c["youngs"], c["poisson"])
    c["dt_dem"] = float(f"{rnd.uniform(0.05, 0.2) * t_r:.3g}")
    u_max = max(c["u_in"] / c["min_eps"], v_t, 0.05) * 2
    n_max = max(1, int(0.5 * h / u_max / c["dt_dem"]))
    c["n_sub"] = rnd.randint(1, min(12, n_max))
    c["dt_f"] = c["n_sub"] * c["dt_dem"]
    steps = rnd.randint(60, 200)
    c["end"] = float(f"{steps * c['dt_f']:.6g}")
    c["writes"] = rnd.randint(2, 4)
    c["max_speed"] = float(f"{max(1.0, 3 * u_max):.3g}")
    c["heat"] = draw_heat(c)
    if c["heat"]:
        c["bandwidth"] = 0.0  # diffusion averaging is not combined with heat (refused)
    return c


def draw_heat(c):
    """Heat for one case in three, from its own stream (the other draws stay as they were):
    starting particle, fluid and inlet temperatures, the particles' c and k, conduction on or
    off, the Nusselt law. None without heat."""
    rnd = random.Random(1000003 * c["seed"] + 17)
    if rnd.random() >= 1 / 3:
        return None
    gas = c["rho_f"] < 10
    return {"T_p": round(rnd.uniform(280, 500), 3), "T_f": round(rnd.uniform(280, 500), 3),
            "T_in": round(rnd.uniform(280, 500), 3),
            "c_p": float(f"{10 ** rnd.uniform(2, 3.3):.4g}"),
            "k_p": float(f"{10 ** rnd.uniform(-1, 1.5):.4g}"),
            "conduction": rnd.random() < 0.6,
            "c_f": 1005.0 if gas else 4180.0, "k_f": 0.026 if gas else 0.6,
            "convection": rnd.choice(["ranz_marshall", "gunn"])}


def blockmesh(c):
    nx, ny, nz = c["cells"]
    lx, ly, lz = (1000 * s for s in c["size"])
    side = []
    for axis, (lo, hi, lo_faces, hi_faces) in enumerate([
            ("left", "right", "(0 4 7 3)", "(1 2 6 5)"),
            ("front", "back", "(0 1 5 4)", "(3 7 6 2)")]):
        if c["periodic"][axis]:
            side.append(f"    {lo} {{ type cyclic; neighbourPatch {hi}; faces ( {lo_faces} ); }}")
            side.append(f"    {hi} {{ type cyclic; neighbourPatch {lo}; faces ( {hi_faces} ); }}")
        else:
            side.append(f"    {lo} {{ type wall; faces ( {lo_faces} ); }}")
            side.append(f"    {hi} {{ type wall; faces ( {hi_faces} ); }}")
    return HEADER.format(cls="dictionary", obj="blockMeshDict") + f"""
scale 0.001;
vertices
(
    (0 0 0) ({lx!r} 0 0) ({lx!r} {ly!r} 0) (0 {ly!r} 0)
    (0 0 {lz!r}) ({lx!r} 0 {lz!r}) ({lx!r} {ly!r} {lz!r}) (0 {ly!r} {lz!r})
);
blocks ( hex (0 1 2 3 4 5 6 7) ({nx} {ny} {nz}) simpleGrading (1 1 1) );
boundary
(
    inlet  {{ type patch; faces ( (0 3 2 1) ); }}
    outlet {{ type patch; faces ( (4 5 6 7) ); }}
{chr(10).join(side)}
);
"""


def fields(c):
    sides_u, sides_p = [], []
    for axis, (lo, hi) in enumerate([("left", "right"), ("front", "back")]):
        if c["periodic"][axis]:
            sides_u.append(f"    \"({lo}|{hi})\" {{ type cyclic; }}")
            sides_p.append(f"    \"({lo}|{hi})\" {{ type cyclic; }}")
        else:
            sides_u.append(f"    \"({lo}|{hi})\" {{ type noSlip; }}")
            sides_p.append(f"    \"({lo}|{hi})\" {{ type zeroGradient; }}")
    u_in, t_on = c["u_in"], c["t_on"]
    if t_on > 0:
        table = f"(0 (0 0 0)) ({t_on} (0 0 0)) ({t_on + 1e-4} (0 0 {u_in!r})) (100 (0 0 {u_in!r}))"
    else:
        table = f"(0 (0 0 {u_in!r})) (100 (0 0 {u_in!r}))"
    u = HEADER.format(cls="volVectorField", obj="U") + f"""
dimensions      [0 1 -1 0 0 0 0];
internalField   uniform (0 0 0);
boundaryField
{{
    inlet
    {{
        type                superficialVelocityInlet;
        superficialVelocity table ( {table} );
    }}
    outlet {{ type zeroGradient; }}
{chr(10).join(sides_u)}
}}
"""
    p = HEADER.format(cls="volScalarField", obj="p") + f"""
dimensions      [0 2 -2 0 0 0 0];
internalField   uniform 0;
boundaryField
{{
    inlet  {{ type fixedFluxPressure; }}
    outlet {{ type fixedValue; value uniform 0; }}
{chr(10).join(sides_p)}
}}
"""
    return u, p


def temperature_field(c):
    """0/T: the fluid at T_f, the inlet gas at T_in, outflow and walls insulated."""
    th = c["heat"]
    sides = []
    for axis, (lo, hi) in enumerate([("left", "right"), ("front", "back")]):
        kind = "cyclic" if c["periodic"][axis] else "zeroGradient"
        sides.append(f"    \"({lo}|{hi})\" {{ type {kind}; }}")
    return HEADER.format(cls="volScalarField", obj="T") + f"""
dimensions      [0 0 0 1 0 0 0];
internalField   uniform {th['T_f']!r};
boundaryField
{{
    inlet  {{ type fixedValue; value uniform {th['T_in']!r}; }}
    outlet {{ type inletOutlet; inletValue uniform {th['T_f']!r}; value uniform {th['T_f']!r}; }}
{chr(10).join(sides)}
}}
"""


def scene(c):
    lx, ly, lz = c["size"]
    walls = ["  - {type: plane, name: distributor, point: [0, 0, 0], normal: [0, 0, 1], "
             "material: m}",
             f"  - {{type: plane, name: lid, point: [0, 0, {lz!r}], normal: [0, 0, -1], "
             "material: m}"]
    for axis, name in enumerate("xy"):
        if not c["periodic"][axis]:
            lo = [0, 0, 0]
            hi = [0, 0, 0]
            hi[axis] = c["size"][axis]
            n_lo = [0, 0, 0]
            n_lo[axis] = 1
            n_hi = [0, 0, 0]
            n_hi[axis] = -1
            walls.append(f"  - {{type: plane, name: {name}lo, point: {lo}, normal: {n_lo}, "
                         "material: m}")
            walls.append(f"  - {{type: plane, name: {name}hi, point: {hi}, normal: {n_hi}, "
                         "material: m}")
    parcel = f"\n    coarse_grain: {c['k']:.4f}" if c["k"] > 1 else ""
    th = c["heat"]
    material_heat = heat = temperature = fluid_heat = ""
    if th:
        material_heat = f", heat_capacity: {th['c_p']!r}, conductivity: {th['k_p']!r}"
        heat = "\nheat: {}" if th["conduction"] else "\nheat: {conduction: none}"
        temperature = f"\n    temperature: {th['T_p']!r}"
        # grain's prescribed fluid temperature; grainFoam's is 0/T.
        fluid_heat = (f"\n  temperature: {th['T_f']!r}\n  heat_capacity: {th['c_f']!r}\n"
                      f"  conductivity: {th['k_f']!r}\n  convection: {th['convection']}")
    r = 0.5 * c["d"]
    return f"""# random_coupled.py seed {c['seed']}
domain:
  min: [0, 0, 0]
  max: [{lx!r}, {ly!r}, {lz!r}]
  periodic: [{str(c['periodic'][0]).lower()}, {str(c['periodic'][1]).lower()}, false]
gravity: [0, 0, -9.81]
time:
  step: {c['dt_dem']!r}
  end: {c['end']!r}
  expected_max_speed: {c['max_speed']!r}
materials:
  - {{name: m, youngs_modulus: {c['youngs']:.4g}, poisson_ratio: {c['poisson']:.3f}, density: {c['rho_p']:.6g}{material_heat}}}
interaction_defaults: {{restitution: {c['restitution']:.3f}, friction: {c['friction']:.3f}}}
contact: {{normal: hertz, tangential: history}}{heat}
walls:
{chr(10).join(walls)}
insert:
  - type: fill
    region: {{box: {{min: [0, 0, 0], max: [{lx!r}, {ly!r}, {lz!r}]}}}}
    material: m
    radius: {{distribution: constant, value: {r!r}}}
    count: {c['count']}
    seed: {c['seed'] + 1}{parcel}{temperature}
fluid:
  density: {c['rho_f']!r}
  viscosity: {c['rho_f'] * c['nu_f']!r}
  drag: {c['drag']}
  model: {c['model']}
  pressure: {{hydrostatic: false}}
  forces: [drag, pressure_gradient, viscous, buoyancy]{fluid_heat}
"""


def coupling(c):
    lines = ['scene           "particles.yaml";', f"voidFraction    {c['void']};",
             f"sampling        {c['sampling']};", f"minVoidFraction {c['min_eps']};",
             f"ddtVoidFraction {c['ddt']};"]
    if c["void"] == "divided":
        lines.append(f"dividedResolution {c['resolution']};")
    if c["bandwidth"] > 0:
        lines.append(f"diffusionBandwidth {c['bandwidth']!r};")
    return HEADER.format(cls="dictionary", obj="couplingProperties") + "\n".join(lines) + "\n"


def make_case(c, template, case):
    shutil.rmtree(case, ignore_errors=True)
    os.makedirs(os.path.join(case, "0"))
    os.makedirs(os.path.join(case, "constant"))
    os.makedirs(os.path.join(case, "system"))
    for f in ("system/fvSchemes", "system/fvSolution", "system/controlDict"):
        shutil.copy(os.path.join(template, f), os.path.join(case, f))
    write = lambda path, text: open(os.path.join(case, path), "w").write(text)  # noqa: E731
    with open(os.path.join(case, "system/controlDict")) as f:
        control = f.read()
    control = re.sub(r"endTime\s+[^;]+;", f"endTime         {c['end']!r};", control)
    control = re.sub(r"deltaT\s+[^;]+;", f"deltaT          {c['dt_f']!r};", control)
    # Writes every m fluid steps; binary, so that a restart is bit-identical (docs/coupling.md).
    c["steps"] = int(round(c["end"] / c["dt_f"]))
    m = max(1, c["steps"] // c["writes"])
    c["write_steps"] = m
    write_interval = c["dt_f"] * m
    control = re.sub(r"writeInterval\s+[^;]+;", f"writeInterval   {write_interval!r};", control)
    control = re.sub(r"writeFormat\s+[^;]+;", "writeFormat     binary;", control)
    control = re.sub(r"timePrecision\s+[^;]+;", "timePrecision   12;", control)
    control = re.sub(r"writeControl\s+[^;]+;", "writeControl    runTime;", control)
    write("system/controlDict", control)
    write("system/blockMeshDict", blockmesh(c))
    u, p = fields(c)
    write("0/U", u)
    write("0/p", p)
    transport = f"rho     {c['rho_f']!r};\nnu      {c['nu_f']!r};\n"
    th = c["heat"]
    if th:
        transport += f"Cp      {th['c_f']!r};\nkappa   {th['k_f']!r};\n"
        write("0/T", temperature_field(c))
        for path, after, add in (
                ("system/fvSchemes", "div(phi,U)      Gauss limitedLinearV 1;",
                 "\n    div(phi,T)      Gauss limitedLinear 1;"),
                ("system/fvSolution", '"(U|UFinal)" { solver smoothSolver; smoother '
                 'symGaussSeidel; tolerance 1e-9; relTol 0; }',
                 "\n    T      { solver PBiCGStab; preconditioner DILU; tolerance 1e-12; "
                 "relTol 0; }")):
            with open(os.path.join(case, path)) as f:
                text = f.read()
            if after not in text:
                raise RuntimeError(f"generator: no '{after}' in {path}")
            write(path, text.replace(after, after + add))
    write("constant/transportProperties", HEADER.format(cls="dictionary", obj="transportProperties")
          + transport)
    write("constant/couplingProperties", coupling(c))
    write("particles.yaml", scene(c))
    if c["ranks"] == 2:
        n = [1, 1, 1]
        n[c["split"]] = 2
        write("system/decomposeParDict", HEADER.format(cls="dictionary", obj="decomposeParDict")
              + f"numberOfSubdomains 2;\nmethod          simple;\ncoeffs          {{ n ({n[0]} {n[1]} {n[2]}); }}\n")


class Runner:
    def __init__(self, args):
        self.args = args
        self.env = dict(os.environ)
        if args.lib_dir:
            self.env["LD_LIBRARY_PATH"] = os.pathsep.join(
                p for p in (args.lib_dir, os.environ.get("LD_LIBRARY_PATH", "")) if p)

    def run(self, case, log, *command, ranks=1):
        """(exit code or 'timeout', output)."""
        cmd = [self.args.foam_env]
        if ranks > 1:
            cmd += [self.args.mpiexec, "-np", str(ranks), "--oversubscribe"]
        cmd += list(command) + ["-case", case] + (["-parallel"] if ranks > 1 else [])
        try:
            r = subprocess.run(cmd, cwd=case, env=self.env, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True, timeout=self.args.timeout)
            out, code = r.stdout, r.returncode
        except subprocess.TimeoutExpired as e:
            out = (e.stdout or b"").decode(errors="replace") if isinstance(e.stdout, bytes) \
                else (e.stdout or "")
            code = "timeout"
        with open(os.path.join(case, "log." + log), "w") as f:
            f.write(out)
        return code, out


def read_void_fraction(path):
    """internalField of a binary (or ASCII) volScalarField: uniform or nonuniform."""
    with open(path, "rb") as f:
        data = f.read()
    head = data.index(b"internalField")
    m = re.compile(rb"internalField\s+uniform\s+(\S+);").match(data, head)
    if m:
        return np.array([float(m.group(1))])
    m = re.compile(rb"internalField\s+nonuniform\s+List<scalar>\s*(\d+)\s*\(").match(data, head)
    if not m:
        raise RuntimeError(f"{path}: no internalField")
    n = int(m.group(1))
    if b"format      binary" in data[:head] or b"format binary" in data[:head]:
        return np.frombuffer(data, dtype="<f8", count=n, offset=m.end())
    return read_scalar_field(path)


def check(c, case, log):
    """The invariants of a run that ended; a list of failures."""
    bad = []
    nan = sorted(set(m.group(0).lower() for m in NAN_WORD.finditer(log)))
    if nan:
        bad.append(f"nan/inf in the log: {nan}")
    lines = void_lines(log)
    worst = max((l[3] for l in lines), default=float("nan"))
    if not lines or not worst < ROUND_OFF:
        bad.append(f"void fraction volume difference {worst:.3g} (of {len(lines)} lines)")
    bal = balance_lines(log)
    worst_bal = max((b[2] for b in bal), default=float("nan"))
    if not bal or not worst_bal < ROUND_OFF:
        bad.append(f"exchange imbalance {worst_bal:.3g} (of {len(bal)} lines)")
    plines = particle_lines(log)
    counts = sorted(set(p[0] for p in plines))
    if not plines or counts != [c["placed"]] or any(p[1] for p in plines):
        bad.append(f"particle lines: counts {counts} (placed {c['placed']}), removed "
                   f"{max((p[1] for p in plines), default=-1)}")
    snaps = snapshots(case)
    if not snaps:
        bad.append("no snapshots")
    lo = np.zeros(3)
    hi = np.array(c["size"])
    for t, s in snaps:
        x, r = s["position"], s["radius"]
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(s["velocity"]))):
            bad.append(f"t = {t}: non-finite positions or velocities")
            continue
        if len(x) != c["placed"]:
            bad.append(f"t = {t}: {len(x)} particles, placed {c['placed']}")
        # Walled axes: at least r (1 - max_overlap) from each plane (default limit 0.25).
        for axis in range(3):
            if axis < 2 and c["periodic"][axis]:
                continue
            gap = np.minimum(x[:, axis] - lo[axis], hi[axis] - x[:, axis]) / r
            if gap.min() < 1 - 0.25:
                i = int(np.argmin(gap))
                bad.append(f"t = {t}: particle {int(s['id'][i])} at {x[i]} is {gap[i]:.3g} r "
                           f"from a wall across axis {axis} (< 0.75 r)")
    for folder in time_folders(case):
        eps = read_void_fraction(os.path.join(case, folder, "voidfraction"))
        if not (np.all(np.isfinite(eps)) and eps.min() >= c["min_eps"] and eps.max() <= 1.0):
            bad.append(f"t = {folder}: eps in [{eps.min()}, {eps.max()}], not within "
                       f"[{c['min_eps']}, 1]")
    if c["heat"]:
        bad += check_heat(c, case, log, snaps)
    return bad


HEAT_IMBALANCE = re.compile(r"grainFoam heat exchange: .*relative imbalance (\S+);")


def check_heat(c, case, log, snaps):
    """Heat: the exchange balanced to round-off, and the maximum principle (no source, no
    flux, adiabatic walls): every temperature within the starting and inlet ones."""
    bad = []
    th = c["heat"]
    imbalances = [float(v) for v in HEAT_IMBALANCE.findall(log)]
    if not imbalances or not max(imbalances) < ROUND_OFF:
        bad.append(f"heat exchange imbalance {max(imbalances, default=float('nan')):.3g} "
                   f"(of {len(imbalances)} lines)")
    lo = min(th["T_p"], th["T_f"], th["T_in"])
    hi = max(th["T_p"], th["T_f"], th["T_in"])
    # The fluid's limitedLinear convection is bounded but not monotone to round-off, and its
    # solver stops at a tolerance: 1e-3 of the range (and round-off of the values).
    tol = 1e-3 * (hi - lo) + 1e-12 * hi
    for t, snap in snaps:
        temp = snap.get("temperature")
        if temp is None:
            bad.append(f"t = {t}: the snapshot holds no temperature")
            break
        if not (np.all(np.isfinite(temp)) and temp.min() >= lo - tol and temp.max() <= hi + tol):
            bad.append(f"t = {t}: particle temperatures in [{temp.min():.12g}, "
                       f"{temp.max():.12g}] K, not within [{lo}, {hi}] K")
    for folder in time_folders(case):
        temp = read_void_fraction(os.path.join(case, folder, "T"))
        if not (np.all(np.isfinite(temp)) and temp.min() >= lo - tol and temp.max() <= hi + tol):
            bad.append(f"t = {folder}: fluid T in [{temp.min():.12g}, {temp.max():.12g}] K, "
                       f"not within [{lo}, {hi}] K")
    return bad


def refusal(log):
    """The message of an acceptable refusal, or None."""
    m = SCENE_ERROR.search(log)
    if m:
        return m.group(0)
    if FOAM_FATAL.search(log):
        tail = log[FOAM_FATAL.search(log).start():]
        text = " ".join(tail.split("\n")[1:8]).strip()
        # An OpenFOAM fatal error must say what to change: a key of a dictionary or file.
        if re.search(r"deltaT|couplingProperties|particles\.yaml|minVoidFraction|sampling|"
                     r"voidFraction|diffusionBandwidth|dividedResolution|decompos", text):
            return text[:300]
    return None


# The settings grainFoam's divergence message may name, and the edit of couplingProperties
# that applies each.
# Each: (file, its text before, after) for a case c, or None when c cannot take it.
REMEDIES = {
    "voidFraction divided": lambda c: ("constant/couplingProperties", "voidFraction    centre;",
                                       "voidFraction    divided;\ndividedResolution 3;"),
    "ddtVoidFraction off": lambda c: ("constant/couplingProperties", "ddtVoidFraction on;",
                                      "ddtVoidFraction off;"),
    # Half as many DEM steps per fluid step (with one, the scene's time.step would have to go
    # down too: the message says so, and this rerun is skipped).
    "a smaller deltaT in system/controlDict": lambda c: (
        "system/controlDict", f"deltaT          {c['dt_f']!r};",
        f"deltaT          {(c['n_sub'] // 2) * c['dt_dem']!r};") if c["n_sub"] >= 2 else None,
}


def diverged_at(log):
    """When the run stopped: the fluid's divergence, or the DEM's error in a coupled step."""
    m = re.search(r"the fluid diverged in [a-z ]+ at t = ([-+0-9.e]+) s", log) or \
        re.search(r"error: t = ([-+0-9.e]+) s \(step", log)
    return float(m.group(1)) if m else None


def run_seed(runner, args, seed):
    c = draw(seed)
    case = os.path.join(args.work, f"seed_{seed}")
    make_case(c, os.path.join(args.cases, "dense_bed"), case)
    t0 = time.monotonic()
    code, out = runner.run(case, "blockMesh", "blockMesh")
    if code != 0:
        return c, "FAIL", f"blockMesh exit {code}", time.monotonic() - t0
    if c["ranks"] == 2:
        code, out = runner.run(case, "decomposePar", "decomposePar")
        if code != 0:
            return c, "FAIL", f"decomposePar exit {code}", time.monotonic() - t0
    code, log = runner.run(case, "grainFoam", args.solver, ranks=c["ranks"])
    elapsed = time.monotonic() - t0
    if code == "timeout":
        return c, "FAIL", f"no end within {args.timeout} s", elapsed
    if code != 0:
        why = refusal(log)
        if why is None:
            tail = " | ".join(log.strip().split("\n")[-6:])
            return c, "FAIL", f"exit {code} without a message naming what to change: {tail[-600:]}", elapsed
        if "the fluid diverged" in log or "The fluid may be what drove the particles" in log:
            # Each setting the message names, applied alone, must carry the run further.
            first = diverged_at(log)
            tried = []
            for remedy, edit in REMEDIES.items():
                if remedy not in log or edit(c) is None:
                    continue
                path, old, new = edit(c)
                again = case + "_" + next(w for w in remedy.split()
                                          if w in ("voidFraction", "ddtVoidFraction", "deltaT"))
                shutil.rmtree(again, ignore_errors=True)
                shutil.copytree(case, again, ignore=shutil.ignore_patterns(
                    "[0-9].[0-9]*", "[1-9]*", "particles", "log.*"))
                path = os.path.join(again, path)
                with open(path) as f:
                    text = f.read()
                if old not in text:
                    return c, "FAIL", f"generator: no '{old}' in {path}", elapsed
                with open(path, "w") as f:
                    f.write(text.replace(old, new))
                code2, log2 = runner.run(again, "grainFoam", args.solver, ranks=c["ranks"])
                later = diverged_at(log2) if code2 != 0 else None
                if code2 != 0 and not (later is not None and later > first):
                    return c, "FAIL", (f"advice '{remedy}' does not get further (exit {code2}; "
                                       f"first stop t = {first}, rerun {later}): {why}"), elapsed
                tried.append(remedy)
                if not args.keep:
                    shutil.rmtree(again, ignore_errors=True)
            elapsed = time.monotonic() - t0
            return c, "refused", f"stopped at t = {first}; advice ran: {', '.join(tried)}", elapsed
        return c, "refused", why, elapsed
    if c["ranks"] == 2:
        runner.run(case, "reconstructPar", "reconstructPar", "-fields",
                   "(voidfraction T)" if c["heat"] else "(voidfraction)")
    m = re.search(r"grainFoam particles: (\d+) particles", log)
    c["placed"] = int(m.group(1)) if m else -1
    bad = check(c, case, log)
    if bad:
        return c, "FAIL", "; ".join(bad[:6]), elapsed
    if not args.no_restarts:
        failure, ran = restart_check(runner, args, c, case)
        elapsed = time.monotonic() - t0
        if failure:
            return c, "FAIL", failure, elapsed
        if ran:
            return c, "ok", f"{c['placed']} particles, restart identical", elapsed
    return c, "ok", f"{c['placed']} particles", elapsed


def restart_check(runner, args, c, case):
    """The case stopped at a middle write and continued from it (startFrom latestTime) must
    end with every particle's position and velocity equal to the uninterrupted run's to the
    last bit. Returns (failure or None, whether it ran)."""
    writes = c["steps"] // c["write_steps"]
    if writes < 2:
        return None, False
    middle = (writes // 2) * c["write_steps"]
    part = case + "_restart"
    make_case(c, os.path.join(args.cases, "dense_bed"), part)
    control = os.path.join(part, "system", "controlDict")
    with open(control) as f:
        text = f.read()
    t_mid = middle * c["dt_f"]
    with open(control, "w") as f:
        f.write(re.sub(r"endTime\s+[^;]+;", f"endTime         {t_mid!r};", text))
    runner.run(part, "blockMesh", "blockMesh")
    if c["ranks"] == 2:
        runner.run(part, "decomposePar", "decomposePar")
    code, log = runner.run(part, "grainFoam", args.solver, ranks=c["ranks"])
    if code != 0:
        return f"restart: the run to the middle write (t = {t_mid:.6g} s) exited {code}", True
    with open(control, "w") as f:
        f.write(text.replace("startFrom       startTime;", "startFrom       latestTime;"))
    code, log = runner.run(part, "grainFoam.restart", args.solver, ranks=c["ranks"])
    if code != 0 or "restart at time" not in log:
        return (f"restart from t = {t_mid:.6g} s: exit {code}, restart line "
                f"{'restart at time' in log}"), True
    a, b = snapshots(case)[-1], snapshots(part)[-1]
    if a[0] != b[0]:
        return f"restart: last snapshots at t = {a[0]} and {b[0]} s", True
    for key in ("id", "position", "velocity") + (("temperature",) if c["heat"] else ()):
        if a[1][key].shape != b[1][key].shape or not np.array_equal(a[1][key], b[1][key]):
            diff = (float(np.max(np.abs(a[1][key] - b[1][key])))
                    if a[1][key].shape == b[1][key].shape else float("nan"))
            return (f"restart from t = {t_mid:.6g} s: {key} differs from the uninterrupted run "
                    f"by {diff:.3g}"), True
    if not args.keep:
        shutil.rmtree(part, ignore_errors=True)
    return None, True


def summary(c):
    walls = "".join("p" if p else "w" for p in c["periodic"])
    return (f"{c['ranks']}r {walls} {'gas' if c['rho_f'] < 10 else 'liq'} d/h {c['d'] / c['h']:.2f} "
            f"k {c['k']:.2f} {c['drag']}/{c['model']} {c['void']}/{c['sampling']} "
            f"n {c['n_sub']}{' heat' if c['heat'] else ''}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--foam-env", required=True)
    ap.add_argument("--solver", required=True)
    ap.add_argument("--mpiexec", default="mpiexec")
    ap.add_argument("--lib-dir", default="")
    ap.add_argument("--cases", required=True, help="tests/coupling_stress/cases (its dense_bed)")
    ap.add_argument("--work", required=True)
    ap.add_argument("--seed", type=int)
    ap.add_argument("--seeds", type=parse_seeds, default="0:8",
                    help="ranges A:B (B excluded) and seeds, comma-separated: 0:8,17")
    ap.add_argument("--timeout", type=float, default=120, help="per grainFoam run [s]")
    ap.add_argument("--keep", action="store_true", help="keep the folders of passing seeds")
    ap.add_argument("--no-restarts", action="store_true",
                    help="leave out the restart from a middle write (bit for bit)")
    args = ap.parse_args()
    for key in ("foam_env", "solver", "cases", "work"):
        setattr(args, key, os.path.abspath(getattr(args, key)))
    if args.lib_dir:
        args.lib_dir = os.path.abspath(args.lib_dir)
    os.makedirs(args.work, exist_ok=True)
    seeds = [args.seed] if args.seed is not None else args.seeds
    runner = Runner(args)
    failed, t0 = [], time.monotonic()
    tally = {}
    for seed in seeds:
        c, result, what, elapsed = run_seed(runner, args, seed)
        tally[result] = tally.get(result, 0) + 1
        print(f"seed {seed:5d} {summary(c):60s} {elapsed:6.1f} s  {result}: {what}", flush=True)
        if result == "FAIL":
            failed.append(seed)
        elif not args.keep:
            shutil.rmtree(os.path.join(args.work, f"seed_{seed}"), ignore_errors=True)
    print(f"\n{len(seeds)} coupled scenes in {time.monotonic() - t0:.1f} s: "
          + ", ".join(f"{v} {k}" for k, v in sorted(tally.items()))
          + (f"; failed seeds {failed} (folders under {args.work})" if failed else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
