#!/usr/bin/env python3
"""Two equal spheres settling side by side in a quiescent liquid, in Stokes flow, coarse cells:
the pair falls faster than one sphere alone, by the velocity each one's force induces at the
other.

Unbounded reference (Happel & Brenner 1965, Low Reynolds number hydrodynamics, sec. 6.3,
method of reflections; the exact bipolar solution: Goldman, Cox & Brenner 1966, Chem. Eng.
Sci. 21:1151): each sphere of a pair at centre distance l, moving perpendicular to the line of
centres, has the drag 6 pi mu a U lambda, lambda = 1 - (3/4) k + (9/16) k^2 - (59/64) k^3 +
O(k^4), k = a / l; under the same weight U_pair / U_single = 1 / lambda = 1 + (3/4) k +
(1/2) k^3 + O(k^4) (the (3/4) k is the other sphere's Stokeslet F / (8 pi mu l), the k^3 its
Faxen term).

Two boxes (--box):
  walls     closed on all six faces, --width cells wide, as tall as settling_cells.py makes it
            (the sphere falls --fall diameters after its transient); the spheres' downward
            flux returns upward across every horizontal section, so the box takes off a large
            part of the Stokeslet at l (no closed-form reference: the ratio is compared with
            the unbounded 1 / lambda).
  periodic  periodic along x, y and z (mesh cyclic on all faces), --width cells along x and y,
            --height along z, the buoyant weight carried by meanPressureGradient
            suspensionWeight. Reference: the periodic Stokeslet of Hasimoto (1959, J. Fluid
            Mech. 5:317) with zero mean velocity, summed here by Hasimoto's Ewald split
                8 pi mu G(x) = sum_n [erfc(xi r)(I + rr/r^2)/r - (2 xi/sqrt(pi)) exp(-xi^2 r^2)
                                      (I - rr/r^2)]_{r = x + n L}
                             + (8 pi / V) sum_{k != 0} (I - kk/k^2)(1 + k^2/4xi^2)
                                      exp(-k^2/4xi^2) cos(k.x) / k^2,
            checked at start-up to be independent of xi and to give Hasimoto's self-mobility
            constant 2.837297 (U = U_0 (1 - 2.837297 a/L) in a cube). A sphere of net force F
            (its buoyant weight less V_p G) settles relative to the fluid's mean at
                U_single = U_t + F S_zz,  S = lim_{x->0} (G - G_free)    (its periodic images)
                U_pair   = U_single + F G_zz(l e_x)                      (the other sphere)
            with U_t the drag law's terminal velocity for F (Schiller-Naumann here; the drag
            law reads the fluid velocity the others induce, to first order in a/L and a/l).
            The measured speed is the distance the sphere falls over a whole number of cells
            (--cells-fallen) after the start-up transient, divided by the time, plus the
            fluid's mean velocity over that time (from the momentum grainFoam logs).

The spheres are those of settling_cells.py (d = 2 mm, rho_p = 2500, rho_f = 1000, viscosity
for the terminal Reynolds number Re_t, Schiller-Naumann, model B, divided footprint, cell
sampling). Walls: the pair sits at +-l/2 along x about the single sphere's place (each at the
same place in its cell when l/2 is a whole number of cells). Periodic: the single sphere sits
where the pair's first one does.

Usage: settling_pair.py [--box walls|periodic] [--re 0.05] [--cells 3] [--spacing 6]
                        [--width 12] [--height H] [--fall 15] [--cells-fallen 2]
                        [--correction oseenBrinkman|off] [--check POINTS] [--work DIR]
                        [--build DIR]
With --check, exit 1 unless the pair falls faster than the single sphere, |U_pair/U_single -
reference| <= POINTS / 100 (periodic: Hasimoto's; walls: 1 / lambda), and every run's
exchange is balanced to 1e-12.
"""
import argparse
import glob
import math
import os
import re
import subprocess
import sys

import h5py
import numpy as np
from scipy.special import erfc

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import settling_cells as sc  # noqa: E402


# ---- Hasimoto's periodic Stokeslet (8 pi mu G_zz), the reference of the periodic box ----

def _real_zz(x, xi):
    r = np.linalg.norm(x, axis=1)
    zz = x[:, 2] ** 2 / r**2
    return (erfc(xi * r) * (1 + zz) / r
            - 2 * xi / math.sqrt(math.pi) * np.exp(-((xi * r) ** 2)) * (1 - zz))


def periodic_zz(x, box, xi=None, nr=3, nk=12, self_term=False):
    """8 pi mu G_zz of the zero-mean periodic Stokeslet at the displacement x in the box
    (Lx, Ly, Lz); with self_term, the limit x -> 0 of the periodic minus the free Stokeslet."""
    box, x = np.asarray(box, float), np.asarray(x, float)
    vol = box.prod()
    xi = math.sqrt(math.pi) / vol ** (1 / 3) if xi is None else xi
    n = np.arange(-nr, nr + 1)
    cells = np.stack(np.meshgrid(n, n, n, indexing="ij"), -1).reshape(-1, 3)
    disp = x + cells * box
    if self_term:
        real = _real_zz(disp[np.any(cells != 0, axis=1)], xi).sum() - 4 * xi / math.sqrt(math.pi)
    else:
        real = _real_zz(disp, xi).sum()
    m = np.arange(-nk, nk + 1)
    waves = np.stack(np.meshgrid(m, m, m, indexing="ij"), -1).reshape(-1, 3)
    k = 2 * math.pi * waves[np.any(waves != 0, axis=1)] / box
    k2 = (k**2).sum(1)
    s = k2 / (4 * xi**2)
    four = ((1 - k[:, 2] ** 2 / k2) * (1 + s) * np.exp(-s) / k2 * np.cos(k @ x)).sum()
    return real + 8 * math.pi * four / vol


def check_ewald():
    """The sum does not depend on the splitting xi and gives Hasimoto's cube constant."""
    c = [0.75 * periodic_zz([0, 0, 0], [1, 1, 1], xi=xi, self_term=True) for xi in (2, 3.5, 5)]
    g = [periodic_zz([0.2, 0.1, 0.3], [1, 1.3, 0.8], xi=xi) for xi in (2, 3.5, 5)]
    if max(abs(v + 2.837297) for v in c) > 1e-6 or max(g) - min(g) > 1e-9 * abs(g[0]):
        sys.exit(f"settling_pair: Ewald sum check failed: {c}, {g}")


# ---- cases ----

# The DEM step is the fluid step's fifth, 8 Rayleigh times: far too long to resolve a contact,
# which grainFoam refuses at start-up. The pair settles side by side, l > d apart, and never
# touches (were it to, the run-time guards would stop the run at that contact): start anyway.
PAIR_STEP = "allowLargeTimeStep yes;\n"


def make_periodic_case(case, a):
    """One or two spheres in a box periodic along x, y, z; returns the case's numbers."""
    mu = sc.viscosity_for(a.re)
    u_t = sc.terminal(mu)
    nu = mu / sc.RHO_F
    h = a.cells * sc.D
    nx, nz = a.width, a.height or a.width
    L, H = nx * h, nz * h
    tau = sc.RHO_P * sc.D**2 / (18 * mu)
    # Start-up: the particle's own relaxation and 4 e-folds of the box's slowest mode
    # exp(-nu (2 pi / L)^2 t); then the fall over --cells-fallen cells, with 25 % room.
    transient = 10 * tau + 4 * max(L, H) ** 2 / (4 * math.pi**2 * nu)
    end = transient + 1.25 * a.cells_fallen * h / u_t
    dt_f = min(a.courant * h / u_t, tau)
    steps = max(1, int(math.ceil(end / dt_f)))
    dt_f = end / steps
    write_every = max(1, steps // 200)
    os.makedirs(case, exist_ok=True)
    pair = lambda name, other, faces: (f"{name} {{ type cyclic; neighbourPatch {other}; "
                                       f"faces ( {faces} ); }}")
    sc.write(f"{case}/system/blockMeshDict", "dictionary", "blockMeshDict", f"""
scale 1;
vertices ( (0 0 0) ({L} 0 0) ({L} {L} 0) (0 {L} 0) (0 0 {H}) ({L} 0 {H}) ({L} {L} {H}) (0 {L} {H}) );
blocks ( hex (0 1 2 3 4 5 6 7) ({nx} {nx} {nz}) simpleGrading (1 1 1) );
boundary (
  {pair('x0', 'x1', '(0 4 7 3)')} {pair('x1', 'x0', '(1 2 6 5)')}
  {pair('y0', 'y1', '(0 1 5 4)')} {pair('y1', 'y0', '(3 7 6 2)')}
  {pair('z0', 'z1', '(0 3 2 1)')} {pair('z1', 'z0', '(4 5 6 7)')}
);
""")
    sc.write(f"{case}/system/controlDict", "dictionary", "controlDict", f"""
application grainFoam; startFrom startTime; startTime 0; stopAt endTime; endTime {end:.12g};
deltaT {dt_f:.12g}; writeControl timeStep; writeInterval {write_every}; purgeWrite 2;
writeFormat binary; writePrecision 12; writeCompression off; timeFormat general;
timePrecision 8; runTimeModifiable false; adjustTimeStep no;
""")
    sc.write(f"{case}/system/fvSchemes", "dictionary", "fvSchemes", """
ddtSchemes { default Euler; } gradSchemes { default Gauss linear; }
divSchemes { default none; div(phi,U) Gauss limitedLinearV 1; div(((c*nu)*dev2(T(grad(U))))) Gauss linear; }
laplacianSchemes { default Gauss linear corrected; } interpolationSchemes { default linear; }
snGradSchemes { default corrected; }
""")
    sc.write(f"{case}/system/fvSolution", "dictionary", "fvSolution", """
solvers { p { solver GAMG; smoother DIC; tolerance 1e-10; relTol 0.01; } pFinal { $p; relTol 0; }
"(U|UFinal)" { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-12; relTol 0; } }
PIMPLE { nOuterCorrectors 1; nCorrectors 2; nNonOrthogonalCorrectors 0; momentumPredictor yes;
pRefCell 0; pRefValue 0; }
""")
    sc.write(f"{case}/0/U", "volVectorField", "U",
             "dimensions [0 1 -1 0 0 0 0]; internalField uniform (0 0 0);\n"
             "boundaryField { \".*\" { type cyclic; } }\n")
    sc.write(f"{case}/0/p", "volScalarField", "p",
             "dimensions [0 2 -2 0 0 0 0]; internalField uniform 0;\n"
             "boundaryField { \".*\" { type cyclic; } }\n")
    sc.write(f"{case}/constant/transportProperties", "dictionary", "transportProperties",
             f"rho {sc.RHO_F}; nu {nu:.12g};\n")
    extra = "" if a.correction == "off" else f"undisturbedVelocity {a.correction};\n"
    if a.bandwidth:
        extra += f"diffusionBandwidth {a.bandwidth * sc.D:.12g};\n"
    if a.n == 2:
        extra += PAIR_STEP
    sc.write(f"{case}/constant/couplingProperties", "dictionary", "couplingProperties",
             'scene "particles.yaml"; voidFraction divided; sampling cell;\n'
             f"minVoidFraction 0.3; ddtVoidFraction on; meanPressureGradient suspensionWeight;\n"
             f"{extra}")
    # as settling_cells.py: off the cell centres and faces, a quarter cell from the centre line
    x0, z0 = L / 2 + 0.27 * h, H - 0.5 * h
    # the single sphere where the pair's first one is (the same place in its cell)
    xs = [x0 - 0.5 * a.spacing * sc.D, x0 + 0.5 * a.spacing * sc.D][:a.n]
    with open(f"{case}/particle.csv", "w") as f:
        f.write("x,y,z,radius\n")
        for x in xs:
            f.write(f"{x:.12g},{x0:.12g},{z0:.12g},{sc.D / 2}\n")
    contact = ("contact: {normal: hertz}\ninteraction_defaults: {restitution: 0.5, friction: 0.5}\n"
               if a.n == 2 else "")
    with open(f"{case}/particles.yaml", "w") as f:
        f.write(f"""domain: {{min: [0, 0, 0], max: [{L:.12g}, {L:.12g}, {H:.12g}], periodic: [true, true, true]}}
gravity: [0, 0, -9.81]
time: {{step: {dt_f / 5:.12g}, end: {2 * end:.12g}, expected_max_speed: {2 * u_t:.6g}}}
materials:
  - {{name: glass, youngs_modulus: 5e7, poisson_ratio: 0.25, density: {sc.RHO_P}}}
{contact}insert:
  - {{type: csv, file: particle.csv, material: glass}}
output: {{snapshot_interval: {write_every * dt_f:.12g}, fields: [position, velocity, radius]}}
fluid:
  density: {sc.RHO_F}
  viscosity: {mu:.12g}
  drag: schiller_naumann
  model: B
  pressure: {{hydrostatic: false}}
  forces: [drag, pressure_gradient, viscous, buoyancy]
""")
    return {"mu": mu, "u_t": u_t, "tau": tau, "end": end, "transient": transient, "h": h,
            "box": (L, L, H), "cells": nx * nx * nz, "cells_fallen": a.cells_fallen}


def periodic_speed(case, info, n):
    """The settling speed relative to the fluid's mean: the fall over whole cells after the
    transient, over its time, plus the fluid's mean upward velocity over that time."""
    L, _, H = info["box"]
    t, z, w = [], [], []
    for f in sorted(glob.glob(os.path.join(case, "particles", "particles_*.h5"))):
        with h5py.File(f, "r") as h5:
            if len(h5["position"]) != n:
                sys.exit(f"settling_pair: {f} holds {len(h5['position'])} particles, expected {n}")
            t.append(float(h5.attrs["time"]))
            z.append(h5["position"][()][:, 2].mean())
            w.append(-h5["velocity"][()][:, 2].mean())
    order = np.argsort(t)
    t, z, w = np.array(t)[order], np.array(z)[order], np.array(w)[order]
    z = np.unwrap(z * 2 * math.pi / H) * H / (2 * math.pi)  # through the periodic z faces
    fallen = z[0] - z
    t0 = info["transient"]
    f0 = np.interp(t0, t, fallen)
    target = f0 + info["cells_fallen"] * info["h"]
    if fallen[-1] < target:
        sys.exit(f"settling_pair: {case}: fell {(fallen[-1] - f0) / info['h']:.2f} cells after "
                 f"the transient, fewer than {info['cells_fallen']}")
    t1 = np.interp(target, fallen, t)
    # the fluid's mean velocity (z) from the logged momentum rho sum eps U V
    num = r"([-+0-9.eE]+)"
    mom = re.compile(r"momentum: fluid \(" + r" ".join([num] * 3) + r"\)")
    tl, uf, tt = [], [], None
    for line in open(os.path.join(case, "log.grainFoam")):
        if line.startswith("Time = "):
            tt = float(line.split()[2])
        elif (m := mom.search(line)) and tt is not None:
            tl.append(tt)
            uf.append(float(m.group(3)))
    vol = L * L * H - n * math.pi * sc.D**3 / 6
    tl, uf = np.array(tl), np.array(uf) / (sc.RHO_F * vol)
    window = (tl >= t0) & (tl <= t1)
    fluid_up = uf[window].mean() if window.any() else 0.0
    late = (t >= t0) & (t <= t1)
    return {"speed": (target - f0) / (t1 - t0) + fluid_up, "fluid_up": fluid_up,
            "wobble": w[late].std(), "window": (t0, t1)}


def walls_speed(case, info, n):
    t, w = [], []
    for f in sorted(glob.glob(os.path.join(case, "particles", "particles_*.h5"))):
        with h5py.File(f, "r") as h5:
            v = h5["velocity"][:]
            if len(v) != n:
                sys.exit(f"settling_pair: {f} holds {len(v)} particles, expected {n}")
            t.append(h5.attrs["time"])
            w.append(-v[:, 2].mean())
    t, w = np.array(t), np.array(w)
    start = info["transient"] / info["u_t"]
    late = t > start + 0.5 * (info["end"] - start)
    return {"speed": w[late].mean(), "fluid_up": 0.0, "wobble": w[late].std()}


def make_walls_case(case, a):
    correction = None if a.correction == "off" else a.correction
    info = sc.make_case(case, a.cells, a.re, a.width, a.fall, "divided", "cell", correction,
                        a.courant, a.bandwidth or None)
    # settling_cells puts the single sphere a quarter cell off the box's centre line; the
    # pair sits at +-l/2 about that point along x.
    with open(os.path.join(case, "particle.csv")) as f:
        _, row = f.read().split("\n")[:2]
    x0, y0, z0, r = (float(v) for v in row.split(","))
    xs = [x0] if a.n == 1 else [x0 - 0.5 * a.spacing * sc.D, x0 + 0.5 * a.spacing * sc.D]
    with open(os.path.join(case, "particle.csv"), "w") as f:
        f.write("x,y,z,radius\n")
        for x in xs:
            f.write(f"{x:.12g},{y0:.12g},{z0:.12g},{r}\n")
    if a.n == 2:  # two particles need contact properties (they never touch: l > d)
        with open(os.path.join(case, "particles.yaml"), "a") as f:
            f.write("contact: {normal: hertz}\n"
                    "interaction_defaults: {restitution: 0.5, friction: 0.5}\n")
        with open(os.path.join(case, "constant", "couplingProperties"), "a") as f:
            f.write(PAIR_STEP)
    return info


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--box", choices=("walls", "periodic"), default="periodic")
    ap.add_argument("--re", type=float, default=0.05)
    ap.add_argument("--cells", type=float, default=3.0, help="cell size in diameters")
    ap.add_argument("--spacing", type=float, default=6.0, help="centre distance l in diameters")
    ap.add_argument("--width", type=int, default=12, help="cells along x and y")
    ap.add_argument("--height", type=int, default=None, help="periodic: cells along z (--width)")
    ap.add_argument("--fall", type=float, default=15, help="walls: fall in diameters")
    ap.add_argument("--cells-fallen", type=int, default=2,
                    help="periodic: the speed is measured over this many cells of fall")
    ap.add_argument("--courant", type=float, default=0.05)
    ap.add_argument("--correction", default="oseenBrinkman")
    ap.add_argument("--bandwidth", type=float, default=0.0,
                    help="diffusionBandwidth b in particle diameters (default: none)")
    ap.add_argument("--check", type=float, default=None)
    ap.add_argument("--work", default="/tmp/settling_pair")
    ap.add_argument("--build", default=os.environ.get("GRAINFLOW_BUILD_DIR", os.path.join(sc.ROOT, "build")))
    a = ap.parse_args()
    k = 0.5 / a.spacing
    unbounded = 1 / (1 - 0.75 * k + 9 / 16 * k**2 - 59 / 64 * k**3)
    if a.box == "periodic":
        check_ewald()
    runs, worst = {}, 0.0
    for n in (1, 2):
        a.n = n
        tag = f"{a.box}_re{a.re:g}_n{a.cells:g}_l{a.spacing:g}_w{a.width}_{a.correction}_b{a.bandwidth:g}_{n}"
        case = os.path.join(a.work, tag)
        subprocess.call(["rm", "-rf", case])
        if a.box == "periodic":
            info = make_periodic_case(case, a)
        else:
            info = make_walls_case(case, a)
        cpu, imbalance, _ = sc.run(case, a.build)
        worst = max(worst, imbalance)
        runs[n] = (periodic_speed if a.box == "periodic" else walls_speed)(case, info, n)
        print(f"settling_pair: {a.box}, {n} sphere(s), Re_t {a.re:g}, cells {a.cells:g} d, "
              f"box {a.width} cells, correction {a.correction}: settling speed "
              f"{runs[n]['speed'] / info['u_t']:.4f} u_t (fluid mean "
              f"{runs[n]['fluid_up'] / info['u_t']:+.1e} u_t, wobble "
              f"{runs[n]['wobble'] / info['u_t']:.1e} u_t), {cpu:.0f} s CPU, "
              f"exchange imbalance {imbalance:.1e}", flush=True)
    ratio = runs[2]["speed"] / runs[1]["speed"]
    u_t = info["u_t"]
    if a.box == "periodic":
        L, _, H = info["box"]
        vol = L * L * H
        vp = math.pi * sc.D**3 / 6
        weight = (sc.RHO_P - sc.RHO_F) * 9.81 * vp
        a_r = sc.D / 2
        mu = info["mu"]
        # net force on each sphere (buoyant weight less V_p G) and its drag-law speed
        f1, f2 = weight * (1 - vp / vol), weight * (1 - 2 * vp / vol)
        ut1 = terminal_for(f1, mu)
        ut2 = terminal_for(f2, mu)
        s_zz = periodic_zz([0, 0, 0], info["box"], self_term=True) / (8 * math.pi * mu)
        g_zz = periodic_zz([a.spacing * sc.D, 0, 0], info["box"]) / (8 * math.pi * mu)
        ref1 = ut1 + f1 * s_zz
        ref2 = ut2 + f2 * s_zz + f2 * g_zz
        expected = ref2 / ref1
        dmeas, dref = runs[2]["speed"] - runs[1]["speed"], ref2 - ref1
        print(f"settling_pair: Hasimoto periodic reference: single {ref1 / u_t:.4f} u_t "
              f"(measured {runs[1]['speed'] / u_t:.4f}), pair {ref2 / u_t:.4f} u_t (measured "
              f"{runs[2]['speed'] / u_t:.4f}); the pair's gain {dref / u_t:.4f} u_t, measured "
              f"{dmeas / u_t:.4f} u_t ({dmeas / dref:.3f} of it); unbounded gain "
              f"{(unbounded - 1):.4f} (Happel & Brenner), a_r/L = {a_r / L:.4f}")
        name = "Hasimoto (periodic)"
    else:
        expected = unbounded
        name = "Happel & Brenner 1 / lambda (unbounded)"
    print(f"settling_pair: l = {a.spacing:g} d: U_pair / U_single = {ratio:.4f}, {name} = "
          f"{expected:.4f} (difference {100 * (ratio - expected):+.2f} points); unbounded "
          f"1 / lambda = {unbounded:.4f}")
    if a.check is not None:
        ok = abs(ratio - expected) <= a.check / 100 and ratio > 1 and worst <= 1e-12
        print(f"settling_pair: within {a.check:g} points of {name}, faster than one sphere, "
              f"exchange balanced to 1e-12: {'ok' if ok else 'FAILED'}")
        sys.exit(0 if ok else 1)


def terminal_for(force, mu):
    """Schiller-Naumann's speed at which the drag equals force."""
    lo, hi = 1e-12, 100.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if sc.sn_drag(mid, mu) > force else (mid, hi)
    return 0.5 * (lo + hi)


if __name__ == "__main__":
    main()
