#!/usr/bin/env python3
"""Fixed-bed pressure drop against the drag law's own packed-bed closed form, and where the
difference comes from: the profile of dp/dz through the bed, cell layer by cell layer.

The bed: the 3300 beads (d = 1 mm) of tutorials/cfd-dem/ergunPackedBed, poured once (0.15 s,
cached in <work>/pour), then re-inserted at rest for every run in the 12 x 12 mm periodic
column and crossed by air (rho = 1.2, mu = 1.8e-5) at 0.2 m/s superficial for 0.06 s, 20 DEM
steps per fluid step, model A, footprint divided, sampling cell (coupled_sweeps.py's bed).
The drop is steady within 0.005 s (the flow starts at full speed); --end shortens the run.

Reference: the drag law's own pressure gradient in a uniform bed, dp/dz = n F_total with
n = (1 - eps)/V_p and F_total = F_drag/eps = K(eps, U) U/eps at the interstitial slip U = U_s/eps
(Ergun's equation for ergun and gidaspow, 18 phi mu U_s F/d^2 for koch_hill, ...), times the
bed's height, both measured from the particles as the tutorial does (eps: the solid fraction
of the bed's core, 3 d from its bottom and top, from exact sphere-slice volumes; height: the
particle volume over A (1 - eps), the mass-equivalent height). That is N F_total(eps)/A: every
particle carrying the drag of a particle inside the bed.

Measured: the inlet pressure averaged over the second half of the run (the outlet holds p = 0), and at
the last time the horizontally averaged pressure of every cell layer: dp/dz between layers
against the closed form, the void fraction of each layer and the law at that void fraction.

Usage: bed_surface.py [--laws gidaspow,koch_hill] [--cells 6,4,3] [--surface cell,sharpInterface]
                      [--pressure linear] [--ranks 1] [--profile] [--plot FILE.png]
                      [--check PERCENT] [--end 0.06] [--bandwidth B] [--pour-seed 7] [--footprint divided]
                      [--model A] [--work DIR]
                      [--build DIR]
--cells: cells across the 12 mm column (6, 4, 3: cells of 2, 3, 4 d).
--surface: couplingProperties dragVoidFraction, comma-separated (cell: the key is left out,
           the default; sharpInterface).
--pressure: couplingProperties facePressure for every run (linear: the key is left out, the
            default; dragSeries).
--bandwidth: couplingProperties diffusionBandwidth, in particle diameters (default none).
--footprint, --model: couplingProperties voidFraction (divided) and the scene's fluid model (A).
--pour-seed: the seed of the pour's fill (7, ergunPackedBed's): another seed pours the same bed
  anew (its own core eps, height and surface).
--check: exit 1 unless every run with a surface treatment is within PERCENT of the closed
         form and every exchange imbalance printed is below 1e-12.
Appends one row per run to <work>/bed_surface.csv.
"""
import argparse
import csv
import glob
import math
import os
import re
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "tests", "dem", "fluid"))
import coupled_sweeps as cs  # noqa: E402  (pour, bed_case, run, bed_dp)
import drag_reference as ref  # noqa: E402  (each law from its paper, independent of the C++)

U_S = 0.2
AREA = cs.AREA
LAW_OF = dict(ref.LAWS)


def law_k(law, eps, u, d):
    """K of `law` [kg/s] (drag_reference.py's formulas, with this bed's d, rho, mu)."""
    ref.D, ref.RHO, ref.MU = d, cs.RHO_F, cs.MU
    ref.VOLUME = math.pi * d**3 / 6
    return LAW_OF[law](eps, u)


def closed_form_gradient(law, eps, d):
    """dp/dz [Pa/m] of a uniform fixed bed at void fraction eps: n F_total."""
    u = U_S / eps
    volume = math.pi * d**3 / 6
    return (1 - eps) / volume * law_k(law, eps, u, d) * u / eps


def bed_geometry(snapshot):
    """d, core eps, mass-equivalent height, highest particle top, solid volume."""
    import h5py
    with h5py.File(snapshot, "r") as f:
        z = f["position"][:, 2]
        r = f["radius"][:]
    d, eps, height = cs.bed_properties(snapshot)
    return d, eps, height, float((z + r).max()), float((4 / 3 * math.pi * r**3).sum())


def read_internal(path):
    """internalField of an ascii OpenFOAM scalar field (uniform or nonuniform List)."""
    text = open(path).read()
    m = re.search(r"internalField\s+nonuniform\s+List<scalar>\s*(\d+)\s*\((.*?)\)\s*;", text, re.S)
    if m:
        return np.array(m.group(2).split(), dtype=float)
    m = re.search(r"internalField\s+uniform\s+(\S+);", text)
    return np.array([float(m.group(1))])


def layer_profile(case, cells):
    """Horizontal means per cell layer (blockMesh order: x fastest, then y, then z) of the
    kinematic pressure and the void fraction at the last written time."""
    times = [t for t in os.listdir(case) if re.fullmatch(r"[0-9.]+(e-?\d+)?", t) and t != "0"]
    last = max(times, key=float)
    nz = int(round(cells * 5))
    p = read_internal(os.path.join(case, last, "p")).reshape(nz, cells * cells).mean(axis=1)
    e = read_internal(os.path.join(case, last, "voidfraction")).reshape(nz, cells * cells).mean(axis=1)
    return p * cs.RHO_F, e


def bulk_gradients(case, cells, h, face_pressure):
    """The cells' own -dp/dz in the bed's bulk at the last written time, as the run's
    momentum equation had it: Gauss linear (the mean of the two neighbours' pressures), or
    dragSeries (the face pressures of the half cells in series, resistance r = Ksl/(rho eps c),
    c = eps: model A, a bulk cell read as one layer; each half cell's r that of its layer: the
    cell and its four neighbours across z, the column periodic sideways). Bulk: layers k whose neighbours k - 1 and
    k + 1 have a mean eps below 0.5, k >= 1. In each layer the fluid's steady balance holds for
    the eps-weighted mean of the cell gradients, sum eps g = the drag; the layer-mean gradient,
    which the pressure profile shows, exceeds it by -cov(eps, g) / mean(eps). Returns the spread
    of eps per cell, the mean g, the eps-weighted mean g and that excess (relative), averaged
    over the bulk layers."""
    times = [t for t in os.listdir(case) if re.fullmatch(r"[0-9.]+(e-?\d+)?", t) and t != "0"]
    last = max(times, key=float)
    nz, n = int(round(cells * 5)), cells * cells
    read = lambda name: read_internal(os.path.join(case, last, name)).reshape(nz, n)
    p, e, k = read("p") * cs.RHO_F, read("voidfraction"), read("Ksl")
    r = (k / (cs.RHO_F * e * e)).reshape(nz, cells, cells)  # [z, y, x]
    r = ((r + np.roll(r, 1, 1) + np.roll(r, -1, 1) + np.roll(r, 1, 2) + np.roll(r, -1, 2)) / 5).reshape(nz, n)
    rows = []
    for z in range(1, nz - 1):
        if max(e[z - 1].mean(), e[z].mean(), e[z + 1].mean()) >= 0.5:
            continue
        if face_pressure == "dragSeries":
            face = lambda a, b: (r[b] * p[a] + r[a] * p[b]) / (r[a] + r[b])
            g = -(face(z, z + 1) - face(z - 1, z)) / h
        else:
            g = -(p[z + 1] - p[z - 1]) / (2 * h)
        ez = e[z]
        cov = np.mean((ez - ez.mean()) * (g - g.mean()))
        rows.append((ez.std(), g.mean(), np.mean(ez * g) / ez.mean(), -cov / ez.mean() / g.mean()))
    return np.mean(np.array(rows), axis=0) if rows else None


def inlet_pressure(case):
    """The area-averaged inlet pressure [Pa] at the last time step."""
    rows = np.loadtxt(glob.glob(os.path.join(case, "postProcessing", "inletPressure", "*",
                                             "surfaceFieldValue.dat"))[0])
    return cs.RHO_F * rows[-1, 1]


def imbalance(case):
    text = open(os.path.join(case, "log.grainFoam")).read()
    return max(float(x) for x in re.findall(r"relative imbalance (\S+)", text))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--laws", default="gidaspow,koch_hill")
    ap.add_argument("--cells", default="6,4,3")
    ap.add_argument("--surface", default="cell")
    ap.add_argument("--pressure", default="linear")
    ap.add_argument("--ranks", type=int, default=1)
    ap.add_argument("--bandwidth", type=float, default=0.0,
                    help="couplingProperties diffusionBandwidth b in particle diameters (0: none)")
    ap.add_argument("--profile", action="store_true")
    ap.add_argument("--plot", default="")
    ap.add_argument("--check", type=float, default=0)
    ap.add_argument("--end", type=float, default=0.06)
    ap.add_argument("--footprint", default="divided", help="couplingProperties voidFraction")
    ap.add_argument("--model", default="A", choices=("A", "B"), help="the scene's fluid model")
    ap.add_argument("--pour-seed", type=int, default=7,
                    help="the pour's fill seed (7: ergunPackedBed's; another: another pour of the bed)")
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "accuracy_cost", "bed_surface"))
    ap.add_argument("--build", default=os.environ.get("GRAINFLOW_BUILD_DIR", os.path.join(ROOT, "build")))
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    started = time.time()
    snapshot = cs.pour(args.work, args.build, args.pour_seed)
    d, eps, height, top, solid = bed_geometry(snapshot)
    print(f"bed_surface: {solid / (math.pi * d**3 / 6):.0f} particles, d = {d * 1e3:.3f} mm, core eps = "
          f"{eps:.4f}, mass-equivalent height {height * 1e3:.2f} mm, highest particle top "
          f"{top * 1e3:.2f} mm", flush=True)
    ok = True
    rows, profiles = [], []
    for law in args.laws.split(","):
        gradient = closed_form_gradient(law, eps, d)
        reference = gradient * height
        for cells in (int(c) for c in args.cells.split(",")):
            h = 0.012 / cells
            for surface in args.surface.split(","):
                name = ((f"seed{args.pour_seed}_" if args.pour_seed != 7 else "") + f"bed_{law}_c{cells}_{surface}"
                        + (f"_{args.footprint}" if args.footprint != "divided" else "")
                        + (f"_model{args.model}" if args.model != "A" else "")) + (f"_{args.pressure}" if args.pressure != "linear" else "") + (f"_b{args.bandwidth:g}" if args.bandwidth else "") + (f"_np{args.ranks}" if args.ranks > 1 else "")
                case = cs.bed_case(args.work, name, snapshot, cells, args.footprint, "cell", 20, u=U_S,
                                   end=args.end)
                cs.sub(f"{case}/particles.yaml", r"^  drag: \S+", f"  drag: {law}")
                if args.model != "A":
                    cs.sub(f"{case}/particles.yaml", r"^  model: A", f"  model: {args.model}")
                cs.sub(f"{case}/system/controlDict", r"^writeInterval .*?;", f"writeInterval {args.end / 2:g};")
                if surface != "cell":
                    with open(f"{case}/constant/couplingProperties", "a") as f:
                        f.write(f"dragVoidFraction {surface};\n")
                if args.pressure != "linear":
                    with open(f"{case}/constant/couplingProperties", "a") as f:
                        f.write(f"facePressure {args.pressure};\n")
                if args.bandwidth:
                    with open(f"{case}/constant/couplingProperties", "a") as f:
                        f.write(f"diffusionBandwidth {args.bandwidth * d:.12g};\n")
                cost = run_case(case, args.build, name, args.ranks)
                dp = cs.bed_dp(case, args.end / 2)
                worst = imbalance(case)
                error = dp / reference - 1
                row = dict(law=law, cells=cells, cell_over_d=round(h / d, 3), surface=surface,
                           face_pressure=args.pressure,
                           ranks=args.ranks, dp=dp, reference=reference, error=error,
                           imbalance=worst, **cost)
                rows.append(row)
                print(f"  {name}: dp = {dp:.2f} Pa, closed form {reference:.2f} Pa, error "
                      f"{100 * error:+.2f} %, exchange imbalance {worst:.1e}, coupling "
                      f"{cost['coupling_s']:.2f} s, cpu {cost['cpu_s']:.1f} s", flush=True)
                if args.check and surface != "cell":
                    good = abs(error) <= args.check / 100 and worst < 1e-12
                    ok &= good
                    print(f"    within {args.check:g} % and balanced to 1e-12: {'ok' if good else 'FAILED'}")
                if args.profile or args.plot:
                    p, e_cell = layer_profile(case, cells)
                    p_inlet = inlet_pressure(case)
                    label = surface + (f" + {args.pressure}" if args.pressure != "linear" else "")
                    profiles.append((law, cells, label, h, p, e_cell, p_inlet, gradient, height))
                    print_profile(law, d, h, p, e_cell, p_inlet, gradient, height)
                    bulk = bulk_gradients(case, cells, h, args.pressure)
                    if bulk is not None:
                        print(f"    bulk layers, cell gradients ({args.pressure}): eps spread per "
                              f"cell {bulk[0]:.3f}; -dp/dz layer mean {bulk[1]:.0f} Pa/m, "
                              f"eps-weighted (the drag's balance) {bulk[2]:.0f} Pa/m; layer mean "
                              f"above it by -cov(eps, g)/(eps g) = {100 * bulk[3]:+.2f} %")
    out = os.path.join(args.work, "bed_surface.csv")
    new = not os.path.exists(out)
    with open(out, "a", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        if new:
            w.writeheader()
        w.writerows(rows)
    if args.plot:
        plot(args.plot, profiles, d)
    print(f"bed_surface: {len(rows)} runs in {time.time() - started:.0f} s -> {out}")
    return 0 if ok else 1


def run_case(case, build, name, ranks):
    if ranks == 1:
        return cs.run(case, build, name)
    import subprocess
    env = dict(os.environ, LD_LIBRARY_PATH=os.path.join(build, "lib"),
               OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    cs.sub(f"{case}/system/decomposeParDict", r"^numberOfSubdomains .*?;", f"numberOfSubdomains {ranks};")
    cs.sub(f"{case}/system/decomposeParDict", r"n\s*\(\d+ 1 1\);", f"n ({ranks} 1 1);")
    for cmd, log in ((["blockMesh"], "log.blockMesh"), (["decomposePar", "-force"], "log.decomposePar"),
                     (["mpirun", "--oversubscribe", "-np", str(ranks),
                       os.path.join(build, "bin", "grainFoam"), "-parallel"], "log.grainFoam"),
                     (["reconstructPar", "-latestTime"], "log.reconstructPar")):
        with open(os.path.join(case, log), "w") as out:
            rc = subprocess.call([cs.FOAM] + cmd, cwd=case, stdout=out, stderr=subprocess.STDOUT, env=env)
        if rc != 0:
            sys.exit(f"bed_surface: {name}: {cmd[0]} failed, see {case}/{log}")
    text = open(os.path.join(case, "log.grainFoam")).read()
    cs.finished(text, case, name)
    split = re.findall(r"grainFoam time split: DEM (\S+) s .*?coupling (\S+) s .*?fluid (\S+) s", text)
    cpu = re.findall(r"ExecutionTime = (\S+) s", text)
    dem, coupling, fluid = (float(x) for x in split[-1])
    return {"dem_s": dem, "coupling_s": coupling, "fluid_s": fluid, "cpu_s": float(cpu[-1])}


def print_profile(law, d, h, p, e_cell, p_inlet, gradient, height):
    """dp/dz across each face between cell layers (from the layer means on either side)
    against the closed form over the same span [z_f - h/2, z_f + h/2], and each span's share
    of the difference; the first span runs from the inlet (area-averaged p there) to the
    first layer centre."""
    print(f"    face z/d   eps below/above  -dp/dz measured / closed form [Pa/m]"
          f"  (law at the two cells' mean eps)  difference x span [Pa]")
    spans = [(0.0, h / 2, p_inlet - p[0], e_cell[0], e_cell[0])]
    for k in range(len(p) - 1):
        spans.append(((k + 0.5) * h, (k + 1.5) * h, p[k] - p[k + 1], e_cell[k], e_cell[k + 1]))
    total = 0.0
    for z0, z1, drop, e0, e1 in spans:
        if z0 > height + 2 * h:
            break
        inside = max(0.0, min(z1, height) - z0) / (z1 - z0)
        closed = gradient * inside
        mean_eps = 0.5 * (e0 + e1)
        local = closed_form_gradient(law, mean_eps, d) if mean_eps < 0.999 else 0.0
        diff = drop - closed * (z1 - z0)
        total += diff
        print(f"    {0.5 * (z0 + z1) / d:6.2f}    {e0:.3f} / {e1:.3f}     {drop / (z1 - z0):9.0f} / "
              f"{closed:9.0f}            ({local:9.0f})                {diff:+7.2f}")
    print(f"    sum of the differences {total:+.2f} Pa")


def plot(path, profiles, d):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=80)
    height = profiles[0][-1]
    for i, (law, cells, surface, h, p, e_cell, p_inlet, gradient, _) in enumerate(profiles):
        zf = np.concatenate(([h / 4], np.arange(1, len(p)) * h))
        grad = np.concatenate(([(p_inlet - p[0]) / (h / 2)], -np.diff(p) / h))
        keep = zf < height + 3 * h
        line, = ax.plot(zf[keep] / d, grad[keep] / gradient, "o-", ms=4,
                        label=f"{law}, cells {h / d:g} d, {surface}")
        # The closed form over the same spans: the fraction of each span below the bed's
        # mass-equivalent height (the first span from the inlet to the first cell centre).
        lo = np.concatenate(([0.0], zf[1:] - h / 2))
        hi = np.concatenate(([h / 2], zf[1:] + h / 2))
        inside = np.clip((height - lo) / (hi - lo), 0, 1)
        same = any(q[3] == h for q in profiles[:i])
        if not same:
            ax.plot(zf[keep] / d, inside[keep], "--", lw=1, color="k" if len({q[3] for q in profiles}) == 1 else line.get_color(),
                    label=f"closed form over the same spans ({h / d:g} d)")
    ax.axvline(height / d, color="k", ls=":", lw=1)
    ax.set_xlabel("z / d  (dotted: the bed's mass-equivalent height)")
    ax.set_ylabel("-dp/dz / closed form at the core eps")
    ax.set_ylim(-0.05, 1.3)
    ax.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    fig.savefig(path)


if __name__ == "__main__":
    sys.exit(main())
