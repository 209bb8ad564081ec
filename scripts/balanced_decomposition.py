#!/usr/bin/env python3
"""A shared decomposition weighted by particle count, for grainFoam (docs/parallel.md,
"Coupled runs: a bed settled at the bottom of a tall column").

grainFoam's DEM takes its processor grid from the fluid mesh's decomposition, so `simple`
cuts a tall column along z into slabs of equal cell counts, and a bed settled at the bottom
lands on one rank. This script keeps the decomposition shared and box-shaped (what grainFoam
requires) but places the cut planes along one axis so that each slab carries the same
estimated work:

    work(slab) = cells(slab) + w * particles(slab)

with w the cost of one particle in cells (from a run's own log: --weight-from LOG, the DEM's
working seconds per particle over the fluid's seconds per cell; or given: --particle-cost w).
It writes constant/cellDecomposition and a decomposeParDict for OpenFOAM's `manual` method, and prints cells, particles and estimated work per rank for the
weighted cuts and for equal slabs:

    balanced_decomposition.py CASE --ranks 2 --axis z --particles SNAPSHOT.h5|FILE.csv
                              (--particle-cost W | --weight-from LOG.grainFoam)
                              [--dict system/decomposeParDict.balanced]
    decomposePar -case CASE -decomposeParDict system/decomposeParDict.balanced
    mpirun -np 2 grainFoam -case CASE -parallel -decomposeParDict system/decomposeParDict.balanced

The cell centres come from OpenFOAM's `postProcess -func writeCellCentres`, run on a copy of
the mesh in a temporary folder (the case itself gains only the two files written). Cuts lie
between layers of cell centres, so the mesh must be layered along the axis (any block mesh
of boxes is). The particles are where the chosen file has them: give a snapshot of the bed as
the run will mostly see it (for a bed poured at the start, a snapshot after it settled).
"""
import argparse
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
AXES = {"x": 0, "y": 1, "z": 2}


def fail(message):
    sys.exit(f"balanced_decomposition.py: error: {message}")


def foam_list(text, what):
    """The numbers of an OpenFOAM ASCII list field file (internalField nonuniform List<...>)."""
    m = re.search(r"internalField\s+nonuniform\s+List<(\w+)>\s*(\d+)\s*\(", text)
    if not m:
        fail(f"cannot read the cell centres from {what} (expected an ASCII nonuniform list)")
    n = int(m.group(2))
    body = text[m.end():]
    if m.group(1) == "vector":
        rows = re.findall(r"\(\s*([-+0-9.eE]+)\s+([-+0-9.eE]+)\s+([-+0-9.eE]+)\s*\)", body)[:n]
        return np.array(rows, dtype=float)
    fail(f"{what}: expected a vector field, found List<{m.group(1)}>")


def cell_centres(case):
    """Cell centres of CASE's mesh (constant/polyMesh), computed by OpenFOAM on a copy."""
    mesh = case / "constant" / "polyMesh"
    if not (mesh / "owner").exists():
        fail(f"{mesh}: no mesh (run blockMesh first)")
    with tempfile.TemporaryDirectory(prefix="balanced_decomposition_") as tmp:
        t = pathlib.Path(tmp)
        (t / "system").mkdir()
        (t / "constant").mkdir()
        shutil.copytree(mesh, t / "constant" / "polyMesh")
        control = (case / "system" / "controlDict").read_text()
        # ASCII output, whatever the case writes, so that the centres can be parsed here.
        control = re.sub(r"^writeFormat\s+\w+;", "writeFormat ascii;", control, flags=re.M)
        if "writeFormat" not in control:
            control += "\nwriteFormat ascii;\n"
        (t / "system" / "controlDict").write_text(control)
        for name in ("fvSchemes", "fvSolution"):
            if (case / "system" / name).exists():
                shutil.copy(case / "system" / name, t / "system" / name)
        res = subprocess.run([str(ROOT / "scripts" / "foam_env.sh"), "postProcess", "-case", str(t),
                              "-func", "writeCellCentres", "-constant"],
                             capture_output=True, text=True)
        found = sorted(t.glob("*/C"))
        if res.returncode != 0 or not found:
            fail("OpenFOAM's postProcess -func writeCellCentres failed:\n" + res.stdout[-2000:] + res.stderr[-2000:])
        return foam_list(found[0].read_text(), "writeCellCentres' C")


def particle_positions(path):
    path = pathlib.Path(path)
    if not path.exists():
        fail(f"{path}: no such file (--particles: a grainflow snapshot .h5 or a CSV with x,y,z columns)")
    if path.suffix == ".h5":
        import h5py
        with h5py.File(path, "r") as f:
            if "position" not in f:
                fail(f"{path}: no dataset 'position' (not a grainflow snapshot)")
            return f["position"][...]
    # grain's CSV insertion format: '#' comment lines, then a header naming the columns.
    lines = [line for line in path.read_text().splitlines()
             if line.strip() and not line.lstrip().startswith("#")]
    head = [c.strip() for c in lines[0].split(",")] if lines else []
    try:
        cols = [head.index(c) for c in ("x", "y", "z")]
    except ValueError:
        fail(f"{path}: the CSV header needs columns x, y and z (found: {','.join(head)})")
    return np.loadtxt(lines[1:], delimiter=",", usecols=cols, ndmin=2)


def weight_from_log(log, cells):
    """Particle cost in cells from a grainFoam log of this case: the DEM's working seconds
    per particle over the fluid's seconds per cell, both summed over the ranks and over the
    run. A parallel run's log has a line per rank at each write time ("grainFoam rank R since
    the last write: N particles; DEM W s working + X s waiting for other ranks, coupling C s,
    fluid F s"), whose working time leaves out the time a rank waited for the others, so the
    estimate does not depend on how that run was decomposed; a serial run's log has the
    whole-run split ("grainFoam time split: DEM D s ... fluid F s") and its particle count."""
    text = pathlib.Path(log).read_text()
    per_rank = re.findall(r"^grainFoam rank (\d+) since the last write: (\d+) particles; "
                          r"DEM ([0-9.e+-]+) s working \+ [0-9.e+-]+ s waiting for other ranks, "
                          r"coupling [0-9.e+-]+ s, fluid ([0-9.e+-]+) s", text, re.M)
    if per_rank:
        dem = sum(float(v[2]) for v in per_rank)
        fluid = sum(float(v[3]) for v in per_rank)
        # Particles: the total at each write (the lines of rank 0 start each write's group),
        # averaged over the writes, as the DEM's time is summed over them.
        totals, current = [], 0
        for rank, n, _, _ in per_rank:
            if int(rank) == 0 and current:
                totals.append(current)
                current = 0
            current += int(n)
        totals.append(current)
        n = sum(totals) / len(totals)
        source = f"{len(totals)} write(s) of {max(int(v[0]) for v in per_rank) + 1} ranks"
    else:
        splits = re.findall(r"^grainFoam time split: DEM ([0-9.e+-]+) s .*?fluid ([0-9.e+-]+) s",
                            text, re.M)
        counts = re.findall(r"^grainFoam particles: (\d+) particles", text, re.M)
        if not splits or not counts:
            fail(f"{log}: neither 'grainFoam rank ...' lines nor a 'grainFoam time split' and a "
                 "'grainFoam particles' line (a grainFoam log that reached a write time is needed)")
        procs = re.search(r"^nProcs\s*:\s*(\d+)", text, re.M)
        if procs and int(procs.group(1)) > 1:
            fail(f"{log}: a parallel run without the per-rank lines 'grainFoam rank ...' (written "
                 "by a grainFoam older than them); give --particle-cost, or a serial run's log")
        dem, fluid = (float(v) for v in splits[-1])
        n = int(counts[-1])
        source = "the serial run's time split"
    if dem <= 0 or fluid <= 0 or n <= 0:
        fail(f"{log}: the time split has no DEM or fluid time, or no particles")
    w = (dem / n) / (fluid / cells)
    return w, f"from {log} ({source}: DEM {dem:.4g} s for {n:.0f} particles, fluid {fluid:.4g} s " \
              f"for {cells} cells)"


def choose_cuts(layer_work, ranks):
    """Indices k (cut after layer k-1) of ranks-1 cuts between layers, so that the largest
    slab's work is as small as a cut between layers allows (binary search on the bound)."""
    work = np.asarray(layer_work, dtype=float)
    if len(work) < ranks:
        fail(f"the mesh has {len(work)} cell layers along the axis, fewer than {ranks} ranks")

    def greedy(bound):
        cuts, acc = [], 0.0
        for k, w in enumerate(work):
            if acc + w > bound and acc > 0:
                cuts.append(k)
                acc = 0.0
            acc += w
        return cuts if len(cuts) <= ranks - 1 else None

    lo, hi = work.max(), work.sum()
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if greedy(mid) is None:
            lo = mid
        else:
            hi = mid
    return fill_cuts(greedy(hi), len(work), ranks)


def feasible(parts, bounds, ranks):
    """Cuts of at most ranks slabs whose sums of each row of parts stay within bounds, or
    None. Greedy, each slab as long as every sum allows: with sums that only grow as a slab
    grows, a slab ending later never leaves more for the rest, so greedy finds cuts whenever
    any exist."""
    cuts, acc = [], np.zeros(len(parts))
    for k in range(parts.shape[1]):
        col = parts[:, k]
        if np.any(col > bounds):
            return None
        if np.any(acc + col > bounds):
            cuts.append(k)
            acc = np.zeros(len(parts))
        acc = acc + col
    return cuts if len(cuts) <= ranks - 1 else None


def choose_cuts_phases(dem, fluid, ranks):
    """Cuts for the least max(slab's DEM work) + max(slab's fluid work): the DEM and the fluid
    each wait for their busiest rank (grainFoam runs them one after the other, each with
    collectives), so the run's time is the sum of the two maxima. Every bound on the DEM's
    maximum that a contiguous slab can give is tried, with the least fluid bound found by
    bisection over the fluid's contiguous sums."""
    dem = np.asarray(dem, dtype=float)
    fluid = np.asarray(fluid, dtype=float)
    n = len(dem)
    if n < ranks:
        fail(f"the mesh has {n} cell layers along the axis, fewer than {ranks} ranks")

    def sums(v):
        c = np.concatenate([[0.0], np.cumsum(v)])
        return np.unique((c[None, :] - c[:, None])[np.triu_indices(n + 1, 1)])

    dem_bounds = sums(dem)
    fluid_bounds = sums(fluid)
    parts = np.vstack([dem, fluid])
    best = None
    for bd in dem_bounds[dem_bounds >= dem.max() - 1e-12]:
        lo, hi = 0, len(fluid_bounds) - 1
        if feasible(parts, np.array([bd, fluid_bounds[hi]]) * (1 + 1e-12), ranks) is None:
            continue
        while lo < hi:
            mid = (lo + hi) // 2
            if feasible(parts, np.array([bd, fluid_bounds[mid]]) * (1 + 1e-12), ranks) is None:
                lo = mid + 1
            else:
                hi = mid
        cuts = feasible(parts, np.array([bd, fluid_bounds[lo]]) * (1 + 1e-12), ranks)
        cuts = fill_cuts(cuts, n, ranks)
        cost = phase_time(dem, fluid, cuts)
        if best is None or cost < best[0] - 1e-12:
            best = (cost, cuts)
    return best[1]


def fill_cuts(cuts, n_layers, ranks):
    """Fewer cuts than ranks - 1 (a few heavy layers): split the largest slabs further."""
    cuts = list(cuts)
    while len(cuts) < ranks - 1:
        bounds = [0] + cuts + [n_layers]
        spans = [(bounds[i + 1] - bounds[i], i) for i in range(len(bounds) - 1)]
        size, i = max(spans)
        if size < 2:
            fail("cannot place a cut: every slab is one cell layer thick")
        cuts = sorted(cuts + [bounds[i] + size // 2])
    return cuts


def phase_time(dem, fluid, cuts):
    """max over slabs of the DEM work + max over slabs of the fluid work."""
    spans = slabs(cuts, len(dem))
    return max(dem[b:e].sum() for b, e in spans) + max(fluid[b:e].sum() for b, e in spans)


def slabs(cuts, n_layers):
    bounds = [0] + list(cuts) + [n_layers]
    return [(bounds[i], bounds[i + 1]) for i in range(len(bounds) - 1)]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case", help="the OpenFOAM case folder (meshed)")
    ap.add_argument("--ranks", type=int, required=True)
    ap.add_argument("--axis", choices=sorted(AXES), required=True, help="the axis the cut planes are normal to")
    ap.add_argument("--particles", required=True, help="a grainflow snapshot (.h5) or a CSV with x,y,z")
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--particle-cost", type=float, help="the work of one particle in cells (> 0)")
    g.add_argument("--weight-from", help="a grainFoam log of this case: w from its time split")
    ap.add_argument("--objective", choices=["phases", "sum"], default="phases",
                    help="phases (default): least busiest-DEM + busiest-fluid work; sum: the "
                         "largest slab's cells + w particles least")
    ap.add_argument("--dict", default="system/decomposeParDict.balanced",
                    help="the decomposeParDict to write, relative to the case (default %(default)s)")
    args = ap.parse_args()
    if args.ranks < 2:
        fail(f"--ranks {args.ranks}: give 2 or more")
    if args.particle_cost is not None and not args.particle_cost > 0:
        fail(f"--particle-cost {args.particle_cost}: give a number > 0")
    case = pathlib.Path(args.case).resolve()
    a = AXES[args.axis]

    centres = cell_centres(case)
    n_cells = len(centres)
    x = particle_positions(args.particles)
    if args.particle_cost is not None:
        w, w_source = args.particle_cost, "given (--particle-cost)"
    else:
        w, w_source = weight_from_log(args.weight_from, n_cells)

    # Layers: cell centres along the axis, equal to 1e-9 of the extent.
    c = centres[:, a]
    span = max(c.max() - c.min(), 1e-300)
    levels = np.unique(np.round((c - c.min()) / span * 1e9))
    layer_of_cell = np.searchsorted(levels, np.round((c - c.min()) / span * 1e9))
    coords = c.min() + levels / 1e9 * span
    n_layers = len(levels)
    # A particle belongs to the layer whose centre band holds it (bands end halfway between
    # neighbouring centres).
    edges = 0.5 * (coords[1:] + coords[:-1])
    layer_of_particle = np.searchsorted(edges, x[:, a])
    cells_per_layer = np.bincount(layer_of_cell, minlength=n_layers).astype(float)
    particles_per_layer = np.bincount(layer_of_particle, minlength=n_layers).astype(float)
    work = cells_per_layer + w * particles_per_layer
    dem_work = w * particles_per_layer
    if args.objective == "sum":
        cuts = choose_cuts(work, args.ranks)
    else:
        cuts = choose_cuts_phases(dem_work, cells_per_layer, args.ranks)

    def describe(name, cut_list):
        rows = []
        for r, (b, e) in enumerate(slabs(cut_list, n_layers)):
            rows.append((cells_per_layer[b:e].sum(), particles_per_layer[b:e].sum(), work[b:e].sum()))
        mean = sum(r[2] for r in rows) / len(rows)
        print(f"{name}: " + "; ".join(f"rank {r}: {int(cl)} cells, {int(p)} particles, work {wk:.4g}"
                                      for r, (cl, p, wk) in enumerate(rows))
              + f"; busiest / mean work {max(r[2] for r in rows) / mean:.3f}; estimated time "
              f"(busiest DEM + busiest fluid) {phase_time(dem_work, cells_per_layer, cut_list):.4g}")

    equal = [round(k * n_layers / args.ranks) for k in range(1, args.ranks)]
    print(f"{n_cells} cells in {n_layers} layers along {args.axis}, {len(x)} particles, "
          f"particle cost w = {w:.4g} cells, {w_source}")
    describe("equal slabs (method simple)", equal)
    describe(f"chosen cuts (--objective {args.objective})", cuts)
    planes = [0.5 * (coords[k - 1] + coords[k]) for k in cuts]
    print("cut planes at " + args.axis + " = " + ", ".join(f"{p:.6g}" for p in planes) + " m")

    rank_of_layer = np.zeros(n_layers, dtype=int)
    for r, (b, e) in enumerate(slabs(cuts, n_layers)):
        rank_of_layer[b:e] = r
    owner = rank_of_layer[layer_of_cell]
    header = ("FoamFile\n{{\n    version     2.0;\n    format      ascii;\n    class       {cls};\n"
              "    location    \"{loc}\";\n    object      {obj};\n}}\n")
    body = "\n".join(str(v) for v in owner)
    (case / "constant" / "cellDecomposition").write_text(
        header.format(cls="labelList", loc="constant", obj="cellDecomposition")
        + f"// written by scripts/balanced_decomposition.py: cuts along {args.axis}, w = {w:.6g}\n"
        + f"{n_cells}\n(\n{body}\n)\n")
    dict_path = case / args.dict
    dict_path.write_text(
        header.format(cls="dictionary", loc="system", obj="decomposeParDict")
        + f"// written by scripts/balanced_decomposition.py: {args.ranks} slabs along {args.axis}\n"
        + f"// weighted by particle count (w = {w:.6g} cells per particle); cut planes at\n"
        + "// " + ", ".join(f"{p:.6g}" for p in planes) + " m\n"
        + f"numberOfSubdomains {args.ranks};\nmethod          manual;\n"
        + "coeffs          { dataFile \"cellDecomposition\"; }\n")
    print(f"wrote {case / 'constant' / 'cellDecomposition'} and {dict_path}")


if __name__ == "__main__":
    main()
