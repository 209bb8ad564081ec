#!/usr/bin/env python3
"""One sphere settling in a quiescent liquid, coarse cells: the terminal velocity against the
drag law's own terminal velocity, for a grid of cell sizes and particle Reynolds numbers.

The particle (d = 2 mm, rho_p = 2500 kg/m^3) settles in a liquid of rho_f = 1000 kg/m^3 whose
viscosity is chosen so that the Schiller-Naumann terminal Reynolds number is Re_t. Cells are
cubes of n particle diameters. The box is `--width` cells wide (walls all round) and tall
enough for the particle to fall `--fall` diameters (at least 6 cells) after reaching its
terminal speed. Error: the mean settling speed over the second half of the fall against u_t
from Schiller & Naumann (1933), C_D = 24/Re (1 + 0.15 Re^0.687); also printed: the fall over
the whole cells crossed in that half over its time, and the fluid's share of the particle's
fluid force at the end (the last exchange against m a + the submerged weight, a from the last
two snapshots; 1 when the fluid gets exactly the drag the particle feels).

Usage: settling_cells.py [--re 2] [--cells 3,5,10] [--correction oseenBrinkman]
                         [--footprint divided] [--sampling cell] [--width 16] [--fall 40]
                         [--courant 0.05] [--check PERCENT [--check-force PERCENT]]
                         [--work DIR] [--build DIR]
Prints one line per case and appends to <work>/settling_cells.csv; with --check, exit 1 unless
every |error| is within PERCENT (and, with --check-force, the fluid's share within PERCENT
of 1). The tables of docs/models/undisturbed-velocity.md come from
--courant 0.02 --width 16 at Re_t 0.1, 2 and 50, with and without --correction.
"""
import argparse
import csv
import glob
import math
import os
import re
import subprocess
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
FOAM = os.path.join(ROOT, "scripts", "foam_env.sh")
D, RHO_P, RHO_F, G = 2e-3, 2500.0, 1000.0, 9.81


def sn_drag(u, mu):
    re = RHO_F * u * D / mu
    return 3 * math.pi * mu * D * u * (1 + 0.15 * re**0.687)


def terminal(mu):
    weight = (RHO_P - RHO_F) * G * math.pi * D**3 / 6
    lo, hi = 1e-12, 100.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if sn_drag(mid, mu) > weight else (mid, hi)
    return 0.5 * (lo + hi)


def viscosity_for(re_t):
    lo, hi = 1e-5, 100.0  # terminal Re falls as mu grows
    for _ in range(200):
        mid = math.sqrt(lo * hi)
        re = RHO_F * terminal(mid) * D / mid
        lo, hi = (mid, hi) if re > re_t else (lo, mid)
    return math.sqrt(lo * hi)


HEADER = "FoamFile {{ version 2.0; format ascii; class {cls}; object {obj}; }}\n"


def write(path, cls, obj, body):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(HEADER.format(cls=cls, obj=obj) + body)


def make_case(case, n, re_t, width, fall, footprint, sampling, correction, courant, bandwidth=None,
              tau_fraction=1.0):
    mu = viscosity_for(re_t)
    u_t = terminal(mu)
    h = n * D
    tau = RHO_P * D * D / (18 * mu)
    fall_len = max(fall * D, 6 * h)
    # Release 2 cells below the lid; fall through the transient (10 tau) and fall_len in the
    # time u_t takes, with room below for a particle up to twice as fast (coarse cells
    # without correction), and 3 cells more.
    transient = 10 * tau * u_t
    height_cells = int(math.ceil((2 * h + 2 * (transient + fall_len) + 3 * h) / h))
    L, H = width * h, height_cells * h
    end = (transient + fall_len) / u_t
    dt_f = min(courant * h / u_t, tau_fraction * tau)
    steps = max(1, int(math.ceil(end / dt_f)))
    dt_f = end / steps
    dt_dem = dt_f / 5
    snap = dt_f * max(1, round(end / 200 / dt_f))
    os.makedirs(case, exist_ok=True)
    write(f"{case}/system/blockMeshDict", "dictionary", "blockMeshDict", f"""
scale 1;
vertices ( (0 0 0) ({L} 0 0) ({L} {L} 0) (0 {L} 0) (0 0 {H}) ({L} 0 {H}) ({L} {L} {H}) (0 {L} {H}) );
blocks ( hex (0 1 2 3 4 5 6 7) ({width} {width} {height_cells}) simpleGrading (1 1 1) );
boundary ( walls {{ type wall; faces ( (0 3 2 1) (4 5 6 7) (0 1 5 4) (2 3 7 6) (1 2 6 5) (3 0 4 7) ); }} );
""")
    write(f"{case}/system/controlDict", "dictionary", "controlDict", f"""
application grainFoam; startFrom startTime; startTime 0; stopAt endTime; endTime {end:.12g};
deltaT {dt_f:.12g}; writeControl timeStep; writeInterval {steps}; purgeWrite 0;
writeFormat ascii; writePrecision 10; writeCompression off; timeFormat general;
timePrecision 8; runTimeModifiable false; adjustTimeStep no;
""")
    write(f"{case}/system/fvSchemes", "dictionary", "fvSchemes", """
ddtSchemes { default Euler; } gradSchemes { default Gauss linear; }
divSchemes { default none; div(phi,U) Gauss limitedLinearV 1; div(((c*nu)*dev2(T(grad(U))))) Gauss linear; }
laplacianSchemes { default Gauss linear corrected; } interpolationSchemes { default linear; }
snGradSchemes { default corrected; }
""")
    write(f"{case}/system/fvSolution", "dictionary", "fvSolution", """
solvers { p { solver GAMG; smoother DIC; tolerance 1e-9; relTol 0.01; } pFinal { $p; relTol 0; }
"(U|UFinal)" { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-10; relTol 0; } }
PIMPLE { nOuterCorrectors 1; nCorrectors 2; nNonOrthogonalCorrectors 0; momentumPredictor yes;
pRefCell 0; pRefValue 0; }
""")
    write(f"{case}/0/U", "volVectorField", "U",
          "dimensions [0 1 -1 0 0 0 0]; internalField uniform (0 0 0);\n"
          "boundaryField { walls { type noSlip; } }\n")
    write(f"{case}/0/p", "volScalarField", "p",
          "dimensions [0 2 -2 0 0 0 0]; internalField uniform 0;\n"
          "boundaryField { walls { type zeroGradient; } }\n")
    write(f"{case}/constant/transportProperties", "dictionary", "transportProperties",
          f"rho {RHO_F}; nu {mu / RHO_F:.12g};\n")
    extra = "" if correction is None else f"undisturbedVelocity {correction};\n"
    if bandwidth:
        extra += f"diffusionBandwidth {bandwidth * D:.12g};\n"
    write(f"{case}/constant/couplingProperties", "dictionary", "couplingProperties",
          f'scene "particles.yaml"; voidFraction {footprint}; sampling {sampling};\n'
          f"minVoidFraction 0.3; ddtVoidFraction on;\n{extra}")
    # Off the cell centres and faces: a quarter cell from the box's centre line.
    x0 = L / 2 + 0.27 * h
    with open(f"{case}/particle.csv", "w") as f:
        f.write(f"x,y,z,radius\n{x0:.12g},{x0:.12g},{H - 2 * h:.12g},{D / 2}\n")
    with open(f"{case}/particles.yaml", "w") as f:
        f.write(f"""domain: {{min: [0, 0, 0], max: [{L:.12g}, {L:.12g}, {H:.12g}]}}
gravity: [0, 0, -9.81]
time: {{step: {dt_dem:.12g}, end: {end * 2:.12g}, expected_max_speed: {2 * u_t:.6g}}}
materials:
  - {{name: glass, youngs_modulus: 5e7, poisson_ratio: 0.25, density: {RHO_P}}}
insert:
  - {{type: csv, file: particle.csv, material: glass}}
output: {{snapshot_interval: {snap:.12g}}}
fluid:
  density: {RHO_F}
  viscosity: {mu:.12g}
  drag: schiller_naumann
  model: B
  pressure: {{hydrostatic: false}}
  forces: [drag, pressure_gradient, viscous, buoyancy]
""")
    return {"mu": mu, "u_t": u_t, "tau": tau, "end": end, "transient": transient, "h": h,
            "cells": width * width * height_cells}


def run(case, build):
    env = dict(os.environ, LD_LIBRARY_PATH=os.path.join(build, "lib"))
    for cmd, log in ((["blockMesh"], "log.blockMesh"),
                     ([os.path.join(build, "bin", "grainFoam")], "log.grainFoam")):
        with open(os.path.join(case, log), "w") as out:
            rc = subprocess.call([FOAM] + cmd, cwd=case, stdout=out, stderr=subprocess.STDOUT, env=env)
        if rc != 0:
            sys.exit(f"settling_cells: {cmd[0]} failed, see {case}/{log}")
    if not re.search(r"^End\s*$", open(os.path.join(case, "log.grainFoam")).read(), re.M):
        sys.exit(f"settling_cells: grainFoam did not reach its end time (a SIGTERM or SIGINT stops it with exit 0 after a checkpoint); "
                 f"see {case}/log.grainFoam")
    cpu, imbalance, fluid_z = 0.0, 0.0, float("nan")
    for line in open(os.path.join(case, "log.grainFoam")):
        if line.startswith("ExecutionTime"):
            cpu = float(line.split()[2])
        if "relative imbalance" in line:
            imbalance = max(imbalance, float(line.split()[-1]))
            fluid_z = float(line.split("fluid (")[1].split(")")[0].split()[2])
    return cpu, imbalance, fluid_z


def measure(case, info):
    t, z, w = [], [], []
    for f in sorted(glob.glob(os.path.join(case, "particles", "particles_*.h5"))):
        with h5py.File(f, "r") as h5:
            t.append(h5.attrs["time"])
            z.append(h5["position"][0][2])
            w.append(-h5["velocity"][0][2])
    t, z, w = np.array(t), np.array(z), np.array(w)
    # The particle's fluid force at the end (the last exchange): m a + the submerged weight,
    # a from the last two snapshots.
    mass = RHO_P * math.pi * D**3 / 6
    end_force = (RHO_P - RHO_F) * math.pi * D**3 / 6 * G - mass * (w[-1] - w[-2]) / (t[-1] - t[-2])
    start = info["transient"] / info["u_t"]
    late = t > start + 0.5 * (info["end"] - start)
    # The fall over the whole cells crossed in the window over its time (the times the centre
    # crosses the cell faces z = k h, interpolated between snapshots): the sawtooth of
    # crossing cells averages out, which the mean of the snapshots over a window holding a
    # fraction of a cell does not.
    tl, zl, h = t[late], z[late], info["h"]
    faces = np.arange(math.floor(zl[0] / h), math.ceil(zl[-1] / h) - 1, -1) * h
    whole = float("nan")
    if len(faces) > 1:
        tc = np.interp(-faces, -zl, tl)
        whole = (faces[0] - faces[-1]) / (tc[-1] - tc[0]) / info["u_t"] - 1
    return w[late].mean() / info["u_t"] - 1, w[late].std() / info["u_t"], whole, end_force


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--re", type=float, default=2.0)
    ap.add_argument("--cells", default="3,5,10")
    ap.add_argument("--correction", default=None)
    ap.add_argument("--footprint", default="divided")
    ap.add_argument("--sampling", default="cell")
    ap.add_argument("--width", type=int, default=16)
    ap.add_argument("--fall", type=float, default=40)
    ap.add_argument("--courant", type=float, default=0.05,
                    help="particle Courant number u_t dt / h of the fluid step (default 0.05)")
    ap.add_argument("--bandwidth", type=float, default=None,
                    help="diffusionBandwidth b in particle diameters (default: none)")
    ap.add_argument("--tau-fraction", type=float, default=1.0,
                    help="the fluid step at most this fraction of the particle's relaxation "
                         "time tau (default 1; at Re_t 0.1 tau, not --courant, sets the step)")
    ap.add_argument("--check", type=float, default=None,
                    help="exit 1 unless every |error| is within this many per cent")
    ap.add_argument("--check-force", type=float, default=None,
                    help="with --check: also exit 1 unless the fluid's share of the particle's "
                         "fluid force at the end is within this many per cent of 1")
    ap.add_argument("--work", default="/tmp/settling_cells")
    ap.add_argument("--build", default=os.environ.get("GRAINFLOW_BUILD_DIR", os.path.join(ROOT, "build")))
    a = ap.parse_args()
    if not 0 < a.tau_fraction <= 1:
        ap.error(f"--tau-fraction {a.tau_fraction:g}: must be in (0, 1]")
    if a.check_force is not None and (a.check is None or not a.check_force > 0):
        ap.error("--check-force PERCENT: needs --check and a positive PERCENT")
    rows = []
    for n in (float(x) for x in a.cells.split(",")):
        name = f"re{a.re:g}_n{n:g}_{a.footprint}_{a.sampling}_{a.correction or 'off'}_w{a.width}_c{a.courant:g}"
        if a.bandwidth:
            name += f"_b{a.bandwidth:g}"
        if a.tau_fraction != 1:
            name += f"_t{a.tau_fraction:g}"
        case = os.path.join(a.work, name)
        subprocess.call(["rm", "-rf", case])
        info = make_case(case, n, a.re, a.width, a.fall, a.footprint, a.sampling, a.correction, a.courant,
                         a.bandwidth, a.tau_fraction)
        cpu, imbalance, fluid_z = run(case, a.build)
        err, wobble, whole, end_force = measure(case, info)
        # The fluid's share of the particle's fluid force at the end: 1 when the fluid gets
        # exactly the drag (and the returned forces) the particle feels.
        share = -fluid_z / end_force
        row = dict(re=a.re, cells_per_d=n, footprint=a.footprint, sampling=a.sampling,
                   correction=a.correction or "off", bandwidth_d=a.bandwidth or 0, mu=info["mu"], u_t=info["u_t"],
                   error_pct=100 * err, wobble_pct=100 * wobble, whole_cells_error_pct=100 * whole,
                   cpu_s=cpu, mesh_cells=info["cells"], imbalance=imbalance,
                   fluid_share=share)
        rows.append(row)
        print(f"settling_cells: Re_t {a.re:g}, cells {n:g} d, {a.footprint}/{a.sampling}, "
              f"correction {row['correction']}"
              f"{f', diffusionBandwidth {a.bandwidth:g} d' if a.bandwidth else ''}: error {100 * err:+.2f} % (wobble {100 * wobble:.2f} %; "
              f"over whole cells {100 * whole:+.2f} %), "
              f"{info['cells']} cells, {cpu:.0f} s, exchange imbalance {imbalance:.1e}, the fluid gets "
              f"{share:.4f} of the particle's fluid force", flush=True)
    out = os.path.join(a.work, "settling_cells.csv")
    new = not os.path.exists(out)
    with open(out, "a", newline="") as f:
        wr = csv.DictWriter(f, fieldnames=list(rows[0]))
        if new:
            wr.writeheader()
        wr.writerows(rows)
    if a.check is not None:
        force = a.check_force
        bad = [r for r in rows if abs(r["error_pct"]) > a.check or r["imbalance"] > 1e-12
               or (force is not None and not abs(r["fluid_share"] - 1) <= force / 100)]
        print(f"settling_cells: {len(rows) - len(bad)} of {len(rows)} within {a.check:g} % "
              f"with the exchange balanced to 1e-12"
              f"{f' and the fluid given its share within {force:g} %' if force is not None else ''}: "
              f"{'ok' if not bad else 'FAILED'}")
        sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
