#!/usr/bin/env python3
"""Hindered settling: a homogeneous suspension in a fully periodic box (x, y, z periodic, the
fluid mesh cyclic on all faces), the mean pressure gradient carrying the suspension's buoyant
weight (couplingProperties meanPressureGradient suspensionWeight). The mean slip velocity,
fluid phase average minus particle average, against

  1. the drag law's own slip for a uniform suspension at the box's void fraction eps: with
     F_drag excluding the pressure-gradient force (dem/fluid/drag_input.hpp), a particle of
     a homogeneous suspension at rest on average feels m g - rho_f V_p g - V_p G + F_drag = 0
     and G = (1 - eps) (rho_p - rho_f) g (the mixture's balance), so
         F_drag(eps, slip) = eps (rho_p - rho_f) g V_p,
     solved here by bisection with the drag law written out from its paper (not the C++);
  2. Richardson & Zaki (1954): the settling speed relative to zero volume flux is
     eps * slip = u_t eps^n, so slip = u_t eps^(n - 1); n from Richardson & Zaki's own
     correlation for an unbounded suspension (d/D = 0): 4.65 below Re_t = 0.2,
     4.35 Re_t^-0.03 up to 1, 4.45 Re_t^-0.1 up to 500, 2.39 beyond; u_t the single
     sphere's terminal velocity from Schiller & Naumann (1933).

Particles: spheres of d = 2 mm, rho_p = 2500 kg/m^3 in a liquid of rho_f = 1000 kg/m^3 with the
viscosity that gives Re_t (default 0.1: the Stokes regime, n = 4.65), elastic (e = 0.9) and
nearly frictionless (mu = 0.05). `--arrangement random` (default): a box of `--cells` cubic
cells of `--h` diameters per side, the particle count set by eps, positions at random without
overlap (Poisson points pushed apart, periodic; `--seed`); `crystal`: a simple cubic lattice of
8 particles per cell, every cell alike (a uniform suspension; the box sized by eps);
`lattice`: a jittered simple cubic lattice. The fluid and the particles start at rest; the
slip is averaged over the log's write times after `--skip` of the run. The results and what
they show: docs/models/undisturbed-velocity.md, "hindered settling".

Usage: hindered_settling.py [--eps 0.6,0.7,0.8,0.9] [--arrangement random] [--cells 4] [--h 3]
                            [--re 0.1] [--drag di_felice] [--model B] [--footprint divided]
                            [--correction oseenBrinkman] [--bandwidth 0] [--end 0.1]
                            [--skip 0.04] [--ranks 1] [--seed 11] [--series]
                            [--check PCT_DRAG,PCT_RZ[,PCT_FORCE]]
                            [--work DIR] [--build DIR]
Prints one line per eps and appends to <work>/hindered_settling.csv; with --check, exit 1
unless every slip is within PCT_DRAG % of the drag law and PCT_RZ % of Richardson-Zaki, the
exchange is balanced (1e-12) and the mixture's momentum stays within 1 % of the particles'
(with PCT_FORCE: its mean net force within PCT_FORCE % of the particles' buoyant weight).
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
from scipy.spatial import cKDTree

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
FOAM = os.path.join(ROOT, "scripts", "foam_env.sh")
D, RHO_P, RHO_F, G = 2e-3, 2500.0, 1000.0, 9.81
VP = math.pi * D**3 / 6


# --- single sphere ---------------------------------------------------------------------
def sn_drag(u, mu):
    """Schiller & Naumann (1933): F = 3 pi mu d u (1 + 0.15 Re^0.687)."""
    re = RHO_F * u * D / mu
    return 3 * math.pi * mu * D * u * (1 + 0.15 * re**0.687)


def bisect(f, lo, hi):
    """The root of an increasing f in (lo, hi)."""
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if f(mid) > 0 else (mid, hi)
    return 0.5 * (lo + hi)


def terminal(mu):
    return bisect(lambda u: sn_drag(u, mu) - (RHO_P - RHO_F) * G * VP, 1e-12, 100.0)


def viscosity_for(re_t):
    # the terminal Reynolds number falls as mu grows
    return math.exp(bisect(lambda lm: re_t - RHO_F * terminal(math.exp(lm)) * D / math.exp(lm),
                           math.log(1e-5), math.log(100.0)))


# --- suspension drag laws, from their papers (F_drag: pressure-gradient force apart) ---------
def di_felice(eps, s, mu):
    """Di Felice (1994), Int. J. Multiphase Flow 20:153, eqs. 3, 9, 13 with Dallavalle's C_D:
    F = C_D rho (pi d^2/4) (eps s)^2 / 2 * eps^-chi, Re = rho eps s d / mu,
    C_D = (0.63 + 4.8 / sqrt(Re))^2, chi = 3.7 - 0.65 exp(-(1.5 - log10 Re)^2 / 2)."""
    re = RHO_F * eps * s * D / mu
    cd = (0.63 + 4.8 / math.sqrt(re)) ** 2
    chi = 3.7 - 0.65 * math.exp(-0.5 * (1.5 - math.log10(re)) ** 2)
    return 0.5 * cd * RHO_F * math.pi * D * D / 4 * (eps * s) ** 2 * eps**-chi


def wen_yu(eps, s, mu):
    """Wen & Yu (1966) as in Gidaspow (1994): beta = 3/4 C_D eps phi rho s eps^-2.65 / d,
    C_D = 24/Re (1 + 0.15 Re^0.687), Re = rho eps s d / mu; F_drag = beta V_p / phi."""
    re = RHO_F * eps * s * D / mu
    cd = 24 / re * (1 + 0.15 * re**0.687) if re < 1000 else 0.44
    return 0.75 * cd * eps * RHO_F * s * eps**-2.65 / D * VP * s


LAWS = {"di_felice": di_felice, "wen_yu": wen_yu}


def drag_slip(law, eps, mu):
    """The slip at which the law's F_drag carries eps (rho_p - rho_f) g V_p."""
    return bisect(lambda s: LAWS[law](eps, s, mu) - eps * (RHO_P - RHO_F) * G * VP, 1e-12, 100.0)


def rz_exponent(re_t):
    """Richardson & Zaki (1954), Trans. Instn Chem. Engrs 32:35, for d/D -> 0."""
    if re_t < 0.2:
        return 4.65
    if re_t < 1:
        return 4.35 * re_t**-0.03
    if re_t < 500:
        return 4.45 * re_t**-0.1
    return 2.39


# --- the case ----------------------------------------------------------------------------
HEADER = "FoamFile {{ version 2.0; format ascii; class {cls}; object {obj}; }}\n"


def write(path, cls, obj, body):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(HEADER.format(cls=cls, obj=obj) + body)


def random_suspension(n, L, seed):
    """n spheres of diameter D at random in a periodic cube of side L, without overlap:
    Poisson points, then overlapping pairs pushed apart along their line until none is left
    closer than 1.02 D (a few dozen sweeps at eps = 0.6)."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(0, L, size=(n, 3))
    gap = 1.02 * D
    for _ in range(5000):
        tree = cKDTree(x, boxsize=L)
        pairs = tree.query_pairs(gap, output_type="ndarray")
        if len(pairs) == 0:
            return x
        i, j = pairs[:, 0], pairs[:, 1]
        d = x[j] - x[i]
        d -= L * np.round(d / L)
        r = np.linalg.norm(d, axis=1)
        push = (0.5 * (gap - r) + 1e-3 * D)[:, None] * d / np.maximum(r, 1e-12)[:, None]
        move = np.zeros_like(x)
        np.add.at(move, i, -push)
        np.add.at(move, j, push)
        x = np.mod(x + move, L)
    sys.exit(f"hindered_settling: could not place {n} spheres without overlap")


def jittered_lattice(m, L, seed):
    """m^3 spheres on a simple cubic lattice of spacing a = L/m, each displaced at random by
    up to (a - 1.02 D)/2 along each axis: no overlap, and every region of the box holds the
    same number of particles up to one layer (count fluctuations far below Poisson's)."""
    rng = np.random.default_rng(seed)
    a = L / m
    room = 0.5 * (a - 1.02 * D)
    if room < 0:
        sys.exit(f"hindered_settling: a lattice of {m}^3 spheres does not fit a box of {L} m")
    g = (np.arange(m) + 0.5) * a
    x = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
    return np.mod(x + rng.uniform(-room, room, size=x.shape), L)


def make_case(case, eps, a, mu):
    n_cells = a.cells
    if a.arrangement == "crystal":
        # 2 particles per cell along each axis, at the same places in every cell: every cell
        # holds the same volume, eps is eps-bar everywhere and the flow is uniform.
        m = 2 * n_cells
        n = m**3
        L = (n * VP / (1 - eps)) ** (1 / 3)
        g = (np.arange(m) + 0.5) * L / m
        x = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
    elif a.arrangement == "lattice":
        # m^3 particles, m the lattice size nearest the box of `cells` cells of h d at eps;
        # the box is then sized to give eps exactly (cells of about h d).
        m = int(round(((1 - eps) * (n_cells * a.h * D) ** 3 / VP) ** (1 / 3)))
        n = m**3
        L = (n * VP / (1 - eps)) ** (1 / 3)
        x = jittered_lattice(m, L, seed=a.seed)
    else:
        L = n_cells * a.h * D
        n = int(round((1 - eps) * L**3 / VP))
        x = random_suspension(n, L, seed=a.seed)
    h = L / n_cells
    eps_box = 1 - n * VP / L**3
    dt_f = a.dt
    steps = int(round(a.end / dt_f))
    write_every = max(1, int(round(a.write / dt_f)))
    os.makedirs(case, exist_ok=True)
    pair = lambda name, other, faces: (f"{name} {{ type cyclic; neighbourPatch {other}; "
                                       f"faces ( {faces} ); }}")
    write(f"{case}/system/blockMeshDict", "dictionary", "blockMeshDict", f"""
scale 1;
vertices ( (0 0 0) ({L} 0 0) ({L} {L} 0) (0 {L} 0) (0 0 {L}) ({L} 0 {L}) ({L} {L} {L}) (0 {L} {L}) );
blocks ( hex (0 1 2 3 4 5 6 7) ({n_cells} {n_cells} {n_cells}) simpleGrading (1 1 1) );
boundary (
  {pair('x0', 'x1', '(0 4 7 3)')} {pair('x1', 'x0', '(1 2 6 5)')}
  {pair('y0', 'y1', '(0 1 5 4)')} {pair('y1', 'y0', '(3 7 6 2)')}
  {pair('z0', 'z1', '(0 3 2 1)')} {pair('z1', 'z0', '(4 5 6 7)')}
);
""")
    write(f"{case}/system/controlDict", "dictionary", "controlDict", f"""
application grainFoam; startFrom startTime; startTime 0; stopAt endTime; endTime {steps * dt_f:.12g};
deltaT {dt_f:.12g}; writeControl timeStep; writeInterval {write_every}; purgeWrite 2;
writeFormat {"ascii" if a.skew else "binary"}; writePrecision 17; writeCompression off; timeFormat general;
timePrecision 8; runTimeModifiable false; adjustTimeStep no;
""")
    write(f"{case}/system/fvSchemes", "dictionary", "fvSchemes", """
ddtSchemes { default Euler; } gradSchemes { default Gauss linear; }
divSchemes { default none; div(phi,U) Gauss limitedLinearV 1; div(((c*nu)*dev2(T(grad(U))))) Gauss linear; }
laplacianSchemes { default Gauss linear corrected; } interpolationSchemes { default linear; }
snGradSchemes { default corrected; }
""")
    write(f"{case}/system/fvSolution", "dictionary", "fvSolution", """
solvers { p { solver GAMG; smoother DIC; tolerance 1e-10; relTol 0.01; } pFinal { $p; relTol 0; }
"(U|UFinal)" { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-12; relTol 0; } }
PIMPLE { nOuterCorrectors 1; nCorrectors 2; nNonOrthogonalCorrectors 0; momentumPredictor yes;
pRefCell 0; pRefValue 0; }
""")
    write(f"{case}/system/decomposeParDict", "dictionary", "decomposeParDict",
          f"numberOfSubdomains {a.ranks}; method simple; coeffs {{ n ({a.ranks} 1 1); }}\n")
    write(f"{case}/0/U", "volVectorField", "U",
          "dimensions [0 1 -1 0 0 0 0]; internalField uniform (0 0 0);\n"
          "boundaryField { \".*\" { type cyclic; } }\n")
    write(f"{case}/0/p", "volScalarField", "p",
          "dimensions [0 2 -2 0 0 0 0]; internalField uniform 0;\n"
          "boundaryField { \".*\" { type cyclic; } }\n")
    write(f"{case}/constant/transportProperties", "dictionary", "transportProperties",
          f"rho {RHO_F}; nu {mu / RHO_F:.12g};\n")
    write(f"{case}/constant/couplingProperties", "dictionary", "couplingProperties",
          f'scene "particles.yaml"; voidFraction {a.footprint}; sampling {a.sampling};\n'
          f"minVoidFraction 0.2; ddtVoidFraction on; meanPressureGradient suspensionWeight;\n"
          + (f"undisturbedVelocity {a.correction};\n" if a.correction else "")
          + (f"diffusionBandwidth {a.bandwidth * D:.12g};\n" if a.bandwidth > 0 else ""))
    with open(f"{case}/suspension.csv", "w") as f:
        f.write("x,y,z,radius\n")
        for p in x:
            f.write(f"{p[0]:.12g},{p[1]:.12g},{p[2]:.12g},{D / 2}\n")
    forces = "[drag, pressure_gradient, viscous, buoyancy]"
    with open(f"{case}/particles.yaml", "w") as f:
        f.write(f"""domain: {{min: [0, 0, 0], max: [{L:.12g}, {L:.12g}, {L:.12g}], periodic: [true, true, true]}}
gravity: [0, 0, -9.81]
time: {{step: {dt_f / a.substeps:.12g}, end: {2 * steps * dt_f:.12g}, expected_max_speed: 0.05}}
materials:
  - {{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.25, density: {RHO_P}}}
interaction_defaults: {{restitution: 0.9, friction: 0.05}}
contact: {{normal: hertz}}
insert:
  - {{type: csv, file: suspension.csv, material: glass}}
output: {{snapshot_interval: {write_every * dt_f:.12g}, fields: [velocity, radius]}}
fluid:
  density: {RHO_F}
  viscosity: {mu:.12g}
  drag: {a.drag}
  model: {a.model}
  pressure: {{hydrostatic: false}}
  forces: {forces}
""")
    return {"n": n, "eps": eps_box, "L": L, "steps": steps, "h": h / D}


def skew_mesh(case, f):
    """Move the mesh's interior points (blockMesh's, ascii) by up to f cell edges along a smooth
    field that vanishes on the box, so that every cell but none of the cyclic faces is
    non-orthogonal: d = f h s(x) (sin 2 pi y/L, sin 2 pi z/L, sin 2 pi x/L), s the product of
    sin(pi x_i / L). Returns how many points moved; checkMesh reports the non-orthogonality
    (log.checkMesh)."""
    path = os.path.join(case, "constant", "polyMesh", "points")
    with open(path) as fh:
        text = fh.read()
    triple = re.compile(r"\(([-0-9.eE+]+) ([-0-9.eE+]+) ([-0-9.eE+]+)\)")
    pts = np.array([[float(v) for v in m.groups()] for m in triple.finditer(text)])
    L = pts.max()
    h = L / round(len(np.unique(np.round(pts[:, 0] / L, 9))) - 1)
    inside = np.all((pts > 1e-9 * L) & (pts < L * (1 - 1e-9)), axis=1)
    u = pts / L
    s = np.prod(np.sin(np.pi * u), axis=1)
    move = f * h * s[:, None] * np.sin(2 * np.pi * u[:, [1, 2, 0]])
    pts[inside] += move[inside]
    rows = iter(pts)
    text = triple.sub(lambda m: "({:.17g} {:.17g} {:.17g})".format(*next(rows)), text)
    with open(path, "w") as fh:
        fh.write(text)
    return int(inside.sum())


def run(case, a):
    env = dict(os.environ, LD_LIBRARY_PATH=os.path.join(a.build, "lib"))
    solver = os.path.join(a.build, "bin", "grainFoam")
    if a.skew:
        with open(os.path.join(case, "log.blockMesh"), "w") as out:
            if subprocess.call([FOAM, "blockMesh"], cwd=case, stdout=out,
                               stderr=subprocess.STDOUT, env=env) != 0:
                sys.exit(f"hindered_settling: blockMesh failed, see {case}/log.blockMesh")
        skew_mesh(case, a.skew)
        with open(os.path.join(case, "log.checkMesh"), "w") as out:
            subprocess.call([FOAM, "checkMesh"], cwd=case, stdout=out,
                            stderr=subprocess.STDOUT, env=env)
    cmds = [] if a.skew else [(["blockMesh"], "log.blockMesh")]
    if a.ranks > 1:
        cmds.append((["decomposePar", "-force"], "log.decomposePar"))
        cmds.append((["mpirun", "--oversubscribe", "-np", str(a.ranks), solver, "-parallel"],
                     "log.grainFoam"))
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    else:
        cmds.append(([solver], "log.grainFoam"))
    for cmd, log in cmds:
        with open(os.path.join(case, log), "w") as out:
            rc = subprocess.call([FOAM] + cmd, cwd=case, stdout=out, stderr=subprocess.STDOUT, env=env)
        if rc != 0:
            sys.exit(f"hindered_settling: {cmd[0]} failed, see {case}/{log}")
    if not re.search(r"^End\s*$", open(os.path.join(case, "log.grainFoam")).read(), re.M):
        sys.exit(f"hindered_settling: grainFoam did not reach its end time (a SIGTERM or SIGINT stops it with exit 0 after a checkpoint); "
                 f"see {case}/log.grainFoam")


def measure(case, info, a):
    """From grainFoam's log: at every write time the time, the fluid's momentum
    rho sum eps U V and the particles' sum m v (the mean pressure gradient line)."""
    t, fluid, parts, imbalance, cpu, clamps = None, [], [], 0.0, 0.0, 0
    rows = []
    num = r"([-+0-9.eE]+)"
    mom = re.compile(r"momentum: fluid \(" + r" ".join([num] * 3) + r"\) kg m/s, particles \("
                     + r" ".join([num] * 3) + r"\)")
    for line in open(os.path.join(case, "log.grainFoam")):
        if line.startswith("Time = "):
            t = float(line.split()[2])
        elif "relative imbalance" in line:
            imbalance = max(imbalance, float(line.split()[-1]))
        elif line.startswith("ExecutionTime"):
            cpu = float(line.split()[2])
        elif (m := mom.search(line)) and t is not None:
            v = [float(g) for g in m.groups()]
            rows.append((t, v[2], v[5]))
    rows = np.array(rows)
    L3 = info["L"] ** 3
    fluid_mass = RHO_F * info["eps"] * L3
    part_mass = RHO_P * (1 - info["eps"]) * L3
    uf = rows[:, 1] / fluid_mass  # fluid phase average (interstitial), z
    vp = rows[:, 2] / part_mass   # particle average, z
    late = rows[:, 0] > a.skip
    slip = uf[late] - vp[late]
    # Homogeneity, from the particle snapshots: the index of dispersion of the particle count
    # per cell, var(n)/mean(n) (1 for Poisson points, about 0.3 for the non-overlapping start
    # at eps 0.8), and the spread of the particles' vertical velocity.
    disp, vstd, tsnap = [], [], []
    h = info["L"] / a.cells
    for f in sorted(glob.glob(os.path.join(case, "particles", "particles_*.h5"))):
        with h5py.File(f, "r") as h5:
            x = np.mod(h5["position"][()], info["L"])
            vz = h5["velocity"][()][:, 2]
            tsnap.append(float(h5.attrs["time"]))
        idx = np.minimum((x / h).astype(int), a.cells - 1)
        counts = np.bincount((idx[:, 0] * a.cells + idx[:, 1]) * a.cells + idx[:, 2],
                             minlength=a.cells**3)
        disp.append(counts.var() / counts.mean())
        vstd.append(vz.std())
    tsnap, disp, vstd = np.array(tsnap), np.array(disp), np.array(vstd)
    after = tsnap > a.skip
    # the mixture's momentum against the particles' (how well G keeps the mixture at rest)
    # the change of the mixture's momentum over the averaging window, against the particles'
    # momentum (G makes the net force zero; the coupling's one-step lag leaves the transient's
    # share, which stays constant once the flow is steady)
    mix = rows[late, 1] + rows[late, 2]
    drift = abs(mix[-1] - mix[0]) / np.abs(rows[late, 2]).mean()
    # the same change as a mean net force on the mixture, against its buoyant weight
    weight = info["n"] * VP * (RHO_P - RHO_F) * G
    tl = rows[late, 0]
    net_force = abs(mix[-1] - mix[0]) / (tl[-1] - tl[0]) / weight if len(tl) > 1 else 0.0
    return {"slip": slip.mean(), "slip_std": slip.std(), "samples": int(late.sum()),
            "drift": drift, "net_force": net_force, "imbalance": imbalance, "cpu": cpu,
            "dispersion_start": disp[0], "dispersion": disp[after].mean(),
            "vz_std": vstd[after].mean(),
            "series": list(zip(rows[:, 0], uf - vp)),
            "snapshots": list(zip(tsnap, disp, vstd)),
            "volume_flux": (info["eps"] * uf[late] + (1 - info["eps"]) * vp[late]).mean()}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--eps", default="0.6,0.7,0.8,0.9")
    ap.add_argument("--cells", type=int, default=4, help="cells per side of the cubic box")
    ap.add_argument("--h", type=float, default=3.0, help="cell edge in particle diameters")
    ap.add_argument("--re", type=float, default=0.1, help="single-sphere terminal Reynolds number")
    ap.add_argument("--drag", default="di_felice", choices=sorted(LAWS))
    ap.add_argument("--model", default="B", choices=["A", "B"])
    ap.add_argument("--footprint", default="divided")
    ap.add_argument("--sampling", default="cell")
    ap.add_argument("--correction", default=None, help="undisturbedVelocity (default off)")
    ap.add_argument("--bandwidth", type=float, default=0.0,
                    help="diffusionBandwidth b in particle diameters (0: none): eps, the exchange "
                         "and the sampled fluid averaged over a Gaussian exp(-r^2/b^2)")
    ap.add_argument("--dt", type=float, default=1e-4, help="fluid time step [s]")
    ap.add_argument("--substeps", type=int, default=10, help="DEM steps per fluid step")
    ap.add_argument("--end", type=float, default=0.1, help="simulated time [s]")
    ap.add_argument("--skip", type=float, default=0.04, help="transient left out of the mean [s]")
    ap.add_argument("--write", type=float, default=2e-3, help="log interval (write times) [s]")
    ap.add_argument("--skew", type=float, default=0.0,
                    help="move the mesh's interior points by up to this many cell edges "
                         "(non-orthogonal cells; skew_mesh())")
    ap.add_argument("--ranks", type=int, default=1)
    ap.add_argument("--seed", type=int, default=11, help="of the random positions")
    ap.add_argument("--arrangement", default="random", choices=["random", "lattice", "crystal"],
                    help="random: non-overlapping, Poisson-like counts per cell; lattice: "
                         "jittered simple cubic; crystal: simple cubic, 8 per cell")
    ap.add_argument("--series", action="store_true", help="print the slip at every write time")
    ap.add_argument("--check", default=None, help="PCT_DRAG,PCT_RZ: exit 1 beyond these")
    ap.add_argument("--work", default="/tmp/hindered_settling")
    ap.add_argument("--build", default=os.environ.get("GRAINFLOW_BUILD_DIR", os.path.join(ROOT, "build")))
    a = ap.parse_args()
    if not 0 <= a.skew < 0.5:  # half a cell edge folds a cell over its neighbour
        ap.error(f"--skew: {a.skew} is not in [0, 0.5) cell edges")
    a.build = os.path.abspath(a.build)
    mu = viscosity_for(a.re)
    u_t = terminal(mu)
    n_rz = rz_exponent(a.re)
    rows = []
    for eps in (float(e) for e in a.eps.split(",")):
        name = f"eps{eps:g}_{a.drag}_{a.model}_{a.footprint}_{a.sampling}_h{a.h:g}_c{a.cells}_re{a.re:g}_r{a.ranks}_{a.correction or 'off'}_{a.arrangement}_s{a.seed}_b{a.bandwidth:g}_t{a.end:g}"
        case = os.path.join(a.work, name)
        subprocess.call(["rm", "-rf", case])
        info = make_case(case, eps, a, mu)
        run(case, a)
        m = measure(case, info, a)
        e = info["eps"]
        s_drag = drag_slip(a.drag, e, mu)
        s_rz = u_t * e ** (n_rz - 1)
        row = dict(eps=e, particles=info["n"], drag=a.drag, model=a.model, footprint=a.footprint,
                   sampling=a.sampling, bandwidth_d=a.bandwidth, correction=a.correction or "off", arrangement=a.arrangement, cell_d=info["h"], cells=a.cells, re_t=a.re, mu=mu, u_t=u_t,
                   n_rz=n_rz, slip=m["slip"], slip_std=m["slip_std"], slip_drag=s_drag,
                   slip_rz=s_rz, err_drag_pct=100 * (m["slip"] / s_drag - 1),
                   err_rz_pct=100 * (m["slip"] / s_rz - 1), drag_vs_rz_pct=100 * (s_drag / s_rz - 1),
                   dispersion_start=m["dispersion_start"], dispersion=m["dispersion"],
                   vz_std=m["vz_std"], momentum_drift=m["drift"], net_force_pct=100 * m["net_force"], volume_flux=m["volume_flux"],
                   imbalance=m["imbalance"], cpu_s=m["cpu"], ranks=a.ranks)
        rows.append(row)
        print(f"hindered_settling: eps {e:.4f} ({info['n']} particles, {a.drag}, model {a.model}, "
              f"{a.arrangement}, {a.footprint}/{a.sampling}, bandwidth {a.bandwidth:g} d, correction {a.correction or 'off'}, cells {info['h']:.2f} d): slip {1e3 * m['slip']:.4f} mm/s "
              f"(std {1e3 * m['slip_std']:.4f}, {m['samples']} samples); drag law "
              f"{1e3 * s_drag:.4f} ({row['err_drag_pct']:+.2f} %), Richardson-Zaki n = {n_rz:g} "
              f"{1e3 * s_rz:.4f} ({row['err_rz_pct']:+.2f} %); mixture momentum change / particles' "
              f"{m['drift']:.1e} (a net force of {100 * m['net_force']:.2f} % of the buoyant weight); exchange imbalance {m['imbalance']:.1e}; {m['cpu']:.0f} s; "
              f"count dispersion {m['dispersion_start']:.2f} at the start, {m['dispersion']:.2f} "
              f"after, particle w spread {1e3 * m['vz_std']:.3f} mm/s", flush=True)
        if a.series:
            for t, s in m["series"]:
                print(f"  t {t:.4f} s  slip {1e3 * s:.4f} mm/s")
            for t, dsp, vs in m["snapshots"]:
                print(f"  t {t:.4f} s  count dispersion {dsp:.3f}  particle w spread "
                      f"{1e3 * vs:.3f} mm/s")
    out = os.path.join(a.work, "hindered_settling.csv")
    new = not os.path.exists(out)
    with open(out, "a", newline="") as f:
        wr = csv.DictWriter(f, fieldnames=list(rows[0]))
        if new:
            wr.writeheader()
        wr.writerows(rows)
    if a.check:
        tols = [float(x) for x in a.check.split(",")]
        tol_drag, tol_rz = tols[:2]
        # a third value: the mixture's net force within that % of its buoyant weight (a random
        # suspension: the PISO corrector does not conserve the mixture's momentum exactly where
        # Ksl varies from cell to cell), instead of its momentum within 1 % of the particles'
        if len(tols) > 2:
            drifts = lambda r: r["net_force_pct"] > tols[2]
            what = f"the mixture's net force within {tols[2]:g} % of its buoyant weight"
        else:
            drifts = lambda r: r["momentum_drift"] > 0.01
            what = "mixture momentum within 1 % of the particles'"
        bad = [r for r in rows if abs(r["err_drag_pct"]) > tol_drag or abs(r["err_rz_pct"]) > tol_rz
               or r["imbalance"] > 1e-12 or drifts(r)]
        print(f"hindered_settling: {len(rows) - len(bad)} of {len(rows)} within {tol_drag:g} % of "
              f"the drag law and {tol_rz:g} % of Richardson-Zaki, exchange balanced to 1e-12, "
              f"{what}: {'ok' if not bad else 'FAILED'}")
        sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
