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

Every run is also checked for: no nan/inf in the log, the snapshots or the written
voidfraction; particle count conserved with none removed; every printed relative volume
difference and exchange imbalance < 1e-12.

Exit status 0 when every check holds; otherwise each failed check is printed and the exit
status is 1. Logs stay in the case folders (log.<program>). Shared helpers:
tests/support/grainfoam_driver.py.
"""
import math
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from grainfoam_driver import (ROUND_OFF, NAN_WORD, balance_lines, main, particle_lines,  # noqa: E402
                              read_scalar_field, snapshots, time_folders, void_lines)


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
    case = runner.fresh_case("dense_bed", "dense_bed")
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


TESTS = {f.__name__: f for f in (dense_bed_10x_umf, particles_larger_than_cells,
                                 on_faces_and_corners_2ranks)}


if __name__ == "__main__":
    sys.exit(main(TESTS, "coupling_stress", __doc__))
