#!/usr/bin/env python3
"""Coupled hard cases of the stress suite (tests/coupling_stress/tests.cmake).

    stress_cases.py TEST --foam-env scripts/foam_env.sh --solver bin/grainFoam
                         --mpiexec mpiexec --lib-dir <build>/lib
                         --cases tests/coupling_stress/cases --work <scratch>

TEST is one of the functions in TESTS below; each copies a case from
tests/coupling_stress/cases/ into <scratch>, edits it (the edits are listed in the test),
runs the OpenFOAM programs through foam_env.sh and checks invariants that hold whatever
the flow does:

  dense_bed_10x_umf            a packed bed hit by 10 U_mf at once: finite, nothing lost,
                               nothing through the distributor;
  particles_larger_than_cells  d / dx = 0.5, 1, 2, 3: eps in [minVoidFraction, 1], the
                               volume check (clamped volume counted), clamps reported;
  on_faces_and_corners_2ranks  beads centred exactly on cell faces, edges, corners and the
                               processor plane: 2 ranks give the 1-rank eps to 1e-12.
  crowded_cell_2ranks          27 beads in one cell: eps = minVoidFraction there, the
                               clamped volume to the closed form; 2 ranks = 1 rank;
  emptied_and_refilled_cells   a slab launched round a periodic box: every cell emptied
                               and refilled >= 4 times, eps exactly 1 when empty;
  fast_crossing_ranks          the slab on 1, 2, 4 ranks: ranks empty at times, nothing
                               lost, agreement with 1 rank within a stated bound.

Every run is also checked for: no nan/inf in the log, the snapshots or the written
voidfraction; particle count conserved with none removed; every printed relative volume
difference and exchange imbalance < 1e-12.

Exit status 0 when every check holds; otherwise each failed check is printed and the exit
status is 1. Logs stay in the case folders (log.<program>). Shared helpers:
tests/support/grainfoam_driver.py.
"""
import math
import os
import re
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from grainfoam_driver import (ROUND_OFF, NAN_WORD, balance_lines, main, particle_lines,  # noqa: E402
                              read_scalar_field, snapshots, time_folders, void_lines)


# benchmarks/hard_cases/coupled/run.sh: GRAINFLOW_STRESS_SCALE=N runs the cases that evolve
# in time (dense bed, convected slab) N times longer, with the same checks at every write.
SCALE = float(os.environ.get("GRAINFLOW_STRESS_SCALE", "1"))


def longer(end_time):
    """The controlDict edit that runs a case SCALE times longer (none at scale 1)."""
    if SCALE == 1:
        return []
    return [("system/controlDict", f"endTime         {end_time};",
             f"endTime         {end_time * SCALE:g};")]


def check_run(checks, label, case, log, count, min_eps, cell_volume=None):
    """The invariants every run must keep. Returns ({folder: eps}, snapshots, void lines).
    cell_volume: when given (uniform mesh), sum (1 - eps) V + clamped is recomputed from
    each written voidfraction and compared with the snapshot's particle volume."""
    bad = sorted(set(m.group(0).lower() for m in NAN_WORD.finditer(log)))
    checks.expect(not bad, f"{label}: no nan/inf in the log (found {bad})")
    lines = void_lines(log)
    checks.expect(len(lines) > 0, f"{label}: {len(lines)} void fraction lines")
    worst = max((l[3] for l in lines), default=float("nan"))
    checks.expect(worst < ROUND_OFF, f"{label}: printed volume relative difference, worst of "
                                     f"{len(lines)}: {worst:.3g} < 1e-12")
    bal = balance_lines(log)
    worst_bal = max((b[2] for b in bal), default=float("nan"))
    checks.expect(len(bal) > 0 and worst_bal < ROUND_OFF,
                  f"{label}: exchange relative imbalance, worst of {len(bal)}: "
                  f"{worst_bal:.3g} < 1e-12")
    plines = particle_lines(log)
    checks.expect(len(plines) > 0 and all(n == count and removed == 0 for n, removed, _ in plines),
                  f"{label}: {count} particles and none removed on all {len(plines)} lines "
                  f"(counts {sorted(set(p[0] for p in plines))}, removed "
                  f"{max((p[1] for p in plines), default=-1)})")
    snaps = snapshots(case)
    finite = all(np.all(np.isfinite(s[k])) for _, s in snaps for k in ("position", "velocity"))
    counts = sorted(set(len(s["id"]) for _, s in snaps))
    checks.expect(len(snaps) > 0 and finite and counts == [count],
                  f"{label}: {len(snaps)} snapshots, finite positions and velocities: {finite}, "
                  f"particle counts {counts}")
    eps = {}
    folders = time_folders(case)
    checks.expect(len(folders) > 0, f"{label}: {len(folders)} written voidfraction fields")
    lo, hi = 1.0, 0.0
    for folder in folders:
        field = read_scalar_field(os.path.join(case, folder, "voidfraction"))
        eps[folder] = field
        if not np.all(np.isfinite(field)):
            checks.expect(False, f"{label}, t = {folder}: voidfraction is not finite")
            continue
        lo, hi = min(lo, float(field.min())), max(hi, float(field.max()))
    # The field is written with 17 significant digits: a clamped cell reads back as
    # minVoidFraction exactly, an empty one as 1 exactly. No tolerance is needed.
    checks.expect(lo >= min_eps and hi <= 1.0,
                  f"{label}: eps in [{lo:.17g}, {hi:.17g}] within [{min_eps}, 1] in all "
                  f"{len(folders)} written fields")
    if cell_volume is not None:
        by_time = {round(t, 9): s for t, s in snaps}
        # The log prints a void fraction line at the first step and at every write; the
        # write-time lines are the last len(folders) ones.
        for folder, line in zip(folders, lines[-len(folders):]):
            s = by_time.get(round(float(folder), 9))
            if s is None:
                checks.expect(False, f"{label}, t = {folder}: a snapshot at the write time")
                continue
            vp = float(np.sum(4.0 / 3.0 * math.pi * s["radius"] ** 3))
            solid = float(np.sum((1 - eps[folder]) * cell_volume)) + line[1]
            checks.expect(abs(solid - vp) <= ROUND_OFF * vp,
                          f"{label}, t = {folder}: from the written field, sum (1-eps) V + "
                          f"clamped {line[1]:.3g} = {solid:.17g} m^3 vs sum V_p {vp:.17g} m^3, "
                          f"relative difference {abs(solid - vp) / vp:.3g}")
    return eps, snaps, lines


# --- coupling_stress.dense_bed_10x_umf --------------------------------------------------

BED_COUNT = 300        # cases/dense_bed/bed.csv
BED_TOP = 0.03         # lid and outlet, system/blockMeshDict
MAX_OVERLAP = 0.25     # time.max_overlap, default (docs/scene-reference.md)


def dense_bed_10x_umf(runner, checks):
    """300 beads, d = 1 mm, eps = 0.39 at rest on the distributor; 10 ms later the gas
    jumps from 0 to 5.4 m/s superficial (10 U_mf) within one fluid step. The Ergun
    pressure gradient of the packed bed is then 6.6e5 Pa/m against a bed weight of
    1.5e4 Pa/m: the bed is thrown at the lid as a plug. The drag is implicit in each DEM
    step, so this must stay finite with dt_DEM = 1e-5 s, 5 DEM steps per fluid step.
    Checked at every write (5 ms): the common invariants, every bead above the
    distributor by no more than max_overlap r (z - r > -0.25 r) and below the lid alike,
    and the bed really moved (its centre of mass rose by > 1 mm after the switch-on: the
    gas is on and strong)."""
    case = runner.fresh_case("dense_bed", "dense_bed", longer(0.04))
    t0 = time.monotonic()
    log = runner.solve(case, 1)
    print(f"  grainFoam wall time {time.monotonic() - t0:.1f} s")
    _, snaps, _ = check_run(checks, "dense bed", case, log, BED_COUNT, 0.3)
    low, high, rise, speed = np.inf, -np.inf, 0.0, 0.0
    z_rest = None
    for t, s in snaps:
        z, r = s["position"][:, 2], s["radius"]
        low = min(low, float(np.min((z - r) / r)))
        high = max(high, float(np.max((z + r - BED_TOP) / r)))
        speed = max(speed, float(np.max(np.linalg.norm(s["velocity"], axis=1))))
        if abs(t - 0.01) < 1e-9:
            z_rest = float(np.mean(z))
        elif z_rest is not None:
            rise = max(rise, float(np.mean(z)) - z_rest)
    checks.expect(low > -MAX_OVERLAP, f"lowest bead bottom (z - r)/r = {low:.4g} > -{MAX_OVERLAP}")
    checks.expect(high < MAX_OVERLAP, f"highest bead top (z + r - lid)/r = {high:.4g} < {MAX_OVERLAP}")
    checks.expect(z_rest is not None and rise > 1e-3,
                  f"bed centre of mass rose by {rise * 1e3:.3g} mm after the switch-on (> 1 mm); "
                  f"largest bead speed {speed:.3g} m/s")


# --- coupling_stress.particles_larger_than_cells ----------------------------------------

SMALL_BOX = 0.012
LARGE_COUNT = 150
LARGE_D = 1.5e-3


def particles_larger_than_cells(runner, checks):
    """150 beads of d = 1.5 mm in a 12 mm box of n^3 cells, n = 4, 8, 16, 24:
    d / dx = 0.5, 1, 2, 3. `smoothed` at every ratio, `centre` at d / dx = 3 (one cell
    would hold 14 times its volume in particle: clamps are certain). For each: the common
    invariants; sum (1 - eps) V + clamped = sum V_p recomputed from every written field;
    with centre the log counts clamped cell-steps > 0 and a clamped volume > 0."""
    runs = [("smoothed", 4), ("smoothed", 8), ("smoothed", 16), ("smoothed", 24), ("centre", 24)]
    for method, n in runs:
        ratio = LARGE_D / (SMALL_BOX / n)
        label = f"{method} d/dx = {ratio:g}"
        print(f"{label}:")
        case = runner.fresh_case("large_particles", f"{method}_n{n}", [
            ("constant/couplingProperties", "voidFraction    divided;", f"voidFraction    {method};"),
            ("system/blockMeshDict", "(8 8 8)", f"({n} {n} {n})")])
        log = runner.solve(case, 1)
        _, _, lines = check_run(checks, label, case, log, LARGE_COUNT, 0.2,
                                cell_volume=(SMALL_BOX / n) ** 3)
        clamps = particle_lines(log)
        cell_steps = clamps[-1][2] if clamps else -1
        clamped_volume = max((l[1] for l in lines), default=0.0)
        print(f"  info  {label}: {cell_steps} clamped cell-steps, largest clamped volume "
              f"{clamped_volume:.3g} m^3")
        if method == "centre":
            checks.expect(cell_steps > 0 and clamped_volume > 0,
                          f"{label}: clamps reported: {cell_steps} cell-steps, clamped volume "
                          f"{clamped_volume:.3g} m^3")


# --- coupling_stress.on_faces_and_corners_2ranks ----------------------------------------

FACES_COUNT = 116      # 16 in on_faces.csv + 100 fill
FACES_CELL = 0.0025


def on_faces_and_corners_2ranks(runner, checks):
    """Beads centred exactly on cell faces, edges, corners, the processor plane x = 10 mm
    and the periodic faces (cases/faces_corners/on_faces.csv), for centre, divided and
    smoothed, on 1 and on 2 ranks (simple (2 1 1)). Fluid at rest without gravity: the
    beads stay exactly there. Then a flow of (0.05 0.02 0.01) m/s for the exchange balance
    (the beads start on the faces and move off by < 1 um). Checked: the common invariants;
    the volume recomputed from the written fields; eps(2 ranks) = eps(1 rank) to 1e-12
    (round-off: the same footprint points summed in another order) after reconstructPar;
    in the rest runs, the CSV beads are still exactly where they were put."""
    for flow in (False, True):
        methods = ("divided",) if flow else ("centre", "divided", "smoothed")
        for method in methods:
            tag = f"{method}{'_flow' if flow else ''}"
            edits = [("constant/couplingProperties", "voidFraction    divided;",
                      f"voidFraction    {method};")]
            if flow:
                edits.append(("0/U", "internalField   uniform (0 0 0);",
                              "internalField   uniform (0.05 0.02 0.01);"))
            eps = {}
            for ranks in (1, 2):
                label = f"{tag} np {ranks}"
                print(f"{label}:")
                case = runner.fresh_case("faces_corners", f"{tag}_np{ranks}", edits)
                log = runner.solve(case, ranks)
                eps[ranks], snaps, _ = check_run(checks, label, case, log, FACES_COUNT, 0.2,
                                                 cell_volume=FACES_CELL ** 3)
                if not flow and snaps:
                    csv = np.loadtxt(os.path.join(case, "on_faces.csv"), delimiter=",",
                                     comments="#", skiprows=3)
                    last = snaps[-1][1]["position"]
                    # The CSV beads are inserted first: ids 1..16 (sorted by id).
                    moved = float(np.max(np.abs(last[: len(csv)] - csv[:, :3])))
                    checks.expect(moved == 0.0, f"{label}: the {len(csv)} CSV beads stayed "
                                                f"exactly in place (moved {moved:.3g} m)")
            for folder in sorted(set(eps[1]) | set(eps[2]), key=float):
                a, b = eps[1].get(folder), eps[2].get(folder)
                if a is None or b is None or a.shape != b.shape:
                    checks.expect(False, f"{tag}, t = {folder}: voidfraction of 1 and 2 ranks")
                    continue
                diff = float(np.max(np.abs(a - b)))
                checks.expect(diff < ROUND_OFF, f"{tag}, t = {folder}: max |eps(np 1) - eps(np 2)| "
                                                f"= {diff:.3g} < 1e-12 (min eps {a.min():.4f})")


# --- coupling_stress.crowded_cell_2ranks ------------------------------------------------

CROWDED_COUNT = 27     # cases/crowded/cluster.csv: 3 x 3 x 3 beads, d = 1 mm, spacing d
CROWDED_CELL = 2.5e-3  # 4^3 cells in a 10 mm box
CROWDED_INDEX = 1 + 4 * (1 + 4 * 1)  # cell (1, 1, 1), blockMesh order i + nx (j + ny k)
CROWDED_MIN_EPS = 0.2


def crowded_cell_2ranks(runner, checks):
    """27 beads (d = 1 mm) in one 2.5 mm cell: 0.905 of the cell's volume. With `centre`
    the cell's raw void fraction is 1 - 27 V_p / V_c = 0.0952 < minVoidFraction = 0.2, so
    (closed form, no tolerance beyond round-off): eps = 0.2 exactly in that cell and 1
    exactly in every other, and the volume clamped away per step is V_c (0.2 - 0.0952).
    With `divided` the outer beads spill into the neighbours. Each on 1 and 2 ranks
    (simple (2 1 1): the processor plane is the crowded cell's upper x face, crossed by
    the outer layer's footprints). Checked: the common invariants; the volume recomputed
    from the fields with the clamped volume counted; eps(2 ranks) = eps(1 rank) to 1e-12."""
    v_p = 4.0 / 3.0 * math.pi * 0.5e-3 ** 3
    v_c = CROWDED_CELL ** 3
    raw = 1 - CROWDED_COUNT * v_p / v_c
    for method in ("centre", "divided"):
        eps = {}
        clamped = {}
        for ranks in (1, 2):
            label = f"{method} np {ranks}"
            print(f"{label}:")
            case = runner.fresh_case("crowded", f"{method}_np{ranks}", [
                ("constant/couplingProperties", "voidFraction    divided;",
                 f"voidFraction    {method};")])
            log = runner.solve(case, ranks)
            eps[ranks], _, lines = check_run(checks, label, case, log, CROWDED_COUNT,
                                             CROWDED_MIN_EPS, cell_volume=v_c)
            plines = particle_lines(log)
            cell_steps = plines[-1][2] if plines else -1
            clamped[ranks] = [l[1] for l in lines]
            if method == "centre":
                checks.expect(cell_steps > 0 and min(clamped[ranks], default=0) > 0,
                              f"{label}: clamps counted: {cell_steps} cell-steps, clamped "
                              f"volume per step {min(clamped[ranks], default=0):.4g} m^3")
                expected = v_c * (CROWDED_MIN_EPS - raw)
                worst = max((abs(c - expected) / expected for c in clamped[ranks]), default=1.0)
                checks.expect(worst < ROUND_OFF,
                              f"{label}: clamped volume = V_c (eps_min - (1 - 27 V_p/V_c)) = "
                              f"{expected:.6g} m^3 on every line (raw eps {raw:.4f}), worst "
                              f"relative difference {worst:.3g}")
                ok = all(f[CROWDED_INDEX] == CROWDED_MIN_EPS and
                         np.all(np.delete(f, CROWDED_INDEX) == 1.0) for f in eps[ranks].values())
                checks.expect(ok and len(eps[ranks]) > 0,
                              f"{label}: eps = {CROWDED_MIN_EPS} exactly in the crowded cell and 1 "
                              f"exactly elsewhere in all {len(eps[ranks])} fields")
            else:
                crowded = min(float(f[CROWDED_INDEX]) for f in eps[ranks].values())
                print(f"  info  {label}: crowded cell eps {crowded:.6g}, {cell_steps} clamped "
                      f"cell-steps")
        for folder in sorted(set(eps[1]) | set(eps[2]), key=float):
            a, b = eps[1].get(folder), eps[2].get(folder)
            if a is None or b is None or a.shape != b.shape:
                checks.expect(False, f"{method}, t = {folder}: voidfraction of 1 and 2 ranks")
                continue
            diff = float(np.max(np.abs(a - b)))
            checks.expect(diff < ROUND_OFF, f"{method}, t = {folder}: max |eps(np 1) - eps(np 2)| "
                                            f"= {diff:.3g} < 1e-12")
        n = min(len(clamped[1]), len(clamped[2]))
        worst = max((abs(a - b) / max(a, 1e-300) for a, b in zip(clamped[1][:n], clamped[2][:n])),
                    default=1.0)
        checks.expect(n > 0 and worst < ROUND_OFF,
                      f"{method}: clamped volume on 2 ranks = 1 rank, worst relative difference "
                      f"{worst:.3g} over {n} lines")


# --- the convected slab: emptied and refilled cells; fast crossing of ranks ---------------

SLAB_COUNT = 60           # cases/convected/particles.yaml
SLAB_CELL = 2.5e-3        # 8 x 2 x 2 cells in a 20 x 5 x 5 mm box
SLAB_LENGTH = 0.02        # periodic along x
SLAB_SPEED = 5.0          # the water's and the beads' initial velocity [m/s]


def empty_to_filled(series):
    """Number of writes at which a cell goes from eps == 1 (empty) to eps < 1."""
    return sum(1 for a, b in zip(series[:-1], series[1:]) if a == 1.0 and b < 1.0)


def slab_laps(snaps):
    """Per bead: crossings of the periodic face x = L -> 0 between writes (a jump back by
    more than half the box; a write comes every 2 mm of travel)."""
    xs = np.array([s["position"][:, 0] for _, s in snaps])
    return np.sum(np.diff(xs, axis=0) < -SLAB_LENGTH / 2, axis=0)


def emptied_and_refilled_cells(runner, checks):
    """60 beads in a 6 mm slab carried by water at 5 m/s along x around a 20 mm periodic
    box of 8 x 2 x 2 cells (`divided`), 20 ms: 5 laps. Every cell is emptied and refilled
    once per lap. Checked: the common invariants with the volume recomputed from every
    written field; every cell is exactly 1 at some writes and below 1 at others, and goes
    from empty to filled at least 4 times; every bead lapped the box at least 4 times."""
    case = runner.fresh_case("convected", "emptied_refilled", longer(0.02))
    t0 = time.monotonic()
    log = runner.solve(case, 1)
    print(f"  grainFoam wall time {time.monotonic() - t0:.1f} s")
    eps, snaps, _ = check_run(checks, "slab", case, log, SLAB_COUNT, 0.2,
                              cell_volume=SLAB_CELL ** 3)
    if not eps or not snaps:
        return
    fields = np.array([eps[f] for f in sorted(eps, key=float)])  # [write, cell]
    empty = np.sum(fields == 1.0, axis=0)
    filled = np.sum(fields < 1.0, axis=0)
    transitions = [empty_to_filled(list(fields[:, c])) for c in range(fields.shape[1])]
    checks.expect(np.all(empty > 0) and np.all(filled > 0),
                  f"every one of the {fields.shape[1]} cells is exactly 1 at some of the "
                  f"{fields.shape[0]} writes ({empty.min()}..{empty.max()}) and below 1 at others "
                  f"({filled.min()}..{filled.max()}); lowest eps {fields.min():.4f}")
    checks.expect(min(transitions) >= 4,
                  f"empty -> filled transitions per cell: {min(transitions)}..{max(transitions)} "
                  f"(>= 4)")
    laps = slab_laps(snaps)
    checks.expect(laps.min() >= 4, f"laps of the periodic box per bead: {laps.min()}..{laps.max()} "
                                   f"(>= 4)")


def fast_crossing_ranks(runner, checks):
    """The convected slab of emptied_and_refilled_cells for 8 ms (2 laps) on 1, 2 and 4
    ranks (simple (2 1 1) and (4 1 1), --oversubscribe): the beads cross the processor
    planes and the periodic face (also a processor boundary) at 5 m/s, twice each, and
    whole ranks are empty at times (all 60 beads beyond a plane). Checked: the common
    invariants on every run (count conserved, none removed, volume and exchange balance to
    1e-12, eps bounds); every rank held no bead at >= 2 writes.

    Agreement with 1 rank. Until the first bead crosses a processor plane the runs are the
    same computation in another summation order (the fluid is solved to 1e-14,
    system/fvSolution): eps to 1e-12 and positions to 1e-12 m at the first write. After,
    they differ by design: a bead that reaches another rank between two fluid steps is
    sampled there on arrival (dem/fluid/coupled_fluid.hpp, "sampled on arrival" in the
    log), where the 1-rank run keeps its sample from the start of the fluid step. Such a
    sample can change the bead's fluid force by at most twice the largest fluid force seen
    (|dv/dt|max, from the 1-rank snapshots), for at most one fluid step dt_f, so with n
    arrivals per bead: |dv| <= n 2 |dv/dt|max dt_f and |dx| <= that times the run time.
    Positions (modulo the period) and velocities after reconstructPar must stay within
    those bounds; the measured differences are printed."""
    end_time, dt_f = 0.008 * SCALE, 1e-4
    eps, snaps, late, first_late = {}, {}, {}, {}
    for ranks in (1, 2, 4):
        label = f"slab np {ranks}"
        print(f"{label}:")
        edits = [("system/controlDict", "endTime         0.02;", f"endTime         {end_time:g};")]
        if ranks != 2:
            edits += [("system/decomposeParDict", "numberOfSubdomains 2;",
                       f"numberOfSubdomains {ranks};"),
                      ("system/decomposeParDict", "n (2 1 1);", f"n ({ranks} 1 1);")]
        case = runner.fresh_case("convected", f"crossing_np{ranks}", edits)
        t0 = time.monotonic()
        log = runner.solve(case, ranks)
        print(f"  grainFoam wall time {time.monotonic() - t0:.1f} s")
        eps[ranks], snaps[ranks], _ = check_run(checks, label, case, log, SLAB_COUNT, 0.2,
                                                cell_volume=SLAB_CELL ** 3)
        arrivals = re.findall(r"sampled on arrival (\d+)", log)
        late[ranks] = int(arrivals[-1]) if arrivals else -1
        first_late[ranks] = int(arrivals[0]) if arrivals else -1
        if ranks > 1 and snaps[ranks]:
            width = SLAB_LENGTH / ranks
            owner = [np.floor(np.mod(s["position"][:, 0], SLAB_LENGTH) / width).astype(int)
                     for _, s in snaps[ranks]]
            empty = [sum(1 for o in owner if not np.any(o == r)) for r in range(ranks)]
            checks.expect(min(empty) >= 2, f"{label}: writes (of {len(owner)}) at which each "
                                           f"rank held no bead: {empty} (>= 2 each)")
            changes = np.sum(np.diff(np.array(owner), axis=0) != 0, axis=0)
            laps = slab_laps(snaps[ranks])
            # Two laps make 2 x ranks changes of rank; the first may come before the first write.
            checks.expect(laps.min() >= 2 and changes.min() >= 2 * ranks - 1,
                          f"{label}: per bead, {laps.min()}..{laps.max()} laps and "
                          f"{changes.min()}..{changes.max()} changes of rank between writes; "
                          f"{late[ranks]} samples on arrival in all")
    if not snaps.get(1):
        return
    v1 = np.array([s["velocity"] for _, s in snaps[1]])
    t1 = np.array([t for t, _ in snaps[1]])
    accel = float(np.max(np.linalg.norm(np.diff(v1, axis=0), axis=2) / np.diff(t1)[:, None]))
    for ranks in (2, 4):
        if not eps.get(ranks) or len(snaps.get(ranks, [])) != len(snaps[1]):
            checks.expect(False, f"np {ranks}: as many snapshots as np 1")
            continue
        first = min(eps[1], key=float)
        d_eps = float(np.max(np.abs(eps[1][first] - eps[ranks][first])))
        d_x0 = float(np.max(np.abs(snaps[1][0][1]["position"] - snaps[ranks][0][1]["position"])))
        if first_late[ranks] == 0:
            checks.expect(d_eps < ROUND_OFF and d_x0 < 1e-12,
                          f"np {ranks} vs np 1 at t = {first} (no bead has changed rank yet): "
                          f"|eps difference| {d_eps:.3g}, |position difference| {d_x0:.3g} m")
        else:
            print(f"  info  np {ranks}: {first_late[ranks]} samples on arrival by t = {first}")
        n = math.ceil(late[ranks] / SLAB_COUNT) + 1
        bound_v = n * 2 * accel * dt_f
        bound_x = bound_v * end_time
        d_v = max(float(np.max(np.abs(a["velocity"] - b["velocity"])))
                  for (_, a), (_, b) in zip(snaps[1], snaps[ranks]))
        d_x = 0.0
        for (_, a), (_, b) in zip(snaps[1], snaps[ranks]):
            d = a["position"] - b["position"]
            d[:, 0] -= SLAB_LENGTH * np.round(d[:, 0] / SLAB_LENGTH)
            d_x = max(d_x, float(np.max(np.abs(d))))
        d_eps = max(float(np.max(np.abs(eps[1][f] - eps[ranks][f]))) for f in eps[1] if f in eps[ranks])
        checks.expect(d_v <= bound_v and d_x <= bound_x,
                      f"np {ranks} vs np 1 over {len(snaps[1])} snapshots: |velocity difference| "
                      f"{d_v:.3g} m/s <= {bound_v:.3g} and |position difference| {d_x:.3g} m <= "
                      f"{bound_x:.3g} (n = {n} arrivals per bead, |dv/dt|max = {accel:.3g} m/s^2); "
                      f"|eps difference| {d_eps:.3g}")

TESTS = {f.__name__: f for f in (dense_bed_10x_umf, particles_larger_than_cells,
                                 on_faces_and_corners_2ranks, crowded_cell_2ranks,
                                 emptied_and_refilled_cells, fast_crossing_ranks)}


if __name__ == "__main__":
    sys.exit(main(TESTS, "coupling_stress", __doc__))
