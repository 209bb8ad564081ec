#!/usr/bin/env python3
"""Coarse-grained parcels in a bubbling fluidised bed (issue 23, validation 1, short form).

The `tutorials/cfd-dem/fluidisedBed` case (12 000 glass beads, d = 1.14-1.26 mm, in a
60 x 9 x 240 mm column of 3 mm cells, air at 2.0 U_mf after a ramp 0.2-0.3 s) run with the
beads as parcels of k = 1, 2, 3: the fill's count is 12 000 / k^3 parcels (the real beads'
number; for k > 1 filled into 2-160 mm instead of 2-82 mm, where random insertion finds room
for them, and time.max_overlap 0.3 instead of 0.25 for the harder landing), the DEM step
k x 1.5e-5 s (the contact time grows as k), or the next shorter step that divides the fluid
step, 3e-4 s for every k (k = 3: 3e-4/7 s).

Per k: the mean pressure drop over [--from, end] against the bed's buoyant weight
N V_p (rho_p - rho_f) g / A (the plateau above U_mf), its standard deviation (bubbles), three
mean bed heights over the snapshots (fields) in the window (bed_height.py):
  real      95 % of the real particles' mass below, each parcel's k^3 beads spread over its
            sphere (the real-particle height, issue 23's measure);
  centres   95 % of the parcel centres below (a parcel counts once, at its centre);
  pressure  where the time-mean, horizontally averaged pressure has fallen to 5 % of the
            drop above the outlet's (95 % of the weight the fluid carries lies below);
and, from the last snapshot before the inflow (0.2 s), the settled bed's real-particle height
and solid fraction (real volume over A times twice the mass-mean height); from the written void
fractions, the bubble holdup (the fraction of the bed's cells with eps > 0.8) and the emulsion's
mean eps (the bed's other cells);
and the cost: grainFoam's CPU seconds (ExecutionTime) per simulated second and its wall time.

usage: fluidised_bed.py [--ks 1,2,3] [--end 1.0] [--from 0.5] [--seed 1] [--depth 0.009]
                        [--cells 0.003] [--depth-cells N] [--periodic-depth] [--bandwidth B]
                        [--sampling cell|cellPoint]
                        [--work DIR] [--build DIR] [--pp-restitution E] [--analyse-only]
                        [--diagnose] [--plot PNG]
--ks takes any factors >= 1 (1.26 is about 2 beads per parcel; cases k<k>_seed<s>).
--end sets both the scene's time.end and controlDict's endTime (grainFoam stops at the earlier).
--seed sets the fill's random seed (another realisation of the same bed; cases k<k>_seed<s>).
--depth D makes the column D deep (a whole number of cells; 12 000 D/9 mm beads, the same
real beads per area; cases k<k>_seed<s>_depth<D>mm).
--cells C makes the cells C wide in x and z (dividing 60 and 240 mm), with a whole number of
them across the depth, or one when the depth is under 1.5 C (cases ..._cells<C>mm).
--depth-cells N puts N cells across the depth instead of cubic cells (1: the pseudo-2D mesh of
many pseudo-2D studies, one cell spanning the depth; cases ..._ny<N>).
--periodic-depth makes the column periodic across its depth: no front and back walls in the
scene, cyclic front and back patches on the mesh (cases ..._periodic). The depth must be at
least twice the interaction range (grainFoam refuses it otherwise: k = 3 needs --depth 0.018).
--sampling cellPoint samples the fluid at the particles by interpolation instead of the
tutorial's footprint-weighted cell values (docs/coupling.md; cases ..._cellPoint).
--bandwidth B adds couplingProperties' diffusionBandwidth B [m] (docs/coupling.md; cases ..._b<B>mm).
--pp-restitution E sets the restitution between the beads (parcels) to E, against the walls
kept at 0.9 (cases k<k>_seed<s>_epp<E>): kinetic theory's collisional dissipation per volume
falls as 1/k for parcels, restored by 1 - E^2 = k (1 - 0.9^2) (docs/accuracy-vs-cost-coupled.md).
--analyse-only reads the cases already in DIR (the cost columns from their logs).
--diagnose also prints the heights per snapshot, the solid-fraction profiles, the real mass
across the depth, and where the gas goes: the emulsion's share of the gas flux through the bed
and, per cell across the depth, the mean eps and the superficial velocity eps U_z.
Prints one row per k and appends them to <work>/fluidised_bed.csv.
--plot PNG runs nothing: it plots the bed height and the CPU per simulated second against k from
that table (the 9 mm column, one series per mesh; docs/accuracy-vs-cost-coupled.md).
"""
import argparse
import csv
import glob
import math
import os
import re
import shutil
import subprocess
import sys
import time

import h5py
import numpy as np

from bed_height import (centre_height, foam_scalar_field, foam_vector_field, pressure_height,
                        real_height, sphere_fraction_below)

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tutorials", "cfd-dem"))
from foam_case import WALL_LOADS, mean_wall_share, series as foam_series  # noqa: E402
FOAM = os.path.join(ROOT, "scripts", "foam_env.sh")
TUTORIAL = os.path.join(ROOT, "tutorials", "cfd-dem", "fluidisedBed")
RHO_F, G = 1.2, 9.81
DEPTH = 0.009  # the column depth; --depth changes it (and AREA, NY)
CELL = 0.003  # the cells' width in x and z; --cells changes it (and NX, NZ, NY)
AREA = 0.06 * DEPTH
FLUID_STEP = 3e-4
INFLOW_START = 0.2  # 0/U: the inflow ramps up from 0.2 s


def sub(path, old, new):
    text = open(path).read()
    if old not in text:
        sys.exit(f"fluidised_bed: no '{old}' in {path}")
    open(path, "w").write(text.replace(old, new, 1))


def dem_step(k):
    """The DEM step: k x 1.5e-5 s, or the next shorter one that divides the fluid step."""
    steps = math.ceil(FLUID_STEP / (k * 1.5e-5) - 1e-9)
    return FLUID_STEP / steps, steps


PP_RESTITUTION = None  # --pp-restitution: the beads' (parcels') restitution against each other
BANDWIDTH = None  # --bandwidth: couplingProperties' diffusionBandwidth [m]
PERIODIC_DEPTH = False  # --periodic-depth: front and back cyclic instead of walls
SAMPLING = None  # --sampling: couplingProperties' sampling (the tutorial's: cell)


def parse_k(text):
    """A coarse-graining factor from --ks: 2 stays 2 (case k2_...), 1.5 is 1.5 (case k1.5_...)."""
    k = float(text)
    if not k >= 1:
        sys.exit(f"fluidised_bed: --ks: {text} is not a coarse-graining factor >= 1")
    return int(k) if k.is_integer() else k


def case_dir(work, k, seed):
    tail = "" if abs(DEPTH - 0.009) < 1e-12 else f"_depth{1e3 * DEPTH:g}mm"
    if abs(CELL - 0.003) > 1e-12:
        tail += f"_cells{1e3 * CELL:g}mm"
    if PP_RESTITUTION is not None:
        tail += f"_epp{PP_RESTITUTION:g}"
    if BANDWIDTH is not None:
        tail += f"_b{1e3 * BANDWIDTH:g}mm"
    if PERIODIC_DEPTH:
        tail += "_periodic"
    if DEPTH_CELLS:
        tail += f"_ny{DEPTH_CELLS}"
    if SAMPLING:
        tail += f"_{SAMPLING}"
    return os.path.join(work, f"k{k}_seed{seed}{tail}")


DEPTH_CELLS = None  # --depth-cells: the cells across the depth (default: cubic cells)


def set_mesh(depth, cell):
    """The column DEPTH deep and its cells CELL wide in x and z (the tutorial: 9 mm, 3 mm).
    The fill's count, the walls, the mesh and the analysis scale with the depth (the same real
    beads per area); the depth holds a whole number of cells, or one cell when it is less than
    1.5 cells (a pseudo-2D mesh, one cell across the depth)."""
    global DEPTH, AREA, CELL, NX, NY, NZ
    if not (cell > 0 and depth > 0):
        sys.exit(f"fluidised_bed: --cells {cell} and --depth {depth} must be lengths > 0 [m]")
    NX, NZ = round(0.06 / cell), round(HEIGHT / cell)
    if abs(NX * cell - 0.06) > 1e-9 or abs(NZ * cell - HEIGHT) > 1e-9:
        sys.exit(f"fluidised_bed: --cells {cell} does not divide the 60 x 240 mm column")
    NY = DEPTH_CELLS or max(1, round(depth / cell))
    if not DEPTH_CELLS and NY > 1 and abs(NY * cell - depth) > 1e-9:
        sys.exit(f"fluidised_bed: --depth {depth} is not a whole number of {cell} m cells")
    DEPTH, AREA, CELL = depth, 0.06 * depth, cell


def prepare(work, k, end, seed):
    case = case_dir(work, k, seed)
    shutil.rmtree(case, ignore_errors=True)
    shutil.copytree(TUTORIAL, case, ignore=shutil.ignore_patterns(
        "particles", "processor*", "postProcessing", "log.*", "*.png", "[1-9]*", "0.[0-9]*"))
    dt, _ = dem_step(k)
    scene = os.path.join(case, "particles.yaml")
    beads = 12000 * DEPTH / 0.009
    sub(scene, "    count: 12000\n", f"    count: {round(beads / k**3)}\n    coarse_grain: {k}\n")
    sub(scene, "  step: 1.5e-5\n", f"  step: {dt:.17g}\n")
    sub(scene, "    seed: 1\n", f"    seed: {seed}\n")
    if PP_RESTITUTION is not None:
        sub(scene, "interaction_defaults: {restitution: 0.9, friction: 0.3}\n",
            "interaction_defaults: {restitution: 0.9, friction: 0.3}\n"
            f"interactions:\n  - {{materials: [glass, glass], restitution: {PP_RESTITUTION:.6g}, friction: 0.3}}\n")
    if k > 1:  # random insertion keeps centres k r inside the region: give the parcels room
        sub(scene, "max: [0.06, 0.009, 0.082]", "max: [0.06, 0.009, 0.16]")
        # The longer fall lands them harder: at k = 2 a pair reached 20.3 % overlap in the pour.
        sub(scene, "  max_overlap: 0.25 ", "  max_overlap: 0.3 ")
    if SAMPLING:
        sub(os.path.join(case, "constant", "couplingProperties"), "sampling          cell;",
            f"sampling          {SAMPLING};")
    if BANDWIDTH is not None:
        with open(os.path.join(case, "constant", "couplingProperties"), "a") as f:
            f.write(f"diffusionBandwidth {BANDWIDTH:.6g};\n")
    # grainFoam stops at the earlier of the two ends: both are set.
    sub(os.path.join(case, "system", "controlDict"), "endTime         1.0;", f"endTime         {end:g};")
    sub(scene, "  end: 1.0 ", f"  end: {end:g} ")
    mesh = os.path.join(case, "system", "blockMeshDict")
    if abs(DEPTH - 0.009) > 1e-12:
        y, mm = f"{DEPTH:g}", f"{1e3 * DEPTH:g}"
        for old in ("max: [0.06, 0.009, 0.24]", "point: [0, 0.009, 0]", "max: [0.06, 0.009, 0."):
            sub(scene, old, old.replace("0.009", y))
        sub(mesh, "(60 9 0) (0 9 0)", f"(60 {mm} 0) (0 {mm} 0)")
        sub(mesh, "(60 9 240) (0 9 240)", f"(60 {mm} 240) (0 {mm} 240)")
    if (NX, NY, NZ) != (20, 3, 80):
        sub(mesh, "(20 3 80)", f"({NX} {NY} {NZ})")
    if PERIODIC_DEPTH:  # no front and back walls: the column repeats across its depth
        top = f"  max: [0.06, {DEPTH:g}, 0.24]\n"
        sub(scene, top, top + "  periodic: [false, true, false]\n")
        sub(scene, "  - {type: plane, name: back, point: [0, 0, 0], normal: [0, 1, 0], material: wall}\n", "")
        sub(scene, f"  - {{type: plane, name: front, point: [0, {DEPTH:g}, 0], normal: [0, -1, 0], material: wall}}\n", "")
        sub(mesh, "walls  { type wall;  faces ( (0 1 5 4) (2 3 7 6) (1 2 6 5) (3 0 4 7) ); }",
            "walls  { type wall;  faces ( (1 2 6 5) (3 0 4 7) ); }\n"
            "    front  { type cyclic; neighbourPatch back;  faces ( (0 1 5 4) ); }\n"
            "    back   { type cyclic; neighbourPatch front; faces ( (3 7 6 2) ); }")
        for name in ("U", "p"):
            field = os.path.join(case, "0", name)
            text = open(field).read()
            at = text.rindex("}")
            open(field, "w").write(text[:at] + '    "(front|back)" { type cyclic; }\n' + text[at:])
    return case


def series(case, name):
    path = glob.glob(os.path.join(case, "postProcessing", name, "*", "surfaceFieldValue.dat"))[0]
    rows = np.loadtxt(path)
    return rows[:, 0], rows[:, 1]


def analyse(case, t_from):
    t, p_in = series(case, "pInlet")
    _, p_out = series(case, "pOutlet")
    n = min(len(t), len(p_out))
    t, dp = t[:n], RHO_F * (p_in[:n] - p_out[:n])
    window = t >= t_from - 1e-9
    centres, reals, settled, last = [], [], None, None
    for s in sorted(glob.glob(os.path.join(case, "particles", "particles_*.h5"))):
        with h5py.File(s, "r") as f:
            ts = float(f.attrs["time"])
            if ts >= t_from - 1e-9 or ts <= INFLOW_START + 1e-9:
                z, r, m = f["position"][:, 2], 0.5 * f["diameter"][:], f["mass"][:]
            if ts >= t_from - 1e-9:
                centres.append(centre_height(z))
                reals.append(real_height(z, r, m))
            elif ts <= INFLOW_START + 1e-9:  # the last snapshot before the inflow: the settled bed
                settled = (real_height(z, r, m), float(np.sum(4 / 3 * math.pi * r**3) / AREA
                                                        / (2 * np.dot(m, z) / m.sum())))
            last = s
    if last is None:
        sys.exit(f"fluidised_bed.py: {case}/particles holds no snapshot (particles_*.h5): the run "
                 f"ended before its first write time; run it longer (--end)")
    with h5py.File(last, "r") as f:
        d, m = f["diameter"][:], f["mass"][:]
        real = f["real_count"][:].sum() if "real_count" in f else len(d)
    v = math.pi / 6 * d**3
    weight = float(np.sum(m - RHO_F * v)) * G / AREA
    return dict(parcels=len(d), real=int(real), dp_mean=float(dp[window].mean()),
                dp_std=float(dp[window].std()), weight=weight,
                height=float(np.mean(reals)) if reals else float("nan"),
                height_centres=float(np.mean(centres)) if centres else float("nan"),
                height_sd=float(np.std(reals)) if reals else float("nan"),
                height_pressure=pressure_profile_height(case, t_from, t, p_in[:n], p_out[:n]),
                snapshots=len(reals), settled_height=settled[0] if settled else float("nan"),
                settled_solid_fraction=settled[1] if settled else float("nan"),
                **dict(zip(("bubble_holdup", "emulsion_voidfraction"), bubbles(case, t_from))))


NX, NY, NZ, HEIGHT = 20, 3, 80, 0.24  # the uniform mesh (3 mm cells; set_mesh), x fastest, z slowest


def written_fields(case, t_from, name):
    """(time, field as [z, y, x]; a vector field as [z, y, x, 3]) of each written field `name`
    from t_from on."""
    out = []
    for d in glob.glob(os.path.join(case, "[0-9]*")):
        try:
            tw = float(os.path.basename(d))
        except ValueError:
            continue
        if tw >= t_from - 1e-9 and os.path.exists(os.path.join(d, name)):
            path = os.path.join(d, name)
            out.append((tw, foam_vector_field(path).reshape(NZ, NY, NX, 3) if name == "U"
                        else foam_scalar_field(path).reshape(NZ, NY, NX)))
    return sorted(out, key=lambda x: x[0])


def pressure_profile_height(case, t_from, t, p_in, p_out):
    """pressure_height of the time-mean profile: the written p fields averaged over each cell
    layer, between the inlet's and the outlet's area-averaged p at the same times, averaged
    over the write times from t_from on."""
    profiles = []
    for tw, p in written_fields(case, t_from, "p"):
        i = int(np.argmin(abs(t - tw)))
        if abs(t[i] - tw) <= 1e-6:
            profiles.append(np.concatenate(([p_in[i]], p.mean(axis=(1, 2)), [p_out[i]])))
    if not profiles:
        return float("nan")
    z = np.concatenate(([0.0], (np.arange(NZ) + 0.5) * HEIGHT / NZ, [HEIGHT]))
    return pressure_height(z, np.mean(profiles, axis=0))


def bubbles(case, t_from):
    """Over the written void fractions from t_from on: the bubble holdup (the fraction of the
    bed's cells with eps > 0.8; the bed: the cell layers whose mean eps is below 0.9) and the
    emulsion's mean eps (the bed's other cells)."""
    hold, emulsion = [], []
    for _, e in written_fields(case, t_from, "voidfraction"):
        bed = e[e.mean(axis=(1, 2)) < 0.9]
        hold.append(float((bed > 0.8).mean()))
        emulsion.append(float(bed[bed <= 0.8].mean()))
    return (float(np.mean(hold)), float(np.mean(emulsion))) if hold else (float("nan"),) * 2


def gas_paths(case, t_from):
    """Where the gas goes through the bed (the cell layers whose mean eps is below 0.9), over the
    written fields from t_from on: the emulsion's share (cells with eps <= 0.8) of the upward
    gas flux sum(eps U_z), and per cell across the depth (y) the mean eps and the superficial
    velocity eps U_z. grainFoam's U is the interstitial velocity."""
    share, eps, flux = [], [], []
    velocity = dict(written_fields(case, t_from, "U"))
    for tw, e in written_fields(case, t_from, "voidfraction"):
        if tw not in velocity:
            continue
        layers = e.mean(axis=(1, 2)) < 0.9
        bed, q = e[layers], (e * velocity[tw][..., 2])[layers]
        share.append(float(q[bed <= 0.8].sum() / q.sum()))
        eps.append(bed.mean(axis=(0, 2)))
        flux.append(q.mean(axis=(0, 2)))
    if not share:
        return float("nan"), [], []
    return float(np.mean(share)), list(np.mean(eps, axis=0)), list(np.mean(flux, axis=0))


def momentum_budget(case, t_from):
    """The bed's vertical momentum budget between the first snapshot from t_from on (t0) and
    the last (t1), each term a share of the buoyant weight W: the gas (mean dp A over the
    fluid steps in (t0, t1]), each wall (grainFoam's `wall loads` lines of the write intervals
    inside [t0, t1]), the inflow's momentum rho U_s^2 (1/eps_b - 1) A (eps_b: the bottom cells'
    void fraction, written fields), the bed's momentum gain between the two snapshots, and
    the balance gas + walls + inflow - gain - 1 (0 when every force is accounted for)."""
    snaps = []
    for s in sorted(glob.glob(os.path.join(case, "particles", "particles_*.h5"))):
        with h5py.File(s, "r") as f:
            ts = float(f.attrs["time"])
            if ts >= t_from - 1e-9:
                m, d = f["mass"][:], f["diameter"][:]
                snaps.append((ts, float(np.dot(m, f["velocity"][:, 2])),
                              float(np.sum(m - RHO_F * math.pi / 6 * d**3)) * G))
    (t0, p0, weight), (t1, p1, _) = snaps[0], snaps[-1]
    t, p_in, _ = foam_series(case, "pInlet")
    _, p_out, _ = foam_series(case, "pOutlet")
    tq, q, area = foam_series(case, "inletFlow")
    n = min(len(t), len(p_out), len(tq))
    inside = (t[:n] > t0 + 1e-9) & (t[:n] <= t1 + 1e-9)
    out = dict(gas=float(RHO_F * (p_in[:n] - p_out[:n])[inside].mean()) * AREA / weight)
    walls, span, now = {}, 0.0, None
    for line in open(os.path.join(case, "log.grainFoam")):
        if line.startswith("Time = "):
            now = float(line.split()[2])
        elif (m := WALL_LOADS.match(line)) and now is not None:
            dt = float(m.group(1))
            if now - dt >= t0 - 1e-9 and now <= t1 + 1e-9:
                span += dt
                for name, values in re.findall(r"(\S+) \(([^)]*)\)", m.group(2)):
                    walls[name] = walls.get(name, 0.0) - dt * float(values.split()[2])
    out["walls"] = {name: f / span / weight for name, f in walls.items()} if span > 0 else {}
    u_s = float(-q[:n][inside].mean() / area)
    inverse = [np.mean(1 / e[0]) for _, e in written_fields(case, t0, "voidfraction") if _ <= t1 + 1e-9]
    out["inflow"] = RHO_F * u_s**2 * (float(np.mean(inverse)) - 1) * AREA / weight
    out["gain"] = (p1 - p0) / (t1 - t0) / weight
    out["balance"] = out["gas"] + sum(out["walls"].values()) + out["inflow"] - out["gain"] - 1
    out["window"] = (t0, t1)
    return out


def diagnose(case, t_from):
    """Print the heights per snapshot, the settled and the time-mean fluidised solid fraction
    per 3 mm layer (real mass spread over each sphere) and the real mass across the depth in
    the lower bed (z 5-25 mm, 1 mm bins)."""
    edges, yedges = np.arange(0, 0.0901, 0.003), np.linspace(0, DEPTH, round(DEPTH / 0.001) + 1)

    def spread(c, r, m, e):
        return (m[:, None] * np.diff(sphere_fraction_below((e[None, :] - c[:, None]) / r[:, None]), axis=1)).sum(0)
    heights, fluid, depth, settled = [], [], [], None
    for s in sorted(glob.glob(os.path.join(case, "particles", "particles_*.h5"))):
        with h5py.File(s, "r") as f:
            ts, x, r, m = float(f.attrs["time"]), f["position"][:], 0.5 * f["diameter"][:], f["mass"][:]
        rho = float(m.sum() / np.sum(4 / 3 * math.pi * r**3))
        layers = spread(x[:, 2], r, m, edges) / (rho * AREA * 0.003)
        if ts <= INFLOW_START + 1e-9:
            settled = (ts, layers)
        elif ts >= t_from - 1e-9:
            heights.append((ts, real_height(x[:, 2], r, m), centre_height(x[:, 2])))
            fluid.append(layers)
            low = (x[:, 2] > 0.005) & (x[:, 2] < 0.025)
            depth.append(spread(x[low, 1], r[low], m[low], yedges) / m[low].sum())
    print(f"  {os.path.basename(case)}: heights real/centres [mm] per snapshot: "
          + " ".join(f"{ts:.2f}:{1e3 * a:.1f}/{1e3 * b:.1f}" for ts, a, b in heights))
    print(f"    solid fraction per 3 mm layer, settled (t = {settled[0]:.2f} s): "
          + " ".join(f"{v:.2f}" for v in settled[1]))
    print("    solid fraction per 3 mm layer, fluidised (time mean): " + " ".join(f"{v:.2f}" for v in np.mean(fluid, 0)))
    print("    real mass across the depth, z 5-25 mm, 1 mm bins: " + " ".join(f"{v:.3f}" for v in np.mean(depth, 0)))
    b = momentum_budget(case, t_from)
    print(f"    momentum budget {b['window'][0]:.2f}-{b['window'][1]:.2f} s, shares of the buoyant weight: "
          f"gas {b['gas']:.4f}, " + ", ".join(f"{k} {v:+.4f}" for k, v in b["walls"].items())
          + f", inflow's momentum {b['inflow']:+.4f}, the bed's momentum gain {b['gain']:+.4f}: "
          f"balance {b['balance']:+.4f}")
    share, eps, flux = gas_paths(case, t_from)
    print(f"    gas through the bed: emulsion's share of the flux {share:.3f}; per cell across the depth, "
          "eps " + " ".join(f"{v:.3f}" for v in eps) + ", superficial u_z [m/s] " + " ".join(f"{v:.3f}" for v in flux))


def plot(table, path):
    """--plot: from the rows of `table` (every run of this script in its work directory), the
    real-particle bed height and the CPU per simulated second against k, for the column 9 mm
    deep with its walls and cubic cells, without averaging or a changed restitution, one series
    per mesh; a fill is a dot, the mean over the fills a line."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = {}
    with open(table) as f:
        for r in csv.DictReader(f):
            if (abs(float(r["depth"]) - 0.009) < 1e-9 and not r["bandwidth"] and not r["pp_restitution"]
                    and not r.get("depth_cells") and r.get("periodic_depth", "0") == "0"
                    and r.get("sampling", "cell") == "cell"):
                rows[(float(r["k"]), int(r["seed"]), float(r["cells"]))] = r  # the last run of each
    if not rows:
        sys.exit(f"fluidised_bed: no runs of the 9 mm column in {table}")
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4.2))
    base, marked = None, False
    for i, cell in enumerate(sorted({key[2] for key in rows})):
        ks = sorted({key[0] for key in rows if key[2] == cell})
        fills = {k: [r for key, r in rows.items() if key[0] == k and key[2] == cell] for k in ks}
        label = f"{1e3 * cell:g} mm cells"
        height = [np.mean([1e3 * float(r["height"]) for r in fills[k]]) for k in ks]
        cpu = [np.mean([float(r["cpu_s"]) / float(r["simulated_s"]) for r in fills[k]]) for k in ks]
        for k in ks:
            ax.plot([k] * len(fills[k]), [1e3 * float(r["height"]) for r in fills[k]], ".", color=f"C{i}", alpha=0.5)
        ax.plot(ks, height, "o-", color=f"C{i}", label=label)
        # A bed the gas does not carry (a plug, or gas passing by): mean dp off the weight by > 5 %.
        stuck = [j for j, k in enumerate(ks)
                 if abs(np.mean([float(r["dp_mean"]) / float(r["weight"]) for r in fills[k]]) - 1) > 0.05]
        ax.plot([ks[j] for j in stuck], [height[j] for j in stuck], "kx", ms=9,
                label="not fluidised (mean dp off the weight by > 5 %)" if stuck and not marked else None)
        marked = marked or bool(stuck)
        bx.plot(ks, cpu, "o-", color=f"C{i}", label=label)
        if abs(cell - 0.003) < 1e-9 and ks[0] == 1:
            base = (height[0], cpu[0])
    if base:
        ax.axhspan(0.95 * base[0], 1.05 * base[0], color="0.85", label="beads on 3 mm cells ± 5 %")
        kk = np.linspace(1, 3, 50)
        bx.plot(kk, base[1] / (kk**3 / 2), "k:", label="beads on 3 mm cells / (k³/2)")
    ax.set(xlabel="coarse-graining factor k", ylabel="bed height, real particles [mm]",
           title="fluidisedBed: bed height (dots: fills)")
    bx.set(xlabel="coarse-graining factor k", ylabel="grainFoam CPU s per simulated s", yscale="log",
           title="cost")
    ax.legend(fontsize=8)
    bx.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"fluidised_bed: wrote {path}")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ks", default="1,2,3")
    ap.add_argument("--end", type=float, default=1.0)
    ap.add_argument("--from", dest="t_from", type=float, default=0.5)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--analyse-only", action="store_true")
    ap.add_argument("--diagnose", action="store_true")
    ap.add_argument("--depth", type=float, default=0.009)
    ap.add_argument("--cells", type=float, default=0.003)
    ap.add_argument("--pp-restitution", type=float, default=None)
    ap.add_argument("--bandwidth", type=float, default=None)
    ap.add_argument("--periodic-depth", action="store_true")
    ap.add_argument("--depth-cells", type=int, default=None)
    ap.add_argument("--sampling", choices=("cell", "cellPoint"), default=None)
    ap.add_argument("--plot", default=None, metavar="PNG")
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "benchmarks", "coarse_grain_fluidised"))
    ap.add_argument("--build", default=os.environ.get("GRAINFLOW_BUILD_DIR", os.path.join(ROOT, "build")))
    args = ap.parse_args()
    if args.plot:
        return plot(os.path.join(args.work, "fluidised_bed.csv"), args.plot)
    global DEPTH_CELLS, SAMPLING
    SAMPLING = args.sampling if args.sampling != "cell" else None
    if args.depth_cells is not None and args.depth_cells < 1:
        sys.exit(f"fluidised_bed: --depth-cells {args.depth_cells} must be a whole number >= 1")
    DEPTH_CELLS = args.depth_cells
    set_mesh(args.depth, args.cells)
    global PP_RESTITUTION
    PP_RESTITUTION = args.pp_restitution
    global BANDWIDTH, PERIODIC_DEPTH
    BANDWIDTH = args.bandwidth
    PERIODIC_DEPTH = args.periodic_depth
    if BANDWIDTH is not None and not BANDWIDTH >= 0:
        sys.exit(f"fluidised_bed: --bandwidth {BANDWIDTH} must be a length >= 0 [m] (0: no averaging)")
    os.makedirs(args.work, exist_ok=True)
    env = dict(os.environ, LD_LIBRARY_PATH=os.path.join(args.build, "lib"))
    rows = []
    for k in (parse_k(x) for x in args.ks.split(",")):
        if args.analyse_only:
            case, wall = case_dir(args.work, k, args.seed), float("nan")
        else:
            case = prepare(args.work, k, args.end, args.seed)
            started = time.monotonic()
            for cmd, log in ((["blockMesh"], "log.blockMesh"),
                             ([os.path.join(args.build, "bin", "grainFoam")], "log.grainFoam")):
                with open(os.path.join(case, log), "w") as out:
                    if subprocess.call([FOAM] + cmd, cwd=case, stdout=out, stderr=subprocess.STDOUT, env=env):
                        sys.exit(f"fluidised_bed: k = {k}: {cmd[0]} failed, see {case}/{log}")
            wall = time.monotonic() - started
        text = open(os.path.join(case, "log.grainFoam")).read()
        if not re.search(r"^End\s*$", text, re.M):
            sys.exit(f"fluidised_bed: k = {k}: grainFoam did not reach its end time (a SIGTERM or SIGINT stops it with exit 0 after a checkpoint); "
                     f"see {case}/log.grainFoam")
        cpu = float(re.findall(r"ExecutionTime = (\S+) s", text)[-1])
        simulated = float(re.findall(r"^Time = (\S+)$", text, re.MULTILINE)[-1])  # the run's own end
        imbalance = max(float(x) for x in re.findall(r"relative imbalance (\S+)", text))
        row = dict(k=k, seed=args.seed, depth=DEPTH, cells=CELL, depth_cells=DEPTH_CELLS or "",
                   periodic_depth=int(PERIODIC_DEPTH), sampling=SAMPLING or "cell",
                   bandwidth="" if BANDWIDTH is None else BANDWIDTH,
                   pp_restitution="" if PP_RESTITUTION is None else PP_RESTITUTION,
                   **analyse(case, args.t_from), cpu_s=cpu, wall_s=wall,
                   simulated_s=simulated, cpu_per_simulated_s=cpu / simulated, worst_imbalance=imbalance,
                   emulsion_gas_share=gas_paths(case, args.t_from)[0],
                   walls_share=mean_wall_share(os.path.join(case, "log.grainFoam"), args.t_from)[0])
        rows.append(row)
        if args.diagnose:
            diagnose(case, args.t_from)
        print(f"k = {k}: {row['parcels']} parcels ({row['real']} beads), mean dp "
              f"{row['dp_mean']:.1f} Pa = {row['dp_mean'] / row['weight']:.4f} x weight "
              f"{row['weight']:.1f} Pa (the walls carry {row['walls_share']:.4f}), std {row['dp_std']:.1f} Pa, bed height (real particles) "
              f"{1e3 * row['height']:.2f} mm (sd over {row['snapshots']} snapshots "
              f"{1e3 * row['height_sd']:.2f}), parcel centres {1e3 * row['height_centres']:.2f} mm, "
              f"pressure {1e3 * row['height_pressure']:.2f} mm; settled before the inflow: real-particle "
              f"height {1e3 * row['settled_height']:.2f} mm, solid fraction "
              f"{row['settled_solid_fraction']:.3f}; bubble holdup {row['bubble_holdup']:.3f}, emulsion eps "
              f"{row['emulsion_voidfraction']:.3f}, its share of the gas flux {row['emulsion_gas_share']:.3f}; CPU {cpu:.0f} s ({cpu / simulated:.0f} s per "
              f"simulated s), wall {wall:.0f} s, exchange imbalance {imbalance:.1e}", flush=True)
    out = os.path.join(args.work, "fluidised_bed.csv")
    new = not os.path.exists(out)
    if not new:  # a table with other columns (an older version of this script): kept aside
        with open(out) as f:
            header = next(csv.reader(f), [])
        if header != list(rows[0].keys()):
            os.replace(out, out + ".old")
            print(f"fluidised_bed: {out} had other columns; moved to {out}.old")
            new = True
    with open(out, "a", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        if new:
            w.writeheader()
        w.writerows(rows)
    if rows and rows[0]["k"] == 1:
        base = rows[0]
        for r in rows[1:]:
            rel = {key: 100 * (r[key] / base[key] - 1) for key in ("height", "height_centres", "height_pressure")}
            print(f"k = {r['k']} vs k = 1: bed height (real particles) {rel['height']:+.1f} %, "
                  f"(parcel centres) {rel['height_centres']:+.1f} %, (pressure) {rel['height_pressure']:+.1f} %, "
                  f"std of dp {100 * (r['dp_std'] / base['dp_std'] - 1):+.1f} %, cost "
                  f"{base['cpu_s'] / r['cpu_s']:.1f}x less (k^3/2 = {r['k']**3 / 2:g})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
