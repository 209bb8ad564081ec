#!/usr/bin/env python3
"""Command-level tests of grainFoam's coupling (tests/coupling/tests.cmake).

    grainfoam_cases.py TEST --foam-env scripts/foam_env.sh --solver bin/grainFoam
                            --mpiexec mpiexec --cases tests/coupling/cases --work <scratch>

TEST is one of the functions in TESTS below; each copies a case from tests/coupling/cases/
into <scratch>, edits it (the edits are listed in the test), runs the OpenFOAM programs
through foam_env.sh and checks the solver's log lines, written fields and particle
snapshots against references that do not come from the coupling itself:

  void_fraction_volume  conservation: sum over cells (1 - eps) V = sum over particles V_p,
                        and rank independence: eps on 2 ranks = eps on 1 rank;
  exchange_balance      Newton's third law: the fluid's exchange source is minus the sum
                        of the fluid forces on the particles;
  neutrally_buoyant     closed form: a particle as dense as the fluid, in fluid at rest,
                        feels no net force and stays where it is; its snapshot's
                        fluid_force is the buoyancy -rho_f V g and its force zero;
  cellpoint_ranks       rank independence of cellPoint sampling: sinking beads next to the
                        processor patch end where the 1-rank run puts them, to round-off;
  refuses_bad_setup     set-ups grainFoam must refuse, with the message it must give;
  scene_output          the scene's output block and time.end: snapshots at the interval's
                        multiples in the given folder, the run ending at the earlier end
                        time, the keys grainFoam does not use refused where they are;
  heat_equilibrium      closed form: beads and air in a closed box reach the equilibrium
                        temperature with the two-body time constant, the mixture's energy
                        conserved; restart continues T exactly;
  heat_balance          conservation: the heat the particles take is the heat the fluid
                        loses, to round-off, on 1 and 2 ranks;
  heat_front            closed form: the thermal front of a packed bed heated by hot gas
                        against Schumann's (1929) solution with Gunn's coefficient
                        (tests/coupling/schumann.py);
  balanced_decomposition  scripts/balanced_decomposition.py: the cut of a settled bed's
                        column where the larger slab's work (cells + w particles) is least,
                        against every cut tried here; grainFoam runs on it, the DEM sharing it.

Exit status 0 when every check holds; otherwise each failed check is printed and the exit
status is 1. Logs stay in the case folders (log.<program>). Shared helpers:
tests/support/grainfoam_driver.py.
"""
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import time

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from grainfoam_driver import (FLOAT, ROUND_OFF, balance_lines, main, read_scalar_field,  # noqa: E402
                              snapshots, time_folders, void_lines)
import schumann  # noqa: E402  (tests/coupling/schumann.py)


# --- coupling.void_fraction_volume ------------------------------------------------------

BOX = 0.02        # cases/periodic_box: a 20 mm cube, periodic along x and y
CELL = BOX / 8    # 8 x 8 x 8 cells
PROCESSOR_PLANE = BOX / 2  # decomposeParDict: simple (2 1 1)
TIME_FOLDERS = ("0.0001", "0.0002")  # controlDict: two steps of 1e-4 s, each written


def check_straddling(checks, particles):
    """The case must really put beads across the faces the test is about."""
    x, r = particles["position"], particles["radius"]
    across_x = np.sum((x[:, 0] < r) | (x[:, 0] > BOX - r))
    across_y = np.sum((x[:, 1] < r) | (x[:, 1] > BOX - r))
    across_plane = np.sum(np.abs(x[:, 0] - PROCESSOR_PLANE) < r)
    faces = np.abs(x / CELL - np.round(x / CELL)) * CELL < r[:, None]
    across_cells = np.sum(np.any(faces, axis=1))
    on_face = np.sum(x[:, 0] == 0)  # still exactly there after the first step (u_x = 0)
    checks.expect(across_x >= 2 and across_y >= 2 and across_plane >= 10 and
                  across_cells >= len(r) // 2 and on_face == 1,
                  f"beads across the periodic faces x: {across_x}, y: {across_y}, the "
                  f"processor plane: {across_plane}, a cell face: {across_cells} of {len(r)}; "
                  f"centred on x = 0: {on_face}")


def void_fraction_volume(runner, checks):
    """Sum (1 - eps) V + clamped = sum V_p to round-off, printed by grainFoam and
    recomputed here from the written voidfraction and the snapshot radii; eps on 2 ranks
    (simple (2 1 1): the processor plane x = 10 mm cuts beads, and each rank is its own
    periodic neighbour) equals eps on 1 rank to 1e-12 (round-off: the same footprint
    points are summed in another order)."""
    for method in ("centre", "divided", "smoothed"):
        print(f"voidFraction {method}:")
        edit = [("constant/couplingProperties", "voidFraction    divided;",
                 f"voidFraction    {method};")]
        eps = {}
        for ranks in (1, 2):
            case = runner.fresh_case("periodic_box", f"{method}_np{ranks}", edit)
            log = runner.solve(case, ranks)
            lines = void_lines(log)
            checks.expect(len(lines) == 2, f"np {ranks}: {len(lines)} void fraction lines "
                                           "(one per fluid step expected: every step is written)")
            for mesh_solid, clamped, particles, relative in lines:
                checks.expect(relative < ROUND_OFF,
                              f"np {ranks}: printed relative difference {relative:.3g} < 1e-12 "
                              f"(sum (1-eps) V = {mesh_solid:.17g}, clamped {clamped:.3g})")
            snaps = snapshots(case)
            checks.expect(len(snaps) == 2, f"np {ranks}: {len(snaps)} particle snapshots, 2 expected")
            # Fluid step k: its log line, its snapshot and its time folder.
            for (t, particles), line, folder in zip(snaps, lines, TIME_FOLDERS):
                checks.expect(abs(t - float(folder)) < 1e-12,
                              f"np {ranks}: snapshot at t = {t:g} s, fields at {folder} s")
                if ranks == 1 and folder == TIME_FOLDERS[0]:
                    check_straddling(checks, particles)
                vp = float(np.sum(4.0 / 3.0 * math.pi * particles["radius"] ** 3))
                checks.expect(abs(line[2] - vp) <= ROUND_OFF * vp,
                              f"np {ranks}, t = {folder}: particles {line[2]:.17g} m^3 = "
                              f"sum 4/3 pi r^3 of the snapshot {vp:.17g} m^3")
                field = read_scalar_field(os.path.join(case, folder, "voidfraction"))
                solid = float(np.sum((1 - field) * CELL ** 3))
                # The field is written with 17 digits: the recomputed sum is as exact as
                # the printed one. Nothing is clamped in this loose bed (checked).
                checks.expect(line[1] == 0 and abs(solid - vp) <= ROUND_OFF * vp,
                              f"np {ranks}, t = {folder}: from the written field, sum (1-eps) V "
                              f"= {solid:.17g} m^3, relative difference {abs(solid - vp) / vp:.3g}")
                eps[(ranks, folder)] = field
        for folder in TIME_FOLDERS:
            a, b = eps.get((1, folder)), eps.get((2, folder))
            if a is None or b is None or a.shape != b.shape:
                checks.expect(False, f"t = {folder}: voidfraction of 1 and 2 ranks to compare")
                continue
            diff = float(np.max(np.abs(a - b)))
            checks.expect(diff < ROUND_OFF, f"t = {folder}: max |eps(np 1) - eps(np 2)| = "
                                            f"{diff:.3g} < 1e-12 (min eps {a.min():.4f})")
    # A bead of 3 mm in the 2 mm cells of neutral_particle: with voidFraction centre its whole
    # volume goes into one cell, and the clamp removes most of it (1.41e-8 m^3 in a cell of
    # 8e-9 m^3): warned at start-up, naming divided; divided spreads it, with no warning.
    # (Both were silent, and so was a smoothingFactor given with either.)
    for method, warned in (("centre", True), ("divided", False)):
        case = runner.fresh_case("neutral_particle", f"wide_bead_{method}", [
            ("particle.csv", "0.00437,0.00512,0.00463,0.6e-3", "0.005,0.005,0.005,1.5e-3"),
            ("constant/couplingProperties", "voidFraction    divided;",
             f"voidFraction    {method};\nsmoothingFactor 1.5;"),
            ("system/controlDict", "endTime         0.1;", "endTime         0.002;")])
        log = runner.solve(case, 1)
        # smoothingFactor, a key of voidFraction smoothed, has no effect here: said.
        checks.expect("warning: smoothingFactor (constant/couplingProperties line 11) is a setting of "
                      f"voidFraction smoothed and has no effect with voidFraction {method}" in log,
                      f"smoothingFactor with voidFraction {method}: warned")
        said = ("warning: particles up to 0.003 m across are wider than the smallest fluid cell "
                "(0.002 m" in log and "Use voidFraction divided" in log)
        checks.expect(said == warned, f"a 3 mm bead in 2 mm cells, voidFraction {method}: "
                                      f"{'warned' if warned else 'no warning'}")


# --- coupling.exchange_balance ----------------------------------------------------------


def exchange_balance(runner, checks):
    """The same bed in a flow (initial U = (0.05 0.02 0) m/s, cyclic along x and y):
    drag is the main force. grainFoam prints the sum of the fluid forces on the particles
    (K (u_p - v) + the model's explicit part) and the fluid's exchange source summed over
    the cells; Newton's third law makes them opposite, to round-off, when the fluid is
    sampled with the same footprint weights it is deposited with (sampling cell)."""
    edits = [("0/U", "internalField   uniform (0 0 0);", "internalField   uniform (0.05 0.02 0);")]
    for ranks in (1, 2):
        case = runner.fresh_case("periodic_box", f"exchange_np{ranks}", edits)
        log = runner.solve(case, ranks)
        checks.expect("sampling cell," in log, f"np {ranks}: the solver samples with `cell`")
        lines = balance_lines(log)
        checks.expect(len(lines) == 2, f"np {ranks}: {len(lines)} exchange balance lines, 2 expected")
        for step, (particles, fluid, imbalance) in enumerate(lines, start=1):
            # Reference for the size: Stokes drag 3 pi mu d |u| (1 + 0.15 Re^0.687) on 307
            # beads at 0.05 m/s is ~1e-3 N along x; at least 1e-4 N shows the drag is on.
            checks.expect(particles[0] > 1e-4,
                          f"np {ranks}, step {step}: drag on the particles along the flow "
                          f"{particles[0]:.4g} N (> 1e-4 N)")
            checks.expect(imbalance < ROUND_OFF,
                          f"np {ranks}, step {step}: relative imbalance {imbalance:.3g} < 1e-12 "
                          f"(particles {particles}, fluid {fluid})")


# --- coupling.neutrally_buoyant ---------------------------------------------------------

# Where cases/neutral_particle/particle.csv puts the bead.
START = np.array([0.00437, 0.00512, 0.00463])


# The snapshot fields the neutrally_buoyant cases ask for (output.fields).
FIELDS_EDIT = ("particle.yaml", "forces: [drag, pressure_gradient, viscous, buoyancy]",
               "forces: [drag, pressure_gradient, viscous, buoyancy]\n"
               "output: {fields: [velocity, radius, force, fluid_force, coordination]}")
G = 9.81


def bead_weight(particles, density):
    return density * 4 / 3 * math.pi * float(particles["radius"][0]) ** 3 * G


def neutrally_buoyant(runner, checks):
    """One bead with the fluid's density, at rest in fluid at rest, model A and model B:
    gravity m g and buoyancy -rho_f V g cancel, drag, pressure-gradient and viscous forces
    vanish in fluid at rest, so it must not move. After 0.1 s (100 fluid steps of 50 DEM
    steps) its displacement must be < 1e-9 m and its speed < 1e-8 m/s: a residual force of
    round-off size (1e-16 of m g) would move it by ~1e-17 m (0 is measured: the forces
    cancel exactly and the fluid stays exactly at rest); a density 1 % off already moves
    it by 0.3 mm (the control below), a missing buoyancy or a hydrostatic pressure counted
    twice by far more. The snapshot's fields (output.fields): fluid_force, the coupling's
    force on the bead, is the buoyancy rho_f V g upward to round-off (1e-12 of it), force
    (weight + fluid) is zero to 1e-12 m g, coordination 0. The snapshot window: model B's
    scene has output.start 0.06 s, so of the write times 0.05 and 0.1 s (controlDict) only
    0.1 s has a snapshot, while both have a checkpoint; model A's has both snapshots."""
    for model in ("A", "B"):
        edits = [("particle.yaml", "model: B", f"model: {model}"), FIELDS_EDIT]
        if model == "B":
            edits.append(("particle.yaml", "coordination]}", "coordination], start: 0.06}"))
        case = runner.fresh_case("neutral_particle", f"neutral_{model}", edits)
        log = runner.solve(case, 1)
        checks.expect(f"VANS model {model}" in log, f"model {model}: the solver says VANS model {model}")
        snaps = snapshots(case)
        times = [t for t, _ in snaps]
        want = [0.1] if model == "B" else [0.05, 0.1]
        checks.expect(len(times) == len(want) and np.allclose(times, want, rtol=0, atol=1e-9),
                      f"model {model}: snapshots at {times} s, {want} s expected")
        checkpoints = sorted(n for n in os.listdir(os.path.join(case, "particles"))
                             if n.startswith("checkpoint_"))
        checks.expect(len(checkpoints) == 2, f"model {model}: checkpoints {checkpoints}, 2 expected")
        t, last = snaps[-1] if snaps else (0.0, None)
        if last is None or len(last["id"]) != 1:
            checks.expect(False, f"model {model}: a snapshot with one particle")
            continue
        moved = float(np.linalg.norm(last["position"][0] - START))
        speed = float(np.linalg.norm(last["velocity"][0]))
        checks.expect(abs(t - 0.1) < 1e-9, f"model {model}: last snapshot at t = {t:g} s (0.1 s)")
        checks.expect(moved < 1e-9, f"model {model}: displacement {moved:.3g} m < 1e-9 m")
        checks.expect(speed < 1e-8, f"model {model}: speed {speed:.3g} m/s < 1e-8 m/s")
        if "fluid_force" not in last:
            checks.expect(False, f"model {model}: the snapshot lacks the fields of output.fields")
            continue
        weight = bead_weight(last, 1000)
        fluid = last["fluid_force"][0]
        checks.expect(np.max(np.abs(fluid - [0, 0, weight])) < 1e-12 * weight,
                      f"model {model}: fluid_force {fluid} N = buoyancy (0, 0, {weight:.6g}) N")
        total = last["force"][0]
        checks.expect(np.max(np.abs(total)) < 1e-12 * weight,
                      f"model {model}: force {total} N = 0 (weight + buoyancy)")
        checks.expect(int(last["coordination"][0]) == 0, f"model {model}: coordination 0")

    # Control: 1 % denser, the bead must sink (so a bead that never moves fails the test).
    # Stokes: terminal speed 2/9 (rho_p - rho_f) g r^2 / mu = 7.8 mm/s, relaxation time
    # rho_p d^2 / (18 mu) = 0.081 s, so it sinks ~0.33 mm in 0.1 s; > 0.01 mm is asked.
    # Its fluid_force is the buoyancy plus an upward drag that has not yet caught up with the
    # net weight (still accelerating at 0.1 s, a relaxation time in), so
    # rho_f V g < fluid_force_z < m g, and force = fluid_force + m g (to 1e-12 m g).
    case = runner.fresh_case("neutral_particle", "denser", [
        ("particle.yaml", "poisson_ratio: 0.3, density: 1000", "poisson_ratio: 0.3, density: 1010"),
        FIELDS_EDIT])
    runner.solve(case, 1)
    t, last = snapshots(case)[-1]
    sunk = START[2] - last["position"][0][2]
    checks.expect(sunk > 1e-5, f"control, 1 % denser: sinks {sunk:.3g} m in {t:g} s (> 1e-5 m)")
    weight, buoyancy = bead_weight(last, 1010), bead_weight(last, 1000)
    fluid, total = last["fluid_force"][0], last["force"][0]
    checks.expect(buoyancy < fluid[2] < weight,
                  f"control: fluid_force_z {fluid[2]:.6g} N between the buoyancy {buoyancy:.6g} N "
                  f"and the weight {weight:.6g} N")
    checks.expect(np.max(np.abs(total - (fluid - [0, 0, weight]))) < 1e-12 * weight,
                  f"control: force {total} N = fluid_force {fluid} N + weight")


# --- coupling.cellpoint_ranks -----------------------------------------------------------

# Four beads 10 % denser than the water, sinking from rest in the closed box of
# cases/neutral_particle meshed 6 x 5 x 5, two on each side of the cut of the 2-rank
# decomposition (x = 5 mm, `simple (2 1 1)`) and within a cell of it: their cellPoint
# stencils hold the points the two ranks share.
CELLPOINT_BEADS = """x,y,z,radius
0.00420,0.00300,0.00800,0.5e-3
0.00570,0.00450,0.00780,0.5e-3
0.00450,0.00650,0.00760,0.5e-3
0.00540,0.00700,0.00820,0.5e-3
"""
DECOMPOSE_X = """FoamFile { version 2.0; format ascii; class dictionary; object decomposeParDict; }
numberOfSubdomains 2;
method simple;
coeffs { n (2 1 1); delta 0.001; }
"""


CYCLIC_Y = [
    ("system/blockMeshDict",
     "walls { type wall; faces ( (0 3 2 1) (4 5 6 7) (0 1 5 4) (2 3 7 6) (1 2 6 5) (3 0 4 7) ); }",
     "walls { type wall; faces ( (0 3 2 1) (4 5 6 7) (1 2 6 5) (3 0 4 7) ); }\n"
     "    front { type cyclic; neighbourPatch back;  faces ( (0 1 5 4) ); }\n"
     "    back  { type cyclic; neighbourPatch front; faces ( (3 7 6 2) ); }"),
    ("0/U", "boundaryField { walls { type noSlip; } }",
     "boundaryField { walls { type noSlip; } front { type cyclic; } back { type cyclic; } }"),
    ("0/p", "boundaryField { walls { type zeroGradient; } }",
     "boundaryField { walls { type zeroGradient; } front { type cyclic; } back { type cyclic; } }"),
    ("particle.yaml", "  max: [0.01, 0.01, 0.01]\n", "  max: [0.01, 0.01, 0.01]\n  periodic: [false, true, false]\n"),
]


def cellpoint_ranks(runner, checks):
    """cellPoint sampling on 1 and 2 ranks: the same beads must come out at the same place.
    The sinking beads stir the water (two-way coupling), so U, grad p, the viscous term and
    eps at their centres are not zero, and two of their cells touch the processor patch:
    the point values there are the two ranks' partial sums added (coupling/foam/
    pointInterpolation), and grad p is interpolated across the patch (gaussLinearGrad.H).
    Three times: in the closed box (the point values in one pass), with the box periodic along
    y (cyclic patches, which pointInterpolation does not reproduce: volPointInterpolation
    field by field, the fallback), and in the closed box with undisturbedVelocity
    oseenBrinkman (the footprint's disturbance sums of the beads at the cut gathered from
    both ranks, their place in the cell that holds their centre).
    Reference: the 1-rank run of the same case (no processor patch). The solvers converge
    to 1e-14 here (the case's 1e-8 with relTol 0.01 leaves 5e-9 m between the decompositions,
    GAMG agglomerating per rank), so the two runs must agree to round-off: positions to
    1e-12 m and velocities to 1e-10 m/s, of beads that sink 1.5 mm and reach 22 mm/s
    (measured in the closed box: 1.2e-16 m and 1.5e-14 m/s). Without the processor sums of
    the point values they differ by 1.3e-5 m and 6.0e-4 m/s."""
    edits = [("constant/couplingProperties", "sampling        cell;", "sampling        cellPoint;"),
             ("particle.yaml", "poisson_ratio: 0.3, density: 1000", "poisson_ratio: 0.3, density: 1100"),
             ("system/blockMeshDict", "(5 5 5)", "(6 5 5)"),
             # the beads sink at 22 mm/s: impacts at the default 1 m/s would take 4.8 steps,
             # which grainFoam refuses (at 0.1 m/s: 7.7)
             ("particle.yaml", "  end: 1\n", "  end: 1\n  expected_max_speed: 0.1\n"),
             ("system/fvSolution", "tolerance 1e-8; relTol 0.01;", "tolerance 1e-14; relTol 0;"),
             ("system/fvSolution", "tolerance 1e-9; relTol 0;", "tolerance 1e-14; relTol 0;")]
    undisturbed = [("constant/couplingProperties", "sampling        cellPoint;",
                    "sampling        cellPoint;\nundisturbedVelocity oseenBrinkman;")]
    variants = {"closed": ([], "cellPoint point values of all fields in one pass"),
                "cyclic": (CYCLIC_Y, "cellPoint point values by volPointInterpolation, field by "
                                     "field (patch front is of type cyclic)"),
                "undisturbed": (undisturbed, "grainFoam undisturbed velocity: the drag of")}
    for variant, (extra, expected) in variants.items():
        final = {}
        for ranks in (1, 2):
            case = runner.fresh_case("neutral_particle", f"cellpoint_{variant}_np{ranks}",
                                     edits + extra)
            with open(os.path.join(case, "particle.csv"), "w") as f:
                f.write(CELLPOINT_BEADS)
            with open(os.path.join(case, "system", "decomposeParDict"), "w") as f:
                f.write(DECOMPOSE_X)
            log = runner.solve(case, ranks)
            tag = f"{variant}, np {ranks}"
            checks.expect("sampling cellPoint" in log, f"{tag}: the solver samples with cellPoint")
            checks.expect(expected in log, f"{tag}: the log says '{expected}'")
            checks.expect("pressure gradient at the particles: Gauss linear, in one pass" in log,
                          f"{tag}: grad p comes from gaussLinearGrad")
            snaps = snapshots(case)
            if not snaps or len(snaps[-1][1]["id"]) != 4 or abs(snaps[-1][0] - 0.1) > 1e-9:
                checks.expect(False, f"{tag}: a snapshot of the 4 beads at t = 0.1 s")
                return
            final[ranks] = snaps[-1][1]
        a, b = final[1], final[2]
        checks.expect(np.array_equal(a["id"], b["id"]), f"{variant}: the same bead ids on 1 and 2 ranks")
        sunk = float(np.min(0.0079 - a["position"][:, 2]))
        speed = float(np.min(-a["velocity"][:, 2]))
        checks.expect(sunk > 1e-3 and speed > 5e-3,
                      f"{variant}: the beads sank (at least {sunk:.3g} m, {speed:.3g} m/s downwards; "
                      "> 1 mm, > 5 mm/s)")
        dx = float(np.max(np.abs(a["position"] - b["position"])))
        dv = float(np.max(np.abs(a["velocity"] - b["velocity"])))
        print(f"  {variant}, 1 vs 2 ranks: largest position difference {dx:.3g} m, velocity {dv:.3g} m/s")
        checks.expect(dx < 1e-12, f"{variant}: positions on 2 ranks = on 1 rank: {dx:.3g} m < 1e-12 m")
        checks.expect(dv < 1e-10, f"{variant}: velocities on 2 ranks = on 1 rank: {dv:.3g} m/s < 1e-10 m/s")


# --- coupling.refuses_bad_setup ---------------------------------------------------------


def staircase_decomposition(case):
    """constant/cellDecomposition for method manual: rank 1 holds x > 10 mm in the lower
    half (z < 10 mm) and x > 7.5 mm in the upper half, a cut with a step in it, as a graph
    partitioner (scotch, metis) makes on a box. blockMesh numbers the 8 x 8 x 8 cells with
    i (along x) fastest, then j, then k."""
    ranks = [int(i >= (4 if k < 4 else 3)) for k in range(8) for j in range(8) for i in range(8)]
    with open(os.path.join(case, "constant", "cellDecomposition"), "w") as f:
        f.write("FoamFile { version 2.0; format ascii; class labelList; "
                "object cellDecomposition; }\n")
        f.write(f"{len(ranks)}\n(\n" + "\n".join(map(str, ranks)) + "\n)\n")


def refuses_bad_setup(runner, checks):
    """Set-ups grainFoam must stop on, each with a message that says what to do."""
    # 1. A decomposition that is not a grid of boxes. Debian's OpenFOAM v1912 ships
    # libscotchDecomp.so as the stub ("Attempted to use <scotch> without the scotchDecomp
    # library loaded"), and metis and kahip likewise, so a graph partitioner's layout is
    # given by hand (method manual): a cut plane with a step, boxes that overlap.
    case = runner.fresh_case("periodic_box", "not_boxes", [
        ("system/decomposeParDict", "method          simple;",
         'method          manual;\nmanualCoeffs    { dataFile "cellDecomposition"; }')])
    staircase_decomposition(case)
    runner.run(case, "blockMesh", "blockMesh")
    runner.run(case, "decomposePar", "decomposePar")
    log = runner.run(case, "grainFoam", runner.solver, ranks=2, expect_failure=True)
    checks.expect("shared decomposition: the 2 processor meshes do not form a grid of boxes"
                  in log and "`simple`" in log and "`hierarchical`" in log,
                  "processor meshes that are not boxes: refused; the message names methods "
                  "simple and hierarchical")

    # 2. deltaT = 1.5 DEM steps.
    case = runner.fresh_case("periodic_box", "deltaT", [
        ("system/controlDict", "deltaT          1e-4;", "deltaT          1.5e-5;")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    checks.expect("must be an integer" in log and "1.5e-05" in log,
                  "deltaT 1.5e-5 s with a 1e-5 s DEM step: refused, 'must be an integer'")
    # The message's own advice, rerun: each deltaT it names runs.
    use = re.search(r"use deltaT (\S+) or deltaT (\S+),", log)
    checks.expect(use is not None and use.groups() == ("1e-05", "2e-05"),
                  f"deltaT 1.5e-5: the message advises deltaT 1e-05 or 2e-05, as typed "
                  f"({use.groups() if use else None})")
    for advised in (use.groups() if use else ()):
        again = runner.fresh_case("periodic_box", f"deltaT_{advised}", [
            ("system/controlDict", "deltaT          1e-4;", f"deltaT          {advised};")])
        runner.run(again, "blockMesh", "blockMesh")
        runner.run(again, "grainFoam", runner.solver)  # raises unless it runs to the end

    # 2c. A DEM step the time-step check refuses (1e-4 s, 1.6 Rayleigh times): stopped at
    #     start-up as `grain run` stops it, after the DEM's own start-up lines (it had started,
    #     without them, until a run-time guard stopped it). The message's advice, rerun: the
    #     step it names for this deltaT runs; `allowLargeTimeStep yes` starts anyway, printing
    #     the refusal as a warning and a setting without effect as a note.
    case = runner.fresh_case("periodic_box", "dem_step_refused", [
        ("particles.yaml", "step: 1e-5 ", "step: 1e-4 ")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    advised = re.search(r"refusing to run with this DEM time step \(see the lines above\); use a "
                        r"time\.step <= \S+ s, .* that divides the fluid step \(deltaT 0\.0001 "
                        r"s\): time\.step (\S+) s \(deltaT / (\d+)\); or set "
                        r"`allowLargeTimeStep yes;`", log)
    checks.expect("rayleigh_fraction" not in (advised.group(0) if advised else "x"),
                  "the advice offers no time.rayleigh_fraction (its step divides deltaT only by "
                  "chance)")
    checks.expect(advised is not None and "grainFoam DEM: error: dt is too large to resolve "
                  "contacts" in log and "grainFoam DEM: Rayleigh time t_R = " in log,
                  "DEM step 1e-4 s: refused at start-up after the DEM's lines, advising a step "
                  f"that divides deltaT ({advised.groups() if advised else None})")
    if advised:
        again = runner.fresh_case("periodic_box", "dem_step_advised", [
            ("particles.yaml", "step: 1e-5 ", f"step: {advised.group(1)} ")])
        runner.run(again, "blockMesh", "blockMesh")
        runner.run(again, "grainFoam", runner.solver)  # raises unless it runs to the end
    anyway = runner.fresh_case("periodic_box", "dem_step_anyway", [
        ("particles.yaml", "step: 1e-5 ", "step: 1e-4 "),
        ("particles.yaml", "friction: 0.5}", "friction: 0.5, rolling_friction: 0.1}"),
        ("constant/couplingProperties", "sampling        cell;",
         "allowLargeTimeStep yes;\nsampling        cell;")])
    runner.run(anyway, "blockMesh", "blockMesh")
    log = runner.run(anyway, "grainFoam", runner.solver)
    checks.expect("grainFoam DEM: warning: dt is too large to resolve contacts" in log
                  and "(running anyway: allowLargeTimeStep yes)" in log
                  and re.search(r"grainFoam DEM: \S*particles\.yaml:\d+:\d+: note: "
                                r"interaction_defaults\.rolling_friction: 0\.1 has no effect", log)
                  is not None,
                  "allowLargeTimeStep yes: starts, the refusal a warning; rolling_friction with "
                  "rolling none named as a note")

    # 2a. A misspelt couplingProperties key: refused at its line, with the key it resembles
    #     and the allowed keys as a plain list (it had printed OpenFOAM's "12 ( ... )" list
    #     and the dictionary's line range). The advice, followed, is the original case.
    case = runner.fresh_case("periodic_box", "misspelt_key", [
        ("constant/couplingProperties", "voidFraction    divided;", "voidfraction    divided;")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    checks.expect("unknown key 'voidfraction' at line 11 (did you mean 'voidFraction'?); "
                  "allowed: scene, voidFraction, dividedResolution" in log,
                  "voidfraction: refused at line 11, 'did you mean voidFraction', a plain list")

    # A misspelt scene path: refused naming the key, its line and where the path is taken from
    # (it had said only "particle.yaml: cannot open the scene file").
    case = runner.fresh_case("periodic_box", "misspelt_scene", [
        ("constant/couplingProperties", '"particles.yaml"', '"particle.yaml"')])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    checks.expect('scene "particle.yaml" (line 10): no such file' in log and "couplingProperties"
                  in log, "scene particle.yaml: refused naming the key, line 10 and the file")

    # A key given twice: OpenFOAM takes the last silently (voidFraction centre ran, against the
    # divided the user saw first). Refused at both lines, in serial and on 2 ranks; keeping one
    # of the two, as advised, runs.
    case = runner.fresh_case("periodic_box", "duplicate_key", [
        ("constant/couplingProperties", "minVoidFraction 0.2;",
         "minVoidFraction 0.2;\nvoidFraction    centre;")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    checks.expect("key 'voidFraction' is given twice (at line 11 and line 14); OpenFOAM would "
                  "silently take the last one" in log and "couplingProperties" in log,
                  "voidFraction given twice: refused at lines 11 and 14, naming the file")
    runner.run(case, "decomposePar", "decomposePar")
    log = runner.run(case, "grainFoam.parallel", runner.solver, ranks=2, expect_failure=True)
    checks.expect("key 'voidFraction' is given twice" in log,
                  "voidFraction given twice, 2 ranks: refused")
    with open(os.path.join(case, "constant/couplingProperties")) as f:
        text = f.read()
    with open(os.path.join(case, "constant/couplingProperties"), "w") as f:
        f.write(text.replace("\nvoidFraction    centre;", ""))
    runner.run(case, "grainFoam.advised", runner.solver)  # raises unless it runs to the end
    checks.expect(True, "the duplicate removed, as advised, runs")

    # 2b. deltaT 0 and an endTime before the start: refused, saying why.
    case = runner.fresh_case("periodic_box", "deltaT_zero", [
        ("system/controlDict", "deltaT          1e-4;", "deltaT          0;")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    checks.expect("deltaT 0 s must be positive" in log and "e.g. deltaT 1e-05" in log
                  and "controlDict" in log,
                  "deltaT 0: refused, 'must be positive', advising 1e-05, naming controlDict")
    case = runner.fresh_case("periodic_box", "end_before_start", [
        ("system/controlDict", "endTime         2e-4;", "endTime         -1;")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    checks.expect("the run would end at t = -1 s, system/controlDict's endTime, before it "
                  "starts at t = 0 s" in log,
                  "endTime -1: refused (before, the run ran no step and ended 'End', exit 0)")

    # 3. The scene's fluid density differs from transportProperties' rho.
    case = runner.fresh_case("periodic_box", "density", [
        ("particles.yaml", "density: 1000", "density: 1100")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    named = re.search(r"particles\.yaml:32: error: fluid\.density is 1100 kg/m\^3 but the fluid "
                      r"solver's rho is 1000 kg/m\^3 \(constant/transportProperties\)", log)
    checks.expect(named is not None,
                  "fluid.density 1100 vs rho 1000: refused; the message names both values, "
                  "particles.yaml:32 (the density key) and constant/transportProperties")

    # 4. undisturbedVelocity: an unknown model.
    case = runner.fresh_case("periodic_box", "undisturbed_unknown", [
        ("constant/couplingProperties", "sampling        cell;",
         "undisturbedVelocity oseen;\nsampling        cell;")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    checks.expect("undisturbedVelocity oseen is not one of: off" in log and "oseenBrinkman" in log,
                  "undisturbedVelocity oseen: refused, naming off and oseenBrinkman")

    # 5. meanPressureGradient: an unknown value, and suspensionWeight in a box with walls
    # across gravity (periodic_box is periodic along x and y only, gravity along -z).
    case = runner.fresh_case("periodic_box", "mean_gradient_unknown", [
        ("constant/couplingProperties", "sampling        cell;",
         "meanPressureGradient weight;\nsampling        cell;")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    checks.expect("meanPressureGradient weight is not one of: off" in log
                  and "suspensionWeight" in log,
                  "meanPressureGradient weight: refused, naming off and suspensionWeight")
    case = runner.fresh_case("periodic_box", "mean_gradient_walls", [
        ("constant/couplingProperties", "sampling        cell;",
         "meanPressureGradient suspensionWeight;\nsampling        cell;")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    checks.expect("meanPressureGradient suspensionWeight: gravity has a component along z but "
                  "the scene's domain is not periodic along z" in log,
                  "meanPressureGradient suspensionWeight with walls across gravity: refused, "
                  "naming the axis z")

    # 6. facePressure: an unknown value is refused naming the file, its line and both values.
    case = runner.fresh_case("periodic_box", "face_pressure_unknown", [
        ("constant/couplingProperties", "sampling        cell;",
         "facePressure    harmonic;\nsampling        cell;")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    checks.expect("facePressure harmonic is not one of: linear" in log and "dragSeries" in log
                  and re.search(r"couplingProperties\D+line \d+", log) is not None,
                  "facePressure harmonic: refused, naming linear, dragSeries and "
                  "constant/couplingProperties with its line")

    # 7. The scene and the mesh periodic along different axes. The closed box with the scene
    # periodic along y: a particle would leave through the fluid's wall and come back on the
    # other side (it did, with exit 0). The mesh cyclic along y with the scene bounded: the
    # fluid would cross the sides the particles stop at. The advice (both periodic along y)
    # runs: cellpoint_ranks' "cyclic" variant.
    for label, edits, words in (
            ("scene_periodic_mesh_walled", CYCLIC_Y[-1:],
             "the scene's domain is periodic along y (domain.periodic in "),
            ("mesh_cyclic_scene_bounded", CYCLIC_Y[:-1],
             "the mesh is periodic along y (patch 'front', type cyclic) but the scene's domain "
             "is not")):
        case = runner.fresh_case("neutral_particle", label, edits)
        runner.run(case, "blockMesh", "blockMesh")
        log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
        checks.expect(words in log and ("closes the y sides with patch 'walls' (type wall)" in log
                                        or "give the mesh walls or an outlet" in log),
                      f"{label}: refused, naming the axis y and the patch")

    # 8. The fluid block's keys that prescribe the fluid for a one-way `grain run` (velocity,
    # shear, void_fraction, pressure.gradient): grainFoam solves the fluid, and ran with them
    # as if they were not there (exit 0, the same settling speed to every digit).
    case = runner.fresh_case("neutral_particle", "prescribed_fluid_keys", [
        ("particle.yaml", "  viscosity: 1e-3\n",
         "  viscosity: 1e-3\n  velocity: [0, 0, 0.05]\n  void_fraction: 0.5\n"),
        ("particle.yaml", "pressure: {hydrostatic: false}",
         "pressure: {hydrostatic: false, gradient: [0, 0, 5000]}")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    for key, line in (("pressure.gradient", 23), ("velocity", 19), ("void_fraction", 20)):
        checks.expect(f"particle.yaml:{line}: error: fluid.{key} prescribes the fluid for a "
                      f"one-way `grain run`; a coupled run does not use it" in log,
                      f"fluid.{key} in a coupled run: refused at particle.yaml:{line}")

    # 9. constant/g, OpenFOAM's place for gravity, which grainFoam does not read (it takes the
    # scene's): one that differs from the scene's is refused (it was ignored, exit 0); one
    # equal to it runs.
    for label, value, fails in (("g_differs", "(0 0 -20)", True), ("g_equal", "(0 0 -9.81)", False)):
        case = runner.fresh_case("neutral_particle", label, [])
        with open(os.path.join(case, "constant", "g"), "w") as f:
            f.write("FoamFile { version 2.0; format ascii; class uniformDimensionedVectorField; "
                    f"object g; }}\ndimensions [0 1 -2 0 0 0 0];\nvalue {value};\n")
        runner.run(case, "blockMesh", "blockMesh")
        log = runner.run(case, "grainFoam", runner.solver, expect_failure=fails)
        if fails:
            checks.expect("constant/g is (0 0 -20) m/s^2 but the scene's gravity is (0 0 -9.81)"
                          in log and "does not read constant/g" in log,
                          "constant/g (0 0 -20) against the scene's (0 0 -9.81): refused, "
                          "naming both")


def hostile_fields(runner, checks):
    """Starting fields a user may mistype (docs/reliability.md, "Starting fields"): a value
    beyond the double range, a speed whose square overflows, a speed a fluid step cannot carry,
    in the internal field and at an inlet. Each must stop grainFoam with a message that names
    the file (never OpenFOAM's floating-point trap and its stack trace); a speed above a Courant
    number of 1 is named in a start-up warning whose figure is the closed form |U| dt / h; a
    fluid temperature at or below 0 K (internal field, inlet) is refused; and the corrected
    fields run."""
    def stack_trace(log):
        return "printStack" in log or "sigFpe" in log

    def with_u(name, value):
        case = runner.fresh_case("periodic_box", name, [
            ("0/U", "internalField   uniform (0 0 0);", f"internalField   uniform {value};")])
        runner.run(case, "blockMesh", "blockMesh")
        return case

    # 1. Beyond the double range: OpenFOAM's own reader error, naming 0/U and its line.
    case = with_u("u_1e400", "(1e400 0 0)")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    checks.expect(re.search(r"FOAM FATAL IO ERROR.*\n.*'internalField' on line 11.*\n\nfile: "
                            r"\S*/u_1e400/0/U at line 11", log) is not None and not stack_trace(log),
                  "0/U (1e400 0 0): the reader's error names internalField, 0/U and line 11; no "
                  "stack trace")

    # 2. A speed whose square overflows, and one far above what a step carries: the start-up
    # warning names the field, the stop repeats it as the remedy.
    for value, speed in (("(1e160 0 0)", "1e+160"), ("(1e6 0 0)", "1e+06")):
        case = with_u("u_" + value.split()[0][1:], value)
        log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
        warned = f"warning: 0/U starts the fluid at up to {speed} m/s (its internalField" in log
        remedy = re.search(r"FOAM FATAL ERROR.*(\n.*)*what changes it: the run started above 1 "
                           rf"\(0/U starts the fluid at up to {re.escape(speed)} m/s", log,
                           re.IGNORECASE)
        checks.expect(warned and remedy is not None and not stack_trace(log),
                      f"0/U {value}: warned at start-up, the stop names 0/U as what to change; "
                      f"no stack trace")

    # 3. The warning's Courant number: |U| dt / h with |(24 0 18)| = 30 m/s, dt = 1e-4 s and
    # h = 2.5 mm cells: 1.2.
    case = with_u("u_30", "(24 0 18)")
    code = subprocess.run([runner.foam_env, runner.solver, "-case", case], cwd=case,
                          env=runner.env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, timeout=300)
    m = re.search(r"warning: 0/U starts the fluid at up to (\S+) m/s \(its internalField, at "
                  r"\(.*\) m\), a Courant number of (\S+) at deltaT 0.0001 s", code.stdout)
    figures = (float(m.group(1)), float(m.group(2))) if m else None
    checks.expect(figures is not None and abs(figures[0] - 30) < 1e-9
                  and abs(figures[1] - 1.2) < 1e-3 and not stack_trace(code.stdout),
                  f"0/U (24 0 18) in 2.5 mm cells at dt 1e-4 s: warned with speed, Courant "
                  f"{figures} (30, 1.2)")

    # 4. At an inlet: parcel_bed's superficial inlet at 1000 m/s is named as the patch.
    case = runner.fresh_case("parcel_bed", "inlet_1e3", [
        ("0/U", "superficialVelocity constant (0 0 0.2);",
         "superficialVelocity constant (0 0 1000);"),
        ("system/controlDict", "endTime         0.2;", "endTime         0.002;")])
    runner.run(case, "blockMesh", "blockMesh")
    code = subprocess.run([runner.foam_env, runner.solver, "-case", case], cwd=case,
                          env=runner.env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, timeout=300)
    checks.expect("warning: 0/U starts the fluid at up to 1000 m/s (its patch inlet" in code.stdout
                  and not stack_trace(code.stdout),
                  f"inlet at 1000 m/s: warned naming patch inlet (exit {code.returncode}); no "
                  f"stack trace")

    # 5. The advice rerun: 0/U at rest runs to the end, without the warning.
    case = with_u("u_rest", "(0 0 0)")
    log = runner.run(case, "grainFoam", runner.solver)
    checks.expect("starts the fluid" not in log,
                  "0/U (0 0 0): runs to the end, no start-up warning")

    # 6. A fluid temperature at or below 0 K (a value in degrees Celsius, say) ran to the end
    # with a negative thermal energy: refused before the first step, naming the internal
    # field or the patch. The message's example, 293.15 K, then runs.
    for name, edit, where in (
            ("t_minus10", ("heated_box", "0/T", "internalField   uniform 300;",
                           "internalField   uniform -10;"), "-10 K (its internalField"),
            ("t_zero", ("heated_box", "0/T", "internalField   uniform 300;",
                        "internalField   uniform 0;"), "0 K (its internalField"),
            ("t_inlet", ("heated_bed", "0/T", "value uniform 400;", "value uniform -5;"),
             "-5 K (its patch inlet")):
        source, *change = edit
        case = runner.fresh_case(source, name, [tuple(change)])
        runner.run(case, "blockMesh", "blockMesh")
        log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
        checks.expect(f"error: 0/T holds {where}" in log and "must be above 0 K" in log
                      and not stack_trace(log),
                      f"0/T {where.split(' (')[0]} in the {where.split('its ')[1]}: refused")
    case = runner.fresh_case("heated_box", "t_advised", [
        ("0/T", "internalField   uniform 300;", "internalField   uniform 293.15;"),
        ("system/controlDict", "endTime         0.1;", "endTime         0.002;")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver)
    checks.expect("End" in log, "0/T 293.15 (the message's example): runs to the end")


# --- coupling.restart -------------------------------------------------------------------


def read_foam_binary_or_ascii(case, folder, name):
    """The internal field of a written volume field, as raw bytes of its values (binary
    files) or their text (ascii), so that two runs compare exactly, digit for digit."""
    with open(os.path.join(case, folder, name), "rb") as f:
        text = f.read()
    start = text.index(b"internalField")
    end = text.index(b"boundaryField")
    return text[start:end]


def restart(runner, checks, coupling_keys="", other_rank_count=True):
    """Restart of a coupled run: cases/periodic_box in a flow of (0.05 0.02 0) m/s under
    10 g, so that the 307 beads rain through the water onto the floor, with over a hundred
    frictional contacts by the end. 400 fluid steps of 10 DEM steps, written every 200
    (binary), against 200 steps and a restart from the time written at step 200
    (startFrom latestTime) for 200 more, in a copy of the stopped run. Reference: the
    uninterrupted run; on the same rank count every particle's position and velocity at
    the end and the written U, p, phi and voidfraction must be the same to the last bit
    (1 and 2 ranks). A restart on another rank count (1-rank checkpoint, decomposePar,
    2 ranks) cannot be bit-identical (sums in another order, which a colliding bed
    amplifies), but must continue the same flow: the same beads, the momentum balance to
    round-off, and the bed's centre of mass within 2 % of the distance it fell."""
    end_time, half_time = "0.04", "0.02"
    edits = [("0/U", "internalField   uniform (0 0 0);", "internalField   uniform (0.05 0.02 0);"),
             ("particles.yaml", "gravity: [0, 0, -9.81]", "gravity: [0, 0, -98.1]"),
             ("system/controlDict", "endTime         2e-4;", "endTime         4e-2;"),
             ("system/controlDict", "writeInterval   1;", "writeInterval   200;"),
             ("system/controlDict", "writeFormat     ascii;", "writeFormat     binary;")]
    if coupling_keys:
        edits.append(("constant/couplingProperties", "ddtVoidFraction on;",
                      "ddtVoidFraction on;\n" + coupling_keys))
    finals = {}
    for ranks in (1, 2):
        whole = runner.fresh_case("periodic_box", f"restart_whole_np{ranks}", edits)
        runner.solve(whole, ranks)
        # The stopped run: the same case stopped after the first write (as if killed before
        # the second), then restarted from its latest time.
        part = runner.fresh_case("periodic_box", f"restart_part_np{ranks}", edits + [
            ("system/controlDict", "endTime         4e-2;", "endTime         2e-2;")])
        runner.solve(part, ranks)
        if ranks == 1:  # its checkpoint serves the restart on another rank count below
            shutil.rmtree(os.path.join(runner.work, "restart_np1_to_np2"), ignore_errors=True)
            shutil.copytree(part, os.path.join(runner.work, "restart_np1_to_np2"))
        with open(os.path.join(part, "system", "controlDict")) as f:
            text = f.read()
        text = text.replace("endTime         2e-2;", "endTime         4e-2;").replace(
            "startFrom       startTime;", "startFrom       latestTime;")
        with open(os.path.join(part, "system", "controlDict"), "w") as f:
            f.write(text)
        if ranks == 1:
            log = runner.run(part, "grainFoam.restart", runner.solver)
        else:
            log = runner.run(part, "grainFoam.restart", runner.solver, ranks=ranks)
            for case in (whole, part):
                runner.run(case, "reconstructPar.all", "reconstructPar", "-latestTime")
        checks.expect(f"restart at time {half_time} (time index 200)" in log,
                      f"np {ranks}: the solver says it restarts at {half_time}, time index 200")
        checks.expect(f"time folder {half_time}: its" in log and
                      "files match the checksums grainFoam recorded" in log,
                      f"np {ranks}: the files of {half_time} match their record")
        contacts = [int(m) for m in re.findall(r"particles, (\d+) contacts", log)]
        checks.expect(contacts and max(contacts) > 100,
                      f"np {ranks}: contacts after the restart {contacts} (> 100 at some write)")
        checks.expect("continuing with the written one, as the uninterrupted run does" in log,
                      f"np {ranks}: the written void fraction is taken")
        a, b = snapshots(whole)[-1], snapshots(part)[-1]
        checks.expect(abs(a[0] - 0.04) < 1e-12 and a[0] == b[0],
                      f"np {ranks}: last snapshots at t = {a[0]} and {b[0]} s (0.04)")
        for key in ("id", "position", "velocity"):
            same = a[1][key].shape == b[1][key].shape and np.array_equal(a[1][key], b[1][key])
            diff = (float(np.max(np.abs(a[1][key] - b[1][key])))
                    if a[1][key].shape == b[1][key].shape else float("nan"))
            checks.expect(same, f"np {ranks}: every particle's {key} equal to the last bit "
                                f"(max difference {diff:.3g})")
        moved = float(np.max(np.linalg.norm(a[1]["position"] - snapshots(whole)[0][1]["position"],
                                            axis=1)))
        checks.expect(moved > 1e-3, f"np {ranks}: the beads moved (up to {moved:.3g} m > 1 mm)")
        for field in ("U", "p", "phi", "voidfraction"):
            same = (read_foam_binary_or_ascii(whole, end_time, field) ==
                    read_foam_binary_or_ascii(part, end_time, field))
            checks.expect(same, f"np {ranks}: {field} at t = {end_time} equal byte for byte")
        finals[ranks] = a[1]
    if not other_rank_count:
        return

    # Another rank count: the 1-rank checkpoint restarted on 2 ranks.
    case = os.path.join(runner.work, "restart_np1_to_np2")
    with open(os.path.join(case, "system", "controlDict")) as f:
        text = f.read()
    with open(os.path.join(case, "system", "controlDict"), "w") as f:
        f.write(text.replace("endTime         2e-2;", "endTime         4e-2;").replace(
            "startFrom       startTime;", "startFrom       latestTime;"))
    runner.run(case, "decomposePar", "decomposePar", "-latestTime")
    log = runner.run(case, "grainFoam.restart", runner.solver, ranks=2)
    checks.expect(f"time folder {half_time} has no record of its files" in log and
                  "on 2 of 2 ranks: its fields are read unchecked" in log,
                  "1 -> 2 ranks: decomposePar's folders have no record, and the log says so")
    lines = balance_lines(log)
    checks.expect(len(lines) >= 1 and all(imb < ROUND_OFF for _, _, imb in lines),
                  f"1 -> 2 ranks: exchange balance to round-off ({len(lines)} lines)")
    snaps = snapshots(case)
    last, first = snaps[-1][1], snaps[0][1]
    ref = finals.get(1)
    if ref is not None and np.array_equal(ref["id"], last["id"]):
        fell = float(np.mean(first["position"][:, 2]) - np.mean(ref["position"][:, 2]))
        off = float(abs(np.mean(last["position"][:, 2]) - np.mean(ref["position"][:, 2])))
        spread = float(np.max(np.abs(ref["position"] - last["position"])))
        checks.expect(fell > 1e-3 and off < 0.02 * fell,
                      f"1 -> 2 ranks: centre of mass {off:.3g} m from the 1-rank run's, < 2 % "
                      f"of the {fell:.3g} m it fell (largest bead difference {spread:.3g} m)")
    else:
        checks.expect(False, "1 -> 2 ranks: the same particles as the 1-rank run")

    # A time whose DEM checkpoint is gone: refused, naming the file.
    checkpoint = os.path.join(case, "particles", "checkpoint_000002000.h5")
    os.remove(checkpoint)
    log = runner.run(case, "grainFoam.missing", runner.solver, expect_failure=True)
    checks.expect("restart from time 0.02" in log and checkpoint in log,
                  "a missing DEM checkpoint: refused; the message names the time and the file")


def restart_files(runner, checks):
    """The files of a restart time (docs/reliability.md, "Restart of a coupled run"): grainFoam
    records each file it wrote at a write time with its FNV-1a checksum (grainflowChecksums), and
    a restart compares them. cases/periodic_box in a flow, binary fields written at 1 ms, then
    restarted to 2 ms from copies of the stopped case: intact (every file named, matched, and
    the run continues); one mantissa bit of one U value flipped (refused, naming the file; the
    message's advice, deleting U's line, then runs, and ends with another U than the intact
    restart: the flip alone would have been a silent wrong answer); phi deleted (without the
    record OpenFOAM would rebuild it from U); a recorded checksum damaged; another run's
    checkpoint of the same step in particles/ (refused; this run's put back restarts as the
    intact copy did); and on 2 ranks a flipped bit in processor1's p."""
    edits = [("0/U", "internalField   uniform (0 0 0);", "internalField   uniform (0.05 0.02 0);"),
             ("system/controlDict", "endTime         2e-4;", "endTime         1e-3;"),
             ("system/controlDict", "writeInterval   1;", "writeInterval   10;"),
             ("system/controlDict", "writeFormat     ascii;", "writeFormat     binary;")]
    record = "grainflowChecksums"

    def restart_case(stopped, name, ranks=1):
        case = os.path.join(runner.work, name)
        shutil.rmtree(case, ignore_errors=True)
        shutil.copytree(stopped, case)
        path = os.path.join(case, "system", "controlDict")
        with open(path) as f:
            text = f.read()
        with open(path, "w") as f:
            f.write(text.replace("endTime         1e-3;", "endTime         2e-3;").replace(
                "startFrom       startTime;", "startFrom       latestTime;"))
        return case

    def flip(path, offset, bit):
        with open(path, "r+b") as f:
            f.seek(offset)
            byte = f.read(1)[0]
            f.seek(offset)
            f.write(bytes([byte ^ (1 << bit)]))

    def first_value(path):
        """Offset of the first double of a binary field's internalField list."""
        with open(path, "rb") as f:
            data = f.read()
        start = data.index(b"internalField")
        return data.index(b"(", start) + 1

    def stack_trace(log):
        return "printStack" in log or "sigFpe" in log

    stopped = runner.fresh_case("periodic_box", "files_stopped", edits)
    runner.solve(stopped, 1)
    with open(os.path.join(stopped, "0.001", record)) as f:
        listed = re.findall(r'^"([^"]+)"  "fnv1a64 [0-9a-f]{16}";$', f.read(), re.MULTILINE)
    wanted = {"U", "p", "phi", "voidfraction", "Ksl", "uniform/time", "uniform/grainflowCheckpoint"}
    checks.expect(wanted <= set(listed),
                  f"the record of 0.001 lists {sorted(listed)} (at least {sorted(wanted)})")

    # Intact: every listed file matches, and the run goes on to the end.
    case = restart_case(stopped, "files_intact")
    log = runner.run(case, "grainFoam.restart", runner.solver)
    checks.expect(f"time folder 0.001: its {len(listed)} files match the checksums" in log,
                  f"intact: all {len(listed)} files matched")
    with open(os.path.join(case, "0.002", "U"), "rb") as f:
        intact_u = f.read()

    # One mantissa bit (2^-12 of the value) of the first U value: refused, naming the file.
    case = restart_case(stopped, "files_u_bit")
    u = os.path.join(case, "0.001", "U")
    flip(u, first_value(u) + 5, 0)
    log = runner.run(case, "grainFoam.restart", runner.solver, expect_failure=True)
    checks.expect(re.search(r"1 file of time folder 0.001 differs from what grainFoam wrote there .*\n  "
                            + re.escape(u) + r": FNV-1a checksum [0-9a-f]{16}, recorded", log)
                  is not None and "delete its line from" in log and not stack_trace(log),
                  "U with one flipped bit: refused, naming 0.001/U and both checksums")
    # The advice: delete U's line (as after an edit made on purpose) and start again.
    path = os.path.join(case, "0.001", record)
    with open(path) as f:
        lines = f.read().splitlines(keepends=True)
    with open(path, "w") as f:
        f.writelines(line for line in lines if not line.startswith('"U"'))
    log = runner.run(case, "grainFoam.restart_advised", runner.solver)
    with open(os.path.join(case, "0.002", "U"), "rb") as f:
        flipped_u = f.read()
    checks.expect(f"its {len(listed) - 1} files match" in log and flipped_u != intact_u,
                  "advice rerun (U's line deleted): runs to the end, and its U at 0.002 differs "
                  "from the intact restart's (the flip unchecked is a silent wrong answer)")

    # phi deleted: OpenFOAM would rebuild it from U (READ_IF_PRESENT), not the written flux.
    case = restart_case(stopped, "files_no_phi")
    phi = os.path.join(case, "0.001", "phi")
    os.remove(phi)
    log = runner.run(case, "grainFoam.restart", runner.solver, expect_failure=True)
    checks.expect(f"  {phi} is missing (line" in log and not stack_trace(log),
                  "phi deleted: refused, naming 0.001/phi as missing")

    # A recorded checksum damaged (the record itself on a failing disk): refused too.
    case = restart_case(stopped, "files_record_bit")
    path = os.path.join(case, "0.001", record)
    with open(path) as f:
        text = f.read()
    at = text.index('"p"  "fnv1a64 ') + len('"p"  "fnv1a64 ')
    digit = "0" if text[at] != "0" else "1"
    with open(path, "w") as f:
        f.write(text[:at] + digit + text[at + 1:])
    log = runner.run(case, "grainFoam.restart", runner.solver, expect_failure=True)
    checks.expect(re.search(re.escape(os.path.join(case, "0.001", "p")) + r": FNV-1a checksum", log)
                  is not None and not stack_trace(log),
                  "a damaged checksum in the record: refused, naming p")
    case = restart_case(stopped, "files_record_line")
    path = os.path.join(case, "0.001", record)
    with open(path, "a") as f:
        f.write('"U"  "fnv1a64 12345";\n')
    log = runner.run(case, "grainFoam.restart", runner.solver, expect_failure=True)
    checks.expect(re.search(r"line \d+ of " + re.escape(path) + r" is not an entry", log)
                  is not None and not stack_trace(log),
                  "a garbled line in the record: refused, naming the record and its line")

    # Another run's checkpoint of the same step in particles/ (an output.directory shared by
    # two cases): a valid file with other particles. Refused, naming it; the advice (put back
    # this run's checkpoint) then restarts exactly as the intact copy did.
    other = runner.fresh_case("periodic_box", "files_other_run", [
        (f, a, b.replace("(0.05 0.02 0)", "(0 0.05 0.02)")) for f, a, b in edits])
    runner.solve(other, 1)
    case = restart_case(stopped, "files_other_checkpoint")
    name = [n for n in os.listdir(os.path.join(case, "particles")) if n.startswith("checkpoint_")]
    checks.expect(len(name) == 1, f"one checkpoint in particles/ ({name})")
    ours = os.path.join(case, "particles", name[0])
    shutil.copy(ours, ours + ".ours")
    shutil.copy(os.path.join(other, "particles", name[0]), ours)
    log = runner.run(case, "grainFoam.restart", runner.solver, expect_failure=True)
    checks.expect(f"{ours} is not the DEM checkpoint grainFoam wrote with this time" in log
                  and "Put back the checkpoint of this run" in log and not stack_trace(log),
                  "another run's checkpoint of the same step: refused, naming it")
    os.replace(ours + ".ours", ours)
    log = runner.run(case, "grainFoam.restart_advised", runner.solver)
    with open(os.path.join(case, "0.002", "U"), "rb") as f:
        checks.expect(f.read() == intact_u,
                      "advice rerun (this run's checkpoint put back): U at 0.002 byte for byte "
                      "the intact restart's")

    # 2 ranks: each processor folder has its own record; a bit of processor1's p is named.
    stopped2 = runner.fresh_case("periodic_box", "files_stopped_np2", edits)
    runner.solve(stopped2, 2)
    case = restart_case(stopped2, "files_p_bit_np2")
    p = os.path.join(case, "processor1", "0.001", "p")
    flip(p, first_value(p) + 5, 0)
    log = runner.run(case, "grainFoam.restart", runner.solver, ranks=2, expect_failure=True)
    checks.expect((p + ": FNV-1a checksum") in log and not stack_trace(log),
                  "2 ranks, processor1's p with one flipped bit: refused, naming that file")


def restart_bed_surface(runner, checks):
    """coupling.restart's bit-identical restarts on 1 and 2 ranks with the bed-surface keys
    dragVoidFraction sharpInterface and facePressure dragSeries (docs/models/bed-surface.md):
    the beads pile on the floor, so cells are read as two layers and the face pressures
    follow the layers' resistances, which the first samples after the restart read from Ksl
    (taken as written, in the uninterrupted run's sum order)."""
    restart(runner, checks, "dragVoidFraction sharpInterface;\nfacePressure dragSeries;\n",
            other_rank_count=False)


# --- coupling.stop_signal ---------------------------------------------------------------


def run_until_signalled(runner, case, ranks, after_time):
    """Starts grainFoam, sends SIGTERM to one process (serial: grainFoam; parallel: rank 1
    only, so the others learn it through the agreement) once the log reaches `after_time`,
    and returns (exit code, log)."""
    cmd = [runner.foam_env]
    if ranks > 1:
        cmd += [runner.mpiexec, "-np", str(ranks), "--oversubscribe"]
    cmd += [runner.solver, "-case", case] + (["-parallel"] if ranks > 1 else [])
    log_path = os.path.join(case, "log.grainFoam.signalled")
    with open(log_path, "w") as log:
        proc = subprocess.Popen(cmd, cwd=case, env=runner.env, stdout=log,
                                stderr=subprocess.STDOUT)
        deadline = time.monotonic() + 120
        target = None
        while time.monotonic() < deadline and proc.poll() is None:
            with open(log_path) as f:
                reached = f"Time = {after_time}\n" in f.read()
            if reached:
                if ranks == 1:
                    target = proc.pid
                else:
                    children = subprocess.run(["pgrep", "-P", str(proc.pid)], text=True,
                                              stdout=subprocess.PIPE).stdout.split()
                    target = int(sorted(children, key=int)[-1]) if children else None
                if target is not None:
                    os.kill(target, signal.SIGTERM)
                break
            time.sleep(0.05)
        code = proc.wait(timeout=120)
    with open(log_path) as f:
        return code, f.read(), target


def stop_signal(runner, checks):
    """SIGTERM in the middle of a coupled run (the case of coupling.restart): the solver
    finishes the fluid step, writes the fields and the DEM checkpoint at that time, says so
    and exits 0; a restart from that time (startFrom latestTime) continues to the end.
    Reference: the same case run to exactly that time (endTime), then restarted; the two
    must end bit-identical, particles and fields. (Writing a checkpoint rebuilds the DEM's
    lists, which changes summation orders, so a run that wrote no checkpoint at that time
    would differ in the last bits; coupling.restart shows that a restart equals the run that
    wrote the checkpoint.) On 2 ranks only one rank is signalled: the ranks agree on it after
    every fluid step and all stop at the same one."""
    end_time = "0.04"
    edits = [("0/U", "internalField   uniform (0 0 0);", "internalField   uniform (0.05 0.02 0);"),
             ("particles.yaml", "gravity: [0, 0, -9.81]", "gravity: [0, 0, -98.1]"),
             ("system/controlDict", "endTime         2e-4;", "endTime         4e-2;"),
             ("system/controlDict", "writeInterval   1;", "writeInterval   200;"),
             ("system/controlDict", "writeFormat     ascii;", "writeFormat     binary;")]

    def restart_to_end(case, ranks):
        path = os.path.join(case, "system", "controlDict")
        with open(path) as f:
            text = re.sub(r"endTime\s+\S+;", "endTime         4e-2;", f.read())
            text = re.sub(r"writeInterval\s+\S+;", "writeInterval   200;", text)
        with open(path, "w") as f:
            f.write(text.replace("startFrom       startTime;", "startFrom       latestTime;"))
        log = runner.run(case, "grainFoam.restart", runner.solver, ranks=ranks)
        if ranks > 1:
            runner.run(case, "reconstructPar.all", "reconstructPar", "-latestTime")
        return log

    for ranks in (1, 2):
        case = runner.fresh_case("periodic_box", f"signalled_np{ranks}", edits)
        runner.run(case, "blockMesh", "blockMesh")
        if ranks > 1:
            runner.run(case, "decomposePar", "decomposePar")
        code, log, target = run_until_signalled(runner, case, ranks, "0.013")
        checks.expect(target is not None, f"np {ranks}: SIGTERM sent to process {target}")
        stopped = re.search(r"grainFoam: received SIGTERM; stopped after time (\S+) \(time index "
                            r"(\d+)\) and wrote it with the DEM checkpoint", log)
        checks.expect(code == 0 and stopped is not None,
                      f"np {ranks}: exit code {code} (0) and the stop message")
        if stopped is None:
            continue
        at = stopped.group(1)
        checks.expect(0.013 <= float(at) < 0.02,
                      f"np {ranks}: stopped at t = {at} s, after the signal, before the next write")
        folder = os.path.join(case, at) if ranks == 1 else os.path.join(case, "processor0", at)
        checks.expect(os.path.exists(os.path.join(folder, "uniform", "grainflowCheckpoint")),
                      f"np {ranks}: time {at} written with its checkpoint record")
        log = restart_to_end(case, ranks)
        checks.expect(f"restart at time {at}" in log, f"np {ranks}: restarted at {at}")

        index = int(stopped.group(2))  # the reference writes there, and only there
        reference = runner.fresh_case("periodic_box", f"reference_np{ranks}", edits + [
            ("system/controlDict", "endTime         4e-2;", f"endTime         {at};"),
            ("system/controlDict", "writeInterval   200;", f"writeInterval   {index};")])
        runner.solve(reference, ranks)
        restart_to_end(reference, ranks)
        a, b = snapshots(reference)[-1], snapshots(case)[-1]
        for key in ("id", "position", "velocity"):
            same = a[1][key].shape == b[1][key].shape and np.array_equal(a[1][key], b[1][key])
            checks.expect(same and a[0] == b[0] and abs(b[0] - 0.04) < 1e-12,
                          f"np {ranks}: every particle's {key} at t = {b[0]:.4g} s equal to the "
                          f"reference's to the last bit")
        for field in ("U", "p", "phi", "voidfraction"):
            same = (read_foam_binary_or_ascii(reference, end_time, field) ==
                    read_foam_binary_or_ascii(case, end_time, field))
            checks.expect(same, f"np {ranks}: {field} at t = {end_time} equal byte for byte")

# --- coupling.nan_guard -----------------------------------------------------------------


def nan_guard(runner, checks):
    """The NaN / Inf guard in a coupled run: cases/periodic_box runs 10 fluid steps and
    writes its checkpoint; the velocity of one bead that touches nothing is set to NaN
    (h5py) and the run is restarted from it (refused as not the checkpoint written with that
    time, then accepted as the message says). The first DEM step must stop grainFoam with an
    error naming that particle, its non-finite state and its forces (not OpenFOAM's
    floating-point trap, which the DEM steps run without), and write every particle of
    that step to particles/diagnostic_000000.h5 — on 1 rank and on 2."""
    for ranks in (1, 2):
        case = runner.fresh_case("periodic_box", f"nan_np{ranks}", [
            ("system/controlDict", "endTime         2e-4;", "endTime         1e-3;"),
            ("system/controlDict", "writeInterval   1;", "writeInterval   10;")])
        runner.solve(case, ranks)
        checkpoint = os.path.join(case, "particles", "checkpoint_000000100.h5")
        with h5py.File(checkpoint, "r+") as f:
            ids, x = f["particles/id"][:], f["particles/position"][:]
            r = f["particles/radius"][:]
            # A bead touching nothing (periodic minimum image along x and y): the NaN must
            # not reach a contact partner within the step, so the guard names this one.
            d = x[:, None, :] - x[None, :, :]
            d[:, :, :2] -= BOX * np.round(d[:, :, :2] / BOX)
            gap = np.linalg.norm(d, axis=2) - (r[:, None] + r[None, :])
            np.fill_diagonal(gap, np.inf)
            alone = np.flatnonzero(gap.min(axis=1) > 1e-4)
            k = int(alone[len(alone) // 2])
            victim = int(ids[k])
            v = f["particles/velocity"][:]
            v[k, 0] = float("nan")
            f["particles/velocity"][...] = v
        path = os.path.join(case, "system", "controlDict")
        with open(path) as f:
            text = f.read().replace("endTime         1e-3;", "endTime         2e-3;")
        with open(path, "w") as f:
            f.write(text.replace("startFrom       startTime;", "startFrom       latestTime;"))
        # The edited checkpoint is not the one written with that time: refused, and accepted
        # as the message says (an edit made on purpose).
        log = runner.run(case, "grainFoam.edited", runner.solver, ranks=ranks,
                         expect_failure=True)
        checks.expect("is not the DEM checkpoint grainFoam wrote with this time" in log,
                      f"np {ranks}: the edited checkpoint is refused at first")
        for folder in ([case] if ranks == 1 else
                       [os.path.join(case, f"processor{i}") for i in range(ranks)]):
            for name, drop in (("uniform/grainflowCheckpoint", "checkpointChecksum"),
                               ("grainflowChecksums", '"uniform/grainflowCheckpoint"')):
                path = os.path.join(folder, "0.001", name)
                with open(path) as f:
                    lines = f.read().splitlines(keepends=True)
                with open(path, "w") as f:
                    f.writelines(line for line in lines if not line.startswith(drop))
        log = runner.run(case, "grainFoam.nan", runner.solver, ranks=ranks, expect_failure=True)
        # The first step's drift carries the NaN from the velocity into the position.
        named = re.search(rf"step 101 \(t = 0.00101 s\): particle {victim} \(rank \d+\) has a "
                          r"non-finite (position|velocity); position \(nan, .*\) m, "
                          r"velocity \(nan, .*force \(", log)
        checks.expect(named is not None, f"np {ranks}: the error names step 101, particle "
                                         f"{victim}, its NaN state and its force")
        diagnostic = os.path.join(case, "particles", "diagnostic_000000.h5")
        count = 0
        if os.path.exists(diagnostic):
            with h5py.File(diagnostic, "r") as f:
                count = int(f.attrs["count"])
        checks.expect(count == 307 and "diagnostic_000000.h5" in log,
                      f"np {ranks}: the log names the diagnostic snapshot, which holds {count} "
                      f"particles (307)")


# --- coupling.scene_output --------------------------------------------------------------

def scene_output(runner, checks):
    """What grainFoam takes from the scene's output block and time.end (docs/coupling.md),
    on cases/neutral_particle (deltaT 1e-3 s, endTime 0.1 s, write times 0.05 and 0.1 s)
    with the bead 1 % denser than the water, so that it sinks.

    1. output: {directory: out/beads, snapshot_interval: 0.004}. Reference, from the
       definition (a snapshot at the start and at the fluid step nearest each multiple of
       the interval): 0.1 / 0.004 + 1 = 26 snapshots at t = 0.004 k, k = 0..25, each within
       1e-9 s of it (the fluid time sums 1e-3 s steps: round-off is 1e-16 s), all in
       <case>/out/beads, with the two write times' checkpoints there and no particles/.
       The bead keeps sinking between them (its depth falls monotonically), so they are
       snapshots of the run, not copies of one state.
       The start-up accuracy line names the regime, a single particle, and quotes no
       packed-bed (Ergun) figure.
    2. time.end 0.03 s, earlier than endTime: the last fluid step is t = 0.03 s (30 steps),
       and the log says so naming particle.yaml:9 (the end key).
    3. output.log_interval is refused naming particle.yaml and its line and what grainFoam
       uses instead (writeInterval); a snapshot_interval shorter than deltaT is refused
       naming deltaT."""
    denser = ("particle.yaml", "poisson_ratio: 0.3, density: 1000", "poisson_ratio: 0.3, density: 1010")
    case = runner.fresh_case("neutral_particle", "output_block", [
        denser,
        ("particle.yaml", "fluid:\n", "output: {directory: out/beads, snapshot_interval: 0.004}\nfluid:\n")])
    log = runner.solve(case, 1)
    checks.expect(not os.path.exists(os.path.join(case, "particles")),
                  "output.directory: no <case>/particles folder")
    snaps = snapshots(case, os.path.join("out", "beads")) if os.path.isdir(
        os.path.join(case, "out", "beads")) else []
    times = [t for t, _ in snaps]
    want = [0.004 * k for k in range(26)]
    checks.expect(len(times) == 26 and all(abs(a - b) < 1e-9 for a, b in zip(times, want)),
                  f"snapshot_interval 0.004 s: {len(times)} snapshots (26) at "
                  f"{', '.join(f'{t:g}' for t in times[:4])}, ... {times[-1] if times else ''}"
                  " (0, 0.004, ..., 0.1)")
    depths = [s["position"][0][2] for _, s in snaps]
    checks.expect(len(depths) > 2 and all(b < a for a, b in zip(depths, depths[1:])),
                  "the bead sinks from one snapshot to the next")
    folder = os.path.join(case, "out", "beads")
    checkpoints = sorted(n for n in os.listdir(folder) if n.startswith("checkpoint_")) if os.path.isdir(folder) else []
    checks.expect(len(checkpoints) == 2,
                  f"the write times' DEM checkpoints are in out/beads: {checkpoints} (2)")
    accuracy = [line for line in log.splitlines() if "accuracy (docs/accuracy-vs-cost-coupled.md)" in line]
    checks.expect(len(accuracy) == 1 and "single particle" in accuracy[0] and "Ergun" not in log,
                  f"accuracy line: a single particle, no packed-bed figure ({accuracy})")

    case = runner.fresh_case("neutral_particle", "time_end", [denser, ("particle.yaml", "  end: 1\n", "  end: 0.03\n")])
    log = runner.solve(case, 1)
    steps = re.findall(r"^Time = (\S+)$", log, re.MULTILINE)
    checks.expect(len(steps) == 30 and abs(float(steps[-1]) - 0.03) < 1e-12,
                  f"time.end 0.03 s before endTime 0.1 s: {len(steps)} fluid steps, the last at "
                  f"t = {steps[-1] if steps else None} (30, 0.03)")
    checks.expect(re.search(r"grainFoam: ends at t = 0.03 s, the scene's time.end \(\S*particle\.yaml:9\)", log)
                  is not None, "the log says the run ends at the scene's time.end, particle.yaml:9")
    checks.expect(re.search(r"grainFoam: stopped at the scene's time.end, t = 0.03 s \(\S*particle\.yaml:9\), "
                            r"before system/controlDict's endTime 0.1 s; to run longer, raise both\nEnd", log)
                  is not None, "the log's last lines say the scene's time.end stopped the run before endTime")

    case = runner.fresh_case("neutral_particle", "log_interval", [
        ("particle.yaml", "fluid:\n", "output:\n  log_interval: 0.01\nfluid:\n")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    checks.expect(re.search(r"particle\.yaml:17: error: output\.log_interval is not used by a coupled "
                            r"run: .*writeInterval", log) is not None,
                  "output.log_interval: refused at particle.yaml:17, naming writeInterval")
    case = runner.fresh_case("neutral_particle", "short_interval", [
        ("particle.yaml", "fluid:\n", "output: {snapshot_interval: 5e-4}\nfluid:\n")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    checks.expect(re.search(r"particle\.yaml:16: error: output\.snapshot_interval 0\.0005 s is shorter "
                            r"than the fluid time step deltaT 0\.001 s", log) is not None,
                  "snapshot_interval 5e-4 s < deltaT 1e-3 s: refused at particle.yaml:16")


# --- coupling.heat_equilibrium, coupling.heat_balance -----------------------------------

HEAT_EXCHANGE_LINE = re.compile(
    r"grainFoam heat exchange: particles took " + FLOAT + r" J from the fluid in the last step, "
    r"the fluid " + FLOAT + r" J from the particles, relative imbalance " + FLOAT +
    r"; since the run's start: particles " + FLOAT + r" J, fluid " + FLOAT + r" J; lost "
    r"\(outside the mesh\) " + FLOAT + " J")
THERMAL_ENERGY_LINE = re.compile(
    r"grainFoam thermal energy: particles " + FLOAT + r" J \(m c " + FLOAT + r" J/K\), fluid " +
    FLOAT + r" J \(eps rho c_p V " + FLOAT + r" J/K\), sum " + FLOAT + " J")
TIME_LINE = re.compile(r"^Time = " + FLOAT + "$", re.MULTILINE)


def heat_lines(log):
    """[(time, exchange line values, thermal energy values)] of every heat report."""
    out = []
    for m in HEAT_EXCHANGE_LINE.finditer(log):
        times = TIME_LINE.findall(log, 0, m.start())
        energy = THERMAL_ENERGY_LINE.search(log, m.end())
        out.append((float(times[-1]) if times else float("nan"),
                    [float(x) for x in m.groups()],
                    [float(x) for x in energy.groups()] if energy else None))
    return out


def check_heat_balance(checks, label, lines, expected):
    """Every reported step: the particles' heat is the fluid's loss to round-off."""
    checks.expect(len(lines) == expected, f"{label}: {len(lines)} heat reports, {expected} expected")
    worst = max((v[2] for _, v, _ in lines), default=float("nan"))
    total = max((abs(v[3] + v[4]) / max(abs(v[3]), 1e-300) for _, v, _ in lines),
                default=float("nan"))
    lost = max((abs(v[5]) for _, v, _ in lines), default=float("nan"))
    checks.expect(worst < ROUND_OFF and total < ROUND_OFF and lost == 0,
                  f"{label}: heat taken by the particles = heat lost by the fluid, per step "
                  f"(worst relative imbalance {worst:.3g}) and since the start ({total:.3g}) < "
                  f"1e-12, none lost ({lost:g} J)")


def check_heated_box(checks, label, log):
    """The closed form of cases/heated_box (eight 1 mm beads, or parcels standing for them, at
    400 K held still in closed air at 300 K): the mixture's thermal energy
    sum m c T + eps rho c_p V T is conserved; the beads' mean temperature approaches
    T_eq = (C_p T_p0 + C_f T_f0) / (C_p + C_f) as exp(-t / tau), tau = 1 / (H (1/C_p + 1/C_f)),
    H = 8 Nu k_f pi d with Nu = 2 (Ranz-Marshall at Re = 0), C_p = 8 m c and
    C_f = rho c_p (V_box - 8 V_p), all from the case's numbers, not from the solver; the
    discretisation's lag (backward Euler, dt / tau = 0.0036) stays under 0.5 % of
    T_p0 - T_eq. Returns the heat reports."""
    d, n, rho_p, c_p, k_f, rho_f, c_f = 1e-3, 8, 2500.0, 7.0, 0.026, 1.2, 1000.0
    vp = math.pi / 6 * d ** 3
    cap_p = n * rho_p * vp * c_p
    cap_f = rho_f * c_f * (0.004 ** 3 - n * vp)
    t_p0, t_f0 = 400.0, 300.0
    t_eq = (cap_p * t_p0 + cap_f * t_f0) / (cap_p + cap_f)
    tau = 1 / (n * 2 * k_f * math.pi * d * (1 / cap_p + 1 / cap_f))
    lines = heat_lines(log)
    check_heat_balance(checks, label, lines, 11)
    energies = [e for _, _, e in lines if e]
    checks.expect(len(energies) == len(lines), f"{label}: a thermal energy line after each heat report")
    if not energies:
        return lines
    checks.expect(abs(energies[0][1] - cap_p) <= 1e-12 * cap_p and
                  abs(energies[0][3] - cap_f) <= 1e-12 * cap_f,
                  f"{label}: heat capacities: particles {energies[0][1]:.10g} J/K (8 m c = "
                  f"{cap_p:.10g}), air {energies[0][3]:.10g} J/K (rho c_p (V - 8 V_p) = {cap_f:.10g})")
    e0 = cap_p * t_p0 + cap_f * t_f0
    drift = max(abs(e[4] - e0) / e0 for e in energies)
    checks.expect(drift < ROUND_OFF, f"{label}: mixture energy sum m c T + eps rho c_p V T "
                                     f"conserved: largest relative change {drift:.3g} < 1e-12")
    worst = 0.0
    for (t, _, e) in lines:
        exact_p = t_eq + (t_p0 - t_eq) * math.exp(-t / tau)
        exact_f = t_eq + (t_f0 - t_eq) * math.exp(-t / tau)
        err_p = abs(e[0] / e[1] - exact_p) / (t_p0 - t_eq)
        err_f = abs(e[2] / e[3] - exact_f) / (t_eq - t_f0)
        worst = max(worst, err_p, err_f)
        print(f"    t = {t:.4f} s: particles {e[0] / e[1]:.4f} K (closed form {exact_p:.4f} K), "
              f"air {e[2] / e[3]:.4f} K ({exact_f:.4f} K)")
    checks.expect(worst < 5e-3, f"{label}: mean temperatures against T_eq + (T_0 - T_eq) "
                                f"exp(-t/tau), T_eq = {t_eq:.4f} K, tau = {tau * 1e3:.3f} ms: "
                                f"largest error {100 * worst:.3f} % of the initial difference < 0.5 %")
    return lines


def heat_equilibrium(runner, checks):
    """cases/heated_box: eight 1 mm beads at 400 K held still (no gravity, no flow) in
    closed air at 300 K, one per cell. Closed forms: the mixture's thermal energy
    sum m c T + eps rho c_p V T is conserved; the beads' mean temperature approaches
    T_eq = (C_p T_p0 + C_f T_f0) / (C_p + C_f) as exp(-t / tau), tau = 1 / (H (1/C_p + 1/C_f)),
    H = 8 Nu k_f pi d with Nu = 2 (Ranz-Marshall at Re = 0), C_p = 8 m c and
    C_f = rho c_p (V_box - 8 V_p), all from the case's numbers, not from the solver; the
    discretisation's lag (backward Euler, dt / tau = 0.0036) stays under 0.5 % of
    T_p0 - T_eq. Restart: 0.05 s, then startFrom latestTime to 0.1 s, ends with the same
    T field and thermal energies as the uninterrupted run, to the last digit written."""
    case = runner.fresh_case("heated_box", "equilibrium")
    lines = check_heated_box(checks, "heated box", runner.solve(case, 1))
    # Set-ups refused: transportProperties without kappa, Cp unlike the scene's, a scene with
    # heat but no convection keys in its fluid block.
    for name, edits, pattern in (
            ("no_kappa", [("constant/transportProperties", "kappa   0.026;\n", "")],
             r"transportProperties\"? needs `kappa  <W/\(m K\)>;`"),
            ("cp_differs", [("constant/transportProperties", "Cp      1000;", "Cp      1005;")],
             r"particles\.yaml:\d+: error: fluid\.heat_capacity is 1000 J/\(kg K\) but .*"
             r"transportProperties has Cp 1005"),
            ("no_convection", [("particles.yaml", "  temperature: 300 ", "  # temperature: 300 "),
                               ("particles.yaml", "  heat_capacity: 1000\n", ""),
                               ("particles.yaml", "  conductivity: 0.026\n", ""),
                               ("particles.yaml", "  convection: ranz_marshall\n", "")],
             r"particles\.yaml:\d+: error: heat is on .*the fluid block has no convection "
             r"settings")):
        bad = runner.fresh_case("heated_box", name, edits)
        runner.run(bad, "blockMesh", "blockMesh")
        out = runner.run(bad, "grainFoam", runner.solver, expect_failure=True)
        checks.expect(re.search(pattern, out, re.DOTALL) is not None,
                      f"{name}: refused with /{pattern}/")
    # Restart: stop at 0.05 s, continue to 0.1 s.
    part = runner.fresh_case("heated_box", "equilibrium_restart", [
        ("system/controlDict", "endTime         0.1;", "endTime         0.05;")])
    runner.solve(part, 1)
    with open(os.path.join(part, "system", "controlDict")) as f:
        text = f.read()
    with open(os.path.join(part, "system", "controlDict"), "w") as f:
        f.write(text.replace("endTime         0.05;", "endTime         0.1;").replace(
            "startFrom       startTime;", "startFrom       latestTime;"))
    restarted = heat_lines(runner.run(part, "grainFoam.restart", runner.solver))
    a = read_scalar_field(os.path.join(case, "0.1", "T"))
    b = read_scalar_field(os.path.join(part, "0.1", "T"))
    checks.expect(a.shape == b.shape and np.array_equal(a, b) and restarted and
                  lines and restarted[-1][2] == lines[-1][2],
                  f"restart at 0.05 s: T at 0.1 s and the final thermal energies as the "
                  f"uninterrupted run's, to the last digit "
                  f"({restarted[-1][2] if restarted else None} vs {lines[-1][2] if lines else None})")


def heat_parcels(runner, checks):
    """cases/heated_box with its eight beads as one parcel of k = 2 (real d = 1 mm, parcel
    d = 2 mm) at the box's centre, in one 4 mm cell: the parcel's heat capacity is the
    eight beads' and its convective conductance eight times a bead's (Ranz-Marshall for the
    real d at Re = 0: Nu = 2; docs/models/coarse-graining.md, "Heat transfer"), so the
    closed form of coupling.heat_equilibrium holds unchanged: the mixture's energy conserved
    to 1e-12, the exchange balanced to round-off, the mean temperatures on
    T_eq + (T_0 - T_eq) exp(-t/tau) within 0.5 % of the initial difference. A bead of the
    parcel's size (k = 1, d = 2 mm) would relax with tau 4 times longer."""
    # One cell: the closed form assumes well-mixed air, which the eight beads' symmetric
    # cells give; a parcel centred on the cells' common corner would not (the `divided`
    # footprint puts its sub-volumes on the faces into the upper cells).
    case = runner.fresh_case("heated_box", "parcel", [
        ("system/blockMeshDict", "(2 2 2)", "(1 1 1)"),
        ("system/fvSolution", "solver GAMG; smoother DIC;", "solver PCG; preconditioner DIC;"),
        ("particles.yaml", "  - {type: csv, file: beads.csv, material: glass, temperature: 400}",
         "  - {type: fill, region: {box: {min: [0.001, 0.001, 0.001], max: [0.003, 0.003, 0.003]}},\n"
         "     count: 1, material: glass, radius: {distribution: constant, value: 5e-4},\n"
         "     coarse_grain: 2, temperature: 400}")])
    check_heated_box(checks, "parcel", runner.solve(case, 1))
    snaps = snapshots(case)
    last = snaps[-1][1] if snaps else {}
    checks.expect(len(last.get("real_count", [])) == 1 and last["real_count"][0] == 8 and
                  last["coarse_grain"][0] == 2 and
                  np.allclose(last["position"][0], 0.002, rtol=0, atol=1e-12),
                  f"the last snapshot holds one parcel of k = 2 standing for 8 real beads, at "
                  f"the box's centre ({last.get('position')})")


def heated_bed(runner, name, ranks, parcels=False, bead_temperature=350, extra=()):
    """cases/periodic_box with heat on: the beads (glass, 350 K) rain at 10 g through water
    at 300 K flowing at (0.05 0.02 0) m/s; 100 fluid steps, written every 20. `parcels`: the
    fill's 300 beads become 38 parcels of k = 2 (304 real beads) among the csv's real ones;
    `extra`: more edits of the case."""
    extra = list(extra) + ([("particles.yaml", "    count: 300\n",
                             "    count: 38\n    coarse_grain: 2\n")] if parcels else [])
    case = runner.fresh_case("periodic_box", name, extra + [
        ("0/U", "internalField   uniform (0 0 0);", "internalField   uniform (0.05 0.02 0);"),
        ("particles.yaml", "gravity: [0, 0, -9.81]", "gravity: [0, 0, -98.1]\nheat: {}"),
        ("particles.yaml", "density: 2500}",
         "density: 2500, heat_capacity: 840, conductivity: 1}"),
        ("particles.yaml", "file: straddling.csv, material: glass}",
         f"file: straddling.csv, material: glass, temperature: {bead_temperature}}}"),
        ("particles.yaml", "    material: glass\n",
         f"    material: glass\n    temperature: {bead_temperature}\n"),
        ("particles.yaml", "  forces: [drag, pressure_gradient, viscous, buoyancy]",
         "  forces: [drag, pressure_gradient, viscous, buoyancy]\n  temperature: 300\n"
         "  heat_capacity: 4180\n  conductivity: 0.6\n  convection: gunn"),
        ("constant/transportProperties", "nu      1e-6;", "nu      1e-6;\nCp      4180;\nkappa   0.6;"),
        ("system/controlDict", "endTime         2e-4;", "endTime         1e-2;"),
        ("system/controlDict", "writeInterval   1;", "writeInterval   20;"),
        ("system/fvSchemes", "    div(phi,U)      Gauss limitedLinearV 1;",
         "    div(phi,U)      Gauss limitedLinearV 1;\n    div(phi,T)      Gauss limitedLinear 1;"),
        ("system/fvSolution", "    pFinal { $p; relTol 0; }",
         "    pFinal { $p; relTol 0; }\n    T { solver PBiCGStab; preconditioner DILU; "
         "tolerance 1e-15; relTol 0; }")])
    with open(os.path.join(case, "0", "p")) as f:
        text = f.read()
    with open(os.path.join(case, "0", "T"), "w") as f:
        f.write(text.replace("object      p;", "object      T;").replace(
            "[0 2 -2 0 0 0 0]", "[0 0 0 1 0 0 0]").replace("uniform 0;", "uniform 300;"))
    return case, runner.solve(case, ranks)


def heat_balance(runner, checks):
    """The heat balance of a moving bed on 1 and 2 ranks (cases/periodic_box with heat:
    Gunn's law, beads crossing the processor plane and the periodic faces): at every write
    time the heat the particles took equals the heat the fluid lost, to round-off, and the
    mixture's thermal energy (walls adiabatic, box periodic) stays what it was; the two rank
    counts agree on the exchanged heat within 1 %. Then the same on 2 ranks with the fill's
    beads as parcels of k = 2 among the real ones; and with ddtVoidFraction off, beads and
    water at 300 K: every temperature stays at 300 K."""
    finals = {}
    for ranks in (1, 2):
        case, log = heated_bed(runner, f"heat_balance_np{ranks}", ranks)
        lines = heat_lines(log)
        check_heat_balance(checks, f"np {ranks}", lines, 6)
        energies = [e for _, _, e in lines if e]
        if not energies:
            continue
        drift = max(abs(e[4] - energies[0][4]) / energies[0][4] for e in energies)
        exchanged = lines[-1][1][3]
        # Scale: 307 beads of ~1.6 mm, h ~ Nu k / d with Nu ~ 2-10, 50 K, 10 ms: ~0.1-1 J.
        checks.expect(drift < 1e-12 and exchanged < -0.01,
                      f"np {ranks}: the beads gave the water {-exchanged:.6g} J in 10 ms; the "
                      f"mixture's thermal energy changed by {drift:.3g} of itself (< 1e-12)")
        finals[ranks] = exchanged
    # Coarse-grained parcels among real beads, on 2 ranks (heat with parcels,
    # docs/models/coarse-graining.md): the same balance and conservation.
    case, log = heated_bed(runner, "heat_balance_parcels_np2", 2, parcels=True)
    lines = heat_lines(log)
    check_heat_balance(checks, "parcels np 2", lines, 6)
    energies = [e for _, _, e in lines if e]
    if energies:
        drift = max(abs(e[4] - energies[0][4]) / energies[0][4] for e in energies)
        exchanged = lines[-1][1][3]
        snaps = snapshots(case)
        k = snaps[-1][1].get("coarse_grain", np.ones(1)) if snaps else np.ones(1)
        checks.expect(drift < 1e-12 and exchanged < -0.01 and int((k == 2).sum()) == 38,
                      f"parcels np 2: 38 parcels of k = 2 ({int((k == 2).sum())} in the last "
                      f"snapshot) and the real beads gave the water {-exchanged:.6g} J in 10 ms; "
                      f"the mixture's thermal energy changed by {drift:.3g} of itself (< 1e-12)")
    # ddtVoidFraction off, beads and water both at 300 K: nothing may change a temperature.
    # The conservative storage term d(eps T)/dt, under a continuity without d(eps)/dt, turned
    # each change of eps into one of T (the random coupled scenes found the fluid 73 K outside
    # its starting and inlet temperatures); eps dT/dt keeps T where the flux, diffusion and
    # exchange put it. Tolerance: the pressure solve leaves div(phi) at its tolerance, which
    # the flux term turns into T div(phi) (1e-6 of T).
    case, log = heated_bed(runner, "heat_isothermal_ddt_off", 1, bead_temperature=300, extra=[
        ("constant/couplingProperties", "ddtVoidFraction on;", "ddtVoidFraction off;")])
    worst = 0.0
    for folder in time_folders(case):
        t = read_scalar_field(os.path.join(case, folder, "T"))
        worst = max(worst, float(np.max(np.abs(t - 300))))
    hottest = max((float(np.max(np.abs(s["temperature"] - 300))) for _, s in snapshots(case)),
                  default=float("nan"))
    checks.expect(len(time_folders(case)) == 5 and worst < 3e-4 and hottest < 3e-4,
                  f"ddtVoidFraction off, all at 300 K: fluid T within {worst:.3g} K and the "
                  f"beads within {hottest:.3g} K of 300 K at every write (< 3e-4 K)")
    if len(finals) == 2:
        diff = abs(finals[1] - finals[2]) / abs(finals[1])
        # Not to round-off: the colliding bed amplifies the sums' order, and a bead that
        # crosses the processor plane gives the heat of its last sub-steps on the old rank
        # to the cell nearest to where it took it, not through its footprint.
        checks.expect(diff < 1e-2, f"heat given on 1 and 2 ranks agree: relative difference "
                                   f"{diff:.3g} < 1e-2")


# --- coupling.heat_front ------------------------------------------------------------------

BED_D = 3e-3                  # cases/heated_bed: beads of 3 mm on a simple cubic lattice
BED_LAYERS = 24               # 4 x 4 beads per layer: a 72 mm bed
BED_COLUMN = (0.012, 0.084)   # column width and height (mesh and DEM domain)
BED_T0, BED_TIN = 300.0, 400.0


def heated_bed_reference():
    """The bed's numbers from the case files (not from the solver): eps of the lattice,
    air and glass as in particles.yaml and transportProperties, h from Gunn (1978)."""
    return schumann.Bed(d=BED_D, eps=1 - math.pi / 6, u=0.8, rho_f=1.2, mu=1.8e-5,
                        c_f=1000.0, k_f=0.026, rho_s=2500.0, c_s=6.0)


def heat_front_profiles(case, bed):
    """Per write time: (t, fluid front, solid front, worst |theta_f - Schumann| over the bed's
    cells) measured from the T field (cell averages over each layer of cells, the inlet
    value at z = 0) and the snapshots (mean temperature of each layer of beads), and the
    largest bead displacement from the lattice site it started on (bed.csv: the nearest site,
    the beads moving far less than d / 2)."""
    out = []
    snaps = dict((round(t, 6), p) for t, p in snapshots(case))
    moved = 0.0
    for folder in time_folders(case):
        t = float(folder)
        field = read_scalar_field(os.path.join(case, folder, "T"))
        per_layer = field.size // 4            # 2 x 2 cells per level, x fastest, z slowest
        dz = BED_COLUMN[1] / per_layer
        theta = (field.reshape(per_layer, 4).mean(axis=1) - BED_T0) / (BED_TIN - BED_T0)
        zc = (np.arange(per_layer) + 0.5) * dz
        fluid = schumann.crossing(np.concatenate(([0.0], zc)), np.concatenate(([1.0], theta)))
        in_bed = zc < BED_LAYERS * BED_D
        profile_error = max(abs(th - bed.fluid(z, t)) for z, th in zip(zc[in_bed], theta[in_bed]))
        solid = float("nan")
        p = snaps.get(round(t, 6))
        if p is not None:
            z = p["position"][:, 2]
            layer = np.floor(z / BED_D).astype(int)
            zl = np.array([z[layer == k].mean() for k in range(BED_LAYERS)])
            tl = np.array([p["temperature"][layer == k].mean() for k in range(BED_LAYERS)])
            solid = schumann.crossing(zl, (tl - BED_T0) / (BED_TIN - BED_T0))
            site = (np.floor(p["position"] / BED_D) + 0.5) * BED_D
            moved = max(moved, float(np.max(np.linalg.norm(p["position"] - site, axis=1))))
        out.append((t, fluid, solid, profile_error))
    return out, moved


def heat_front(runner, checks):
    """cases/heated_bed: 384 beads (d = 3 mm, simple cubic lattice, eps = 1 - pi/6) resting
    on a distributor, 72 mm of bed, air at 400 K entering at 0.8 m/s into the bed at 300 K
    (contact conduction off, 2 x 2 x 28 cells, 2 d across and d high, 50 DEM steps per fluid
    step of 1 ms).
    Reference (tests/coupling/schumann.py, numpy only): Schumann's (1929) solution of plug
    flow through a bed of lumped particles without axial conduction, with h from Gunn's
    (1978) correlation written out there (Re = 160, Pr = 0.692, Nu = 23.30); the front is
    where theta = (T - T_0) / (T_in - T_0) = 1/2, of the fluid (the T field) and of the beads
    (each layer's mean temperature), at 0.1, 0.2, 0.3 and 0.4 s: within 5 %. What the
    reference neglects and the run has: the fluid's axial conduction eps k_f d2T/dz2, whose
    effect on the front is computed (Laplace-transform solution with it, < 0.1 %); the
    beads' motion (they settle by their contacts' overlap: < 0.1 d, checked). The exchange
    is balanced at every write time as in heat_balance."""
    bed = heated_bed_reference()
    print(f"  bed: eps = {bed.eps:.4f}, Re = {bed.re:.2f}, Pr = {bed.pr:.4f}, Gunn Nu = "
          f"{bed.nu:.3f}, h = {bed.h:.2f} W/(m2 K), h a = {bed.h * bed.a:.4g} W/(m3 K), "
          f"h a z / (rho_f c_f U) = 1 at z = {1e3 / bed.xi(1.0):.2f} mm")
    z_bed = BED_LAYERS * BED_D
    check = schumann.self_check(bed, (0.1, 0.2, 0.3, 0.4), z_bed)
    checks.expect(check < 1e-8, f"Schumann's Bessel integral = Talbot inversion of its Laplace "
                                f"transform to {check:.2g} (< 1e-8)")
    case = runner.fresh_case("heated_bed", "heat_front")
    log = runner.solve(case, 1)
    lines = heat_lines(log)
    check_heat_balance(checks, "heated bed", lines, 5)
    profiles, moved = heat_front_profiles(case, bed)
    checks.expect(len(profiles) == 4, f"{len(profiles)} write times, 4 expected")
    checks.expect(moved < 0.1 * BED_D, f"the bed stays put: largest bead displacement "
                                       f"{moved * 1e3:.4f} mm = {moved / BED_D:.4f} d < 0.1 d")
    for t, fluid, solid, profile_error in profiles:
        ref_f = schumann.front(bed.fluid, t, z_bed)
        ref_s = schumann.front(bed.solid, t, z_bed)
        conducting = schumann.front(bed.fluid_conducting, t, z_bed, tol=1e-8)
        err_f, err_s = (fluid - ref_f) / ref_f, (solid - ref_s) / ref_s
        checks.expect(abs(err_f) < 0.05 and abs(err_s) < 0.05 and
                      abs(conducting - ref_f) < 1e-3 * ref_f,
                      f"t = {t:.1f} s: fluid front {1e3 * fluid:.3f} mm (Schumann {1e3 * ref_f:.3f} "
                      f"mm, {100 * err_f:+.2f} %), bead front {1e3 * solid:.3f} mm (Schumann "
                      f"{1e3 * ref_s:.3f} mm, {100 * err_s:+.2f} %), within 5 %; with the "
                      f"fluid's axial conduction the reference moves "
                      f"{100 * (conducting - ref_f) / ref_f:+.3f} %; largest |theta_f - "
                      f"Schumann| in the bed's cells {profile_error:.4f}")
    # What 5 % tells apart: the same reference with h halved or doubled.
    t = profiles[-1][0] if profiles else 0.4
    ref = schumann.front(bed.fluid, t, z_bed)
    for factor in (0.5, 2.0):
        other = schumann.Bed(bed.d, bed.eps, bed.u, bed.rho_f, bed.mu, bed.c_f, bed.k_f,
                             bed.rho_s, bed.c_s, h=factor * bed.h)
        z = schumann.front(other.fluid, t, z_bed)
        early = schumann.front(other.fluid, 0.1, z_bed)
        print(f"  (h x {factor:g}: the fluid front at {t:.1f} s would be {1e3 * z:.3f} mm, "
              f"{100 * (z - ref) / ref:+.2f} %; at 0.1 s "
              f"{100 * (early / schumann.front(bed.fluid, 0.1, z_bed) - 1):+.2f} %)")


# --- coupling.balanced_decomposition -----------------------------------------------------

BALANCE_LAYERS = 56           # the heated_bed column made twice as tall: 56 cell layers of 3 mm
PER_RANK_LINE = re.compile(r"^grainFoam rank (\d+) since the last write: (\d+) particles; DEM "
                           + FLOAT + r" s working \+ " + FLOAT + r" s waiting", re.M)


def slab_sums(values, k):
    return sum(values[:k]), sum(values[k:])


def expected_cuts(cells, particles, w, objective):
    """Every cut (layers on rank 0) that is best for the objective, found by trying them all,
    and the best value: `sum`, the larger slab's cells + w particles; `phases`, the larger
    slab's w particles plus the larger slab's cells (the DEM and the fluid each wait for
    their busiest rank)."""
    def value(k):
        if objective == "sum":
            return max(slab_sums([c + w * n for c, n in zip(cells, particles)], k))
        return max(slab_sums([w * n for n in particles], k)) + max(slab_sums(cells, k))
    values = {k: value(k) for k in range(1, len(cells))}
    best = min(values.values())
    return [k for k, v in values.items() if v <= best * (1 + 1e-12)], best


def balanced_decomposition(runner, checks):
    """scripts/balanced_decomposition.py on a bed settled at the bottom of a tall column:
    cases/heated_bed (384 beads, 24 layers of 16 on a 3 mm lattice, each layer in one layer
    of 2 x 2 cells) in a column made 168 mm tall (56 cell layers, the bed in the lowest 24),
    cut along z for 2 ranks. For each objective and particle cost w (cells per particle)
    tried, the script's constant/cellDecomposition must give every cell a rank, put the
    cells below one plane on rank 0 and the rest on rank 1, at a cut that is best for the
    objective, found here by trying every cut over the layers counted from bed.csv and the
    mesh's numbering (`sum`: the larger slab's cells + w particles least, w = 4: 13 layers;
    `phases`: the busier DEM slab's plus the busier fluid slab's least, w = 4: 12 layers; w =
    0.25: 28, the equal slabs, as the beads are too cheap to pay for the cells a lower cut
    moves to rank 1). grainFoam then runs 10 fluid steps on
    the `phases`, w = 4 decomposition (2 ranks): each rank owns the beads of its slab, the
    DEM's cut plane is the mesh's, and the momentum exchange balances to round-off."""
    height = 3e-3 * BALANCE_LAYERS
    case = runner.fresh_case("heated_bed", "balanced_decomposition", [
        ("system/blockMeshDict", "(0 0 84) (12 0 84) (12 12 84) (0 12 84)",
         "(0 0 168) (12 0 168) (12 12 168) (0 12 168)"),
        ("system/blockMeshDict", "(2 2 28)", f"(2 2 {BALANCE_LAYERS})"),
        ("particles.yaml", "max: [0.012, 0.012, 0.084]", f"max: [0.012, 0.012, {height:g}]"),
        ("system/controlDict", "endTime         0.4;", "endTime         0.01;"),
        ("system/controlDict", "writeInterval   0.1;", "writeInterval   0.005;")])
    runner.run(case, "blockMesh", "blockMesh")
    with open(os.path.join(case, "bed.csv")) as f:
        rows = [line for line in f if line.strip() and not line.startswith("#")]
    bed = np.loadtxt(rows[1:], delimiter=",")  # after the header x,y,z,radius
    layer_particles = np.bincount((bed[:, 2] / 3e-3).astype(int), minlength=BALANCE_LAYERS)
    layer_cells = [4] * BALANCE_LAYERS  # 2 x 2 cells per layer
    script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts",
                          "balanced_decomposition.py")
    k = None
    for objective, w in (("sum", 4.0), ("phases", 0.25), ("phases", 4.0)):
        best_cuts, best = expected_cuts(layer_cells, layer_particles, w, objective)
        r = subprocess.run([sys.executable, script, case, "--ranks", "2", "--axis", "z",
                            "--particles", os.path.join(case, "bed.csv"),
                            "--particle-cost", str(w), "--objective", objective],
                           env=runner.env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           text=True, timeout=120)
        print(r.stdout)
        what = f"{objective}, w = {w}"
        checks.expect(r.returncode == 0, f"{what}: the script ran")
        if r.returncode != 0:
            return
        with open(os.path.join(case, "constant", "cellDecomposition")) as f:
            text = f.read()
        m = re.search(r"\n(\d+)\s*\(([^)]*)\)", text)
        owner = np.array(m.group(2).split(), dtype=int) if m else np.array([], dtype=int)
        n = 4 * BALANCE_LAYERS
        layer = np.arange(n) // 4  # blockMesh numbers the cells x fastest, then y, then z
        checks.expect(m is not None and int(m.group(1)) == n and len(owner) == n and
                      set(owner.tolist()) <= {0, 1},
                      f"{what}: every one of the {n} cells has rank 0 or 1")
        k = int((owner == 0).sum()) // 4 if len(owner) == n else None
        checks.expect(k is not None and np.array_equal(owner, (layer >= k).astype(int)),
                      f"{what}: rank 0 holds the {k} lowest layers, rank 1 the rest")
        checks.expect(k in best_cuts, f"{what}: {k} layers is a best cut (every cut tried: "
                                      f"{best_cuts[0]}..{best_cuts[-1]}, value {best:g}; equal "
                                      f"slabs 28)")
    with open(os.path.join(case, "system", "decomposeParDict.balanced")) as f:
        text = f.read()
    checks.expect("method          manual;" in text and "numberOfSubdomains 2;" in text,
                  "decomposeParDict.balanced: method manual on 2 subdomains")
    dict_args = ("-decomposeParDict", "system/decomposeParDict.balanced")
    runner.run(case, "decomposePar", "decomposePar", *dict_args)
    log = runner.run(case, "grainFoam", runner.solver, *dict_args, ranks=2)
    below = int(layer_particles[:k].sum())
    counts = [(int(a), int(b)) for a, b, _, _ in PER_RANK_LINE.findall(log)]
    checks.expect(len(counts) == 4 and counts == [(0, below), (1, 384 - below)] * 2,
                  f"each rank owns the beads of its slab: rank 0 {below}, rank 1 {384 - below} "
                  f"at both write times (log: {counts})")
    checks.expect(f"processor grid 1 x 1 x 2; cuts along z at {k * 3e-3:g} m" in log,
                  f"the DEM's cut plane is the mesh's, z = {k * 3e-3:g} m")
    lines = balance_lines(log)
    checks.expect(len(lines) >= 2 and max(b[2] for b in lines) < ROUND_OFF,
                  f"momentum exchange balanced to round-off at every write time "
                  f"({max((b[2] for b in lines), default=None)} < {ROUND_OFF:g})")


# --- coupling.diffusion_smoothing -------------------------------------------------------


def diffusion_smoothing(runner, checks):
    """couplingProperties diffusionBandwidth b (coupling/foam/diffusionSmoothing.H): the
    deposited fields diffused to pseudo-time b^2/4 (Sun & Xiao 2015).
    1. One bead at rest in cases/neutral_particle (a closed 10 mm box of 5^3 cells of 2 mm,
       the bead in the middle cell), voidFraction centre (all its volume in that cell),
       b = 1.6 mm: grainFoam takes 2 explicit steps, which reach the cells next to the walls
       but no wall, so the solid fraction is the discrete heat kernel, whose variance is
       exactly twice the pseudo-time per axis: sum phi V (x - x_c)^2 / sum phi V = b^2 / 2
       (Gaussian exp(-r^2/b^2)), its centre the middle cell's, its integral the bead's
       volume. Tolerance 1e-9 relative: phi = 1 - eps is read from 17-digit eps, and the
       outermost cells hold phi ~ 1e-5.
    2. cases/periodic_box in a flow (as exchange_balance), divided, b = 5 mm (12 steps, across
       the cyclic x and y patches, the walls along z and, on 2 ranks, the processor plane):
       exchange balanced to 1e-12 (the particles read the fluid smoothed by the same,
       self-adjoint operator), sum (1 - eps) V = the beads' volume to 1e-12, and eps on 2
       ranks = eps on 1 rank to 1e-12.
    3. Refused: a negative bandwidth, with the allowed range in the message."""
    b, h = 1.6e-3, 2e-3
    case = runner.fresh_case("neutral_particle", "smoothing_kernel", [
        ("constant/couplingProperties", "voidFraction    divided;",
         f"voidFraction    centre;\ndiffusionBandwidth {b};"),
        ("system/controlDict", "endTime         0.1;", "endTime         0.002;"),
        ("system/controlDict", "writeInterval   0.05;", "writeInterval   0.001;")])
    log = runner.solve(case, 1)
    checks.expect("diffusionBandwidth b = 0.0016" in log and "in 2 explicit steps" in log,
                  "b = 1.6 mm in cells of 2 mm: the log says 2 explicit steps")
    snaps = snapshots(case)
    radius = float(snaps[-1][1]["radius"][0]) if snaps else 0.0
    vp = 4.0 / 3.0 * math.pi * radius**3
    centre = np.array([5e-3, 5e-3, 5e-3])  # the middle cell's centre
    ijk = np.stack(np.meshgrid(np.arange(5), np.arange(5), np.arange(5), indexing="ij"),
                   axis=-1)
    # blockMesh numbers cells with x fastest: cell = i + 5 j + 25 k
    x = ((ijk.transpose(2, 1, 0, 3).reshape(-1, 3)) + 0.5) * h
    for folder in time_folders(case):
        phi = 1 - read_scalar_field(os.path.join(case, folder, "voidfraction"))
        mass = float(np.sum(phi)) * h**3
        first = (phi @ x) * h**3 / mass
        second = (phi @ (x - centre) ** 2) * h**3 / mass
        checks.expect(abs(mass - vp) < 1e-9 * vp,
                      f"t = {folder}: sum (1 - eps) V = {mass:.12g} m^3, the bead's {vp:.12g}")
        checks.expect(np.max(np.abs(first - centre)) < 1e-9 * h,
                      f"t = {folder}: centre of the solid {first} m = the middle cell's")
        checks.expect(np.max(np.abs(second / (b * b / 2) - 1)) < 1e-9,
                      f"t = {folder}: variance per axis {second} m^2 = b^2/2 = {b * b / 2:g} m^2")

    edits = [("0/U", "internalField   uniform (0 0 0);", "internalField   uniform (0.05 0.02 0);"),
             ("constant/couplingProperties", "ddtVoidFraction on;",
              "ddtVoidFraction on;\ndiffusionBandwidth 5e-3;")]
    eps = {}
    for ranks in (1, 2):
        case = runner.fresh_case("periodic_box", f"smoothing_np{ranks}", edits)
        log = runner.solve(case, ranks)
        checks.expect("in 12 explicit steps" in log, f"np {ranks}: b = 5 mm in 12 steps")
        lines = balance_lines(log)
        checks.expect(len(lines) == 2 and all(line[2] < ROUND_OFF for line in lines),
                      f"np {ranks}: exchange imbalance {[line[2] for line in lines]} < 1e-12")
        volumes = void_lines(log)
        checks.expect(len(volumes) == 2 and all(v[3] < ROUND_OFF for v in volumes),
                      f"np {ranks}: sum (1 - eps) V vs the beads' volume, relative "
                      f"{[v[3] for v in volumes]} < 1e-12")
        for folder in TIME_FOLDERS:
            eps[(ranks, folder)] = read_scalar_field(os.path.join(case, folder, "voidfraction"))
    for folder in TIME_FOLDERS:
        diff = float(np.max(np.abs(eps[(1, folder)] - eps[(2, folder)])))
        checks.expect(diff < ROUND_OFF, f"t = {folder}: max |eps(np 1) - eps(np 2)| = {diff:.3g}")

    case = runner.fresh_case("periodic_box", "smoothing_negative", [
        ("constant/couplingProperties", "sampling        cell;",
         "diffusionBandwidth -1e-3;\nsampling        cell;")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    expected = "diffusionBandwidth -0.001 is negative"
    checks.expect(expected in log and "0 for none" in log,
                  f"smoothing_negative: refused ('{expected}', naming 0 for none)")

# --- coupling.restart_lost_snapshots -------------------------------------------------------


def restart_lost_snapshots(runner, checks):
    """Snapshots lost before a restart keep their numbers as gaps. cases/periodic_box with
    output.snapshot_interval 0.005 s (snapshot n at t = n * 0.005 s), written every 50 fluid
    steps, is stopped at t = 0.01 s (snapshots 0, 1, 2); 1 and 2 (the one at the checkpoint)
    are deleted, and the run restarts to
    0.02 s. Its next snapshots must be 3 and 4, at 0.015 and 0.02 s, as in the uninterrupted
    run, and the log must name 1 and 2 as gaps. (Before, with no file left after 0, the
    restart numbered its snapshots 1 and 2, so that particles_000001.h5 held t = 0.015 s.)"""
    case = runner.fresh_case("periodic_box", "lost_snapshots", [
        ("system/controlDict", "endTime         2e-4;", "endTime         1e-2;"),
        ("system/controlDict", "writeInterval   1;", "writeInterval   50;"),
        ("particles.yaml", "buoyancy]\n", "buoyancy]\noutput: {snapshot_interval: 0.005}\n")])
    runner.solve(case, 1)
    folder = os.path.join(case, "particles")
    written = sorted(n for n in os.listdir(folder) if n.startswith("particles_"))
    checks.expect(written == [f"particles_00000{n}.h5" for n in range(3)],
                  f"the stopped run wrote snapshots 0, 1, 2 ({written})")
    for n in (1, 2):
        os.remove(os.path.join(folder, f"particles_00000{n}.h5"))
    set_keys(case, "system/controlDict", endTime="2e-2", startFrom="latestTime")
    log = runner.run(case, "grainFoam.restart", runner.solver)
    for n in (1, 2):
        checks.expect(f"particles/particles_00000{n}.h5 (missing) is a gap in "
                      "the snapshot series" in log,
                      f"the log names the deleted snapshot {n} as a gap")
    times = {}
    for name in sorted(os.listdir(folder)):
        if name.startswith("particles_") and name.endswith(".h5"):
            with h5py.File(os.path.join(folder, name), "r") as f:
                times[int(name[10:16])] = float(f.attrs["time"])
    checks.expect(sorted(times) == [0, 3, 4] and
                  all(abs(t - 0.005 * n) < 1e-12 for n, t in times.items()),
                  f"after the restart snapshot n holds t = n * 0.005 s, 1 and 2 gaps ({times})")
    with open(os.path.join(folder, "particles.xdmf")) as f:
        index = f.read()
    listed = [float(t) for t in re.findall(r'<Time Value="([^"]+)"', index)]
    checks.expect(listed == [0.0, 0.015, 0.02] or
                  np.allclose(listed, [0.0, 0.015, 0.02], rtol=0, atol=1e-12),
                  f"particles.xdmf lists the snapshots on disk at 0, 0.015, 0.02 s ({listed})")


# --- coupling.restart_unwritten_time, coupling.run_time_edits, coupling.restart_time_step,
# --- coupling.checkpoint_keeping, coupling.setup_messages --------------------------------

# neutral_particle cut short: endTime 0.002 (2 fluid steps of 50 DEM steps), written each step.
SHORT = [("system/controlDict", "endTime         0.1;", "endTime         0.002;"),
         ("system/controlDict", "writeInterval   0.05;", "writeInterval   0.001;")]


def set_keys(case, path, **keys):
    """Sets `key value;` lines of a case dictionary (each key must be there)."""
    full = os.path.join(case, path)
    with open(full) as f:
        text = f.read()
    for key, value in keys.items():
        text, n = re.subn(r"^" + key + r"\s+[^;]*;", f"{key} {value};", text, flags=re.M)
        if n != 1:
            raise RuntimeError(f"{full}: no line `{key} ...;`")
    with open(full, "w") as f:
        f.write(text)


def fluid_and_dem_time(case, folder):
    """(fluid time, time index, DEM time, DEM step) that grainFoam wrote at a time folder."""
    def value(path, key):
        full = os.path.join(case, folder, "uniform", path)
        if not os.path.exists(full):
            return float("nan")
        with open(full) as f:
            m = re.search(r"^" + key + r"\s+(\S+);", f.read(), re.M)
        return float(m.group(1)) if m else float("nan")
    return (value("time", "value"), value("time", "index"),
            value("grainflowCheckpoint", "demTime"), value("grainflowCheckpoint", "demStep"))


def restart_unwritten_time(runner, checks):
    """A time folder grainFoam did not write has no time index (uniform/time) and names no DEM
    checkpoint (uniform/grainflowCheckpoint): a restart from it would start the DEM afresh at
    t = 0 while the fluid goes on from the folder's time. (a) 0 copied to 0.002 with startFrom
    latestTime: refused, naming the missing files and both ways forward, nothing written.
    (b) 0.002 written by grainFoam with its uniform/ lost: refused by the checksum record
    without the advice "delete its line" (followed, it led to the same mismatch); the lines
    deleted anyway: refused by (a)'s check. The advice given (restart from an intact time,
    0.001) runs, and at 0.003 the DEM's time is the fluid's (3 fluid steps = 150 DEM steps).
    (c) only uniform/grainflowCheckpoint lost: refused with the same advice."""
    case = runner.fresh_case("neutral_particle", "unwritten_copy", SHORT)
    runner.run(case, "blockMesh", "blockMesh")
    shutil.copytree(os.path.join(case, "0"), os.path.join(case, "0.002"))
    set_keys(case, "system/controlDict", startFrom="latestTime", endTime="0.003")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    checks.expect("time folder 0.002 was not written by grainFoam: it has no uniform/time and "
                  "uniform/grainflowCheckpoint" in log and "startTime 0" in log
                  and "Restart from a time grainFoam wrote" in log,
                  "0 copied to 0.002, startFrom latestTime: refused, naming uniform/time and "
                  "uniform/grainflowCheckpoint, advising a written time or time 0")
    checks.expect(not os.path.exists(os.path.join(case, "0.003")),
                  "0 copied to 0.002: nothing written at 0.003")

    stopped = runner.fresh_case("neutral_particle", "unwritten_stopped", SHORT)
    runner.solve(stopped, 1)

    def restart_copy(name):
        case = os.path.join(runner.work, name)
        shutil.rmtree(case, ignore_errors=True)
        shutil.copytree(stopped, case)
        set_keys(case, "system/controlDict", startFrom="latestTime", endTime="0.003")
        return case

    case = restart_copy("unwritten_lost_uniform")
    shutil.rmtree(os.path.join(case, "0.002", "uniform"))
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    checks.expect("uniform/time is missing" in log and "delete its line" not in log
                  and "Restart from another time folder that is intact" in log,
                  "0.002/uniform lost: refused by the checksums, without 'delete its line', "
                  "advising another intact time or time 0")
    record = os.path.join(case, "0.002", "grainflowChecksums")
    with open(record) as f:
        lines = f.read().splitlines(keepends=True)
    with open(record, "w") as f:
        f.writelines(line for line in lines if not line.startswith('"uniform/'))
    log = runner.run(case, "grainFoam.lines_deleted", runner.solver, expect_failure=True)
    checks.expect("time folder 0.002 was not written by grainFoam" in log,
                  "0.002/uniform lost and its lines deleted from the record anyway: refused "
                  "(it had run with the DEM at t = 0.001 against the fluid's 0.003)")
    # The advice given: restart from another intact time folder.
    set_keys(case, "system/controlDict", startFrom="startTime", startTime="0.001")
    runner.run(case, "grainFoam.advised", runner.solver)
    fluid, index, dem, step = fluid_and_dem_time(case, "0.003")
    checks.expect(abs(fluid - 0.003) < 1e-12 and index == 3 and abs(dem - fluid) < 1e-12
                  and step == 150,
                  f"advice rerun (startTime 0.001): at 0.003 fluid t = {fluid:.17g} (index "
                  f"{index:g}), DEM t = {dem:.17g} (step {step:g}); equal, step 150")

    case = restart_copy("unwritten_lost_checkpoint_name")
    os.remove(os.path.join(case, "0.002", "uniform", "grainflowCheckpoint"))
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    checks.expect("uniform/grainflowCheckpoint is missing" in log and "delete its line" not in log,
                  "0.002/uniform/grainflowCheckpoint lost: refused, without 'delete its line'")


# timeActivatedFileUpdate (OpenFOAM's function object) copies a file over another at a given
# time and has the run re-read it: an edit made during the run, at a known step.
FILE_UPDATE = """
functions
{{
{entries}
}}
"""
FILE_UPDATE_ENTRY = """    {name}
    {{
        type            timeActivatedFileUpdate;
        libs            ("libutilityFunctionObjects.so");
        writeControl    timeStep;
        writeInterval   1;
        fileToUpdate    "$FOAM_CASE/{target}";
        timeVsFile      (({at} "$FOAM_CASE/{target}.edited"));
    }}
"""


def edit_during_run(case, updates):
    """updates: [(file, at time, {key: value} of the edited copy)]. Writes <file>.edited, the
    function objects that put it in place at the time, and dates the files an hour back
    (OpenFOAM takes a file as modified only when it is fileModificationSkew, 10 s, newer than
    when it was read; a copy at the start would use up the one re-read)."""
    entries = []
    for n, (target, at, keys) in enumerate(updates):
        entries.append(FILE_UPDATE_ENTRY.format(name=f"edit{n}", target=target, at=at))
    control = os.path.join(case, "system", "controlDict")
    with open(control, "a") as f:
        f.write(FILE_UPDATE.format(entries="".join(entries)))
    for target, at, keys in updates:
        path = os.path.join(case, target)
        shutil.copy(path, path + ".edited")
        set_keys(case, target + ".edited", **keys)
    hour_ago = time.time() - 3600
    for target, _, _ in updates:
        os.utime(os.path.join(case, target), (hour_ago, hour_ago))


def run_time_edits(runner, checks):
    """runTimeModifiable true: system/controlDict, couplingProperties and transportProperties
    edited during a run (cases/neutral_particle, 1 ms steps of 50 DEM steps). (a) deltaT 1e-3
    -> 2e-3 at t = 0.003: the run keeps 1e-3 (10 steps to 0.01) and says so once; at 0.01 the
    DEM's time is the fluid's (it had fallen behind: 50 sub-steps of 2e-5 s in each 2e-3 s
    step). (b) scene time.end 0.006 before endTime 0.01, writeInterval edited at 0.002: the
    run still ends at 0.006, the last line says so and the DEM is there too (it had run on to
    0.01 under a last line claiming 0.006); then endTime edited to 0.004 (< time.end): the run
    ends at 0.004 and the last line does not claim the scene's end. (c) couplingProperties and
    transportProperties edited at 0.002: each said once not to be taken during the run."""
    base = [("system/controlDict", "runTimeModifiable false;", "runTimeModifiable true;"),
                        ("system/controlDict", "endTime         0.1;", "endTime         0.01;"),
                        ("system/controlDict", "writeInterval   0.05;", "writeInterval   0.005;")]
    case = runner.fresh_case("neutral_particle", "edit_delta_t", base)
    edit_during_run(case, [("system/controlDict", 0.003, {"deltaT": "2e-3"})])
    log = runner.solve(case, 1)
    steps = re.findall(r"^Time = (\S+)$", log, re.M)
    warned = log.count("system/controlDict was re-read with deltaT 0.002 s; the run keeps deltaT 0.001 s")
    checks.expect(len(steps) == 10 and warned == 1,
                  f"deltaT edited to 2e-3 at 0.003: {len(steps)} steps of 1e-3 (10), the change "
                  f"refused in {warned} warning (1)")
    last = time_folders(case)[-1]
    fluid, index, dem, step = fluid_and_dem_time(case, last)
    checks.expect(last == "0.01" and abs(dem - fluid) < 1e-12 and step == 500,
                  f"the last time folder {last}: fluid t = {fluid:.17g}, DEM t = {dem:.17g} "
                  f"(step {step:g}): 0.01, equal, step 500")

    case = runner.fresh_case("neutral_particle", "edit_end", base + [
        ("particle.yaml", "  end: 1\n", "  end: 0.006\n")])
    edit_during_run(case, [("system/controlDict", 0.002, {"writeInterval": "0.002"})])
    log = runner.solve(case, 1)
    steps = re.findall(r"^Time = (\S+)$", log, re.M)
    checks.expect(len(steps) == 6 and abs(float(steps[-1]) - 0.006) < 1e-12,
                  f"writeInterval edited during a run with time.end 0.006 < endTime 0.01: "
                  f"{len(steps)} steps, the last at {steps[-1] if steps else None} (6, 0.006)")
    checks.expect(re.search(r"grainFoam: stopped at the scene's time.end, t = 0.006 s "
                            r"\(\S*particle\.yaml:9\), before system/controlDict's endTime "
                            r"0.01 s; to run longer, raise both\nEnd", log) is not None,
                  "the last line says the scene's time.end stopped the run, and it did")
    last = time_folders(case)
    fluid, _, dem, _ = fluid_and_dem_time(case, last[-1]) if last else (0, 0, 0, 0)
    checks.expect(last and abs(fluid - 0.006) < 1e-12 and abs(dem - 0.006) < 1e-12,
                  f"the last time folder {last[-1] if last else None}: fluid t = {fluid:.17g}, "
                  f"DEM t = {dem:.17g} (0.006)")

    case = runner.fresh_case("neutral_particle", "edit_end_earlier", base + [
        ("particle.yaml", "  end: 1\n", "  end: 0.006\n")])
    edit_during_run(case, [("system/controlDict", 0.002, {"endTime": "0.004"})])
    log = runner.solve(case, 1)
    steps = re.findall(r"^Time = (\S+)$", log, re.M)
    checks.expect(len(steps) == 4 and "stopped at the scene's time.end" not in log
                  and "system/controlDict re-read: endTime 0.004 s; the run ends at t = 0.004 s, "
                      "system/controlDict's endTime" in log,
                  f"endTime edited to 0.004 (< time.end 0.006): {len(steps)} steps (4), said, "
                  "and the last line does not claim the scene's end")

    case = runner.fresh_case("neutral_particle", "edit_properties", base)
    edit_during_run(case, [("constant/couplingProperties", 0.002, {"voidFraction": "centre"}),
                           ("constant/transportProperties", 0.002, {"nu": "2e-6"})])
    log = runner.solve(case, 1)
    for name in ("constant/couplingProperties", "constant/transportProperties"):
        said = log.count(f"grainFoam: warning: {name} was edited during the run; grainFoam read "
                         "it at start-up and does not take changes to it during a run")
        checks.expect(said == 1, f"{name} edited at 0.002: said {said} time(s) (once)")


def restart_time_step(runner, checks):
    """deltaT and time.step at start-up and at a restart (cases/neutral_particle). (a) time.step
    3.333333e-6 with deltaT 1e-4 (30.000003 DEM steps): it used to start (a relative 1e-6 was
    allowed) and fall 1e-11 s behind the fluid per step, and its own restart was refused.
    Refused at start-up now, offering the exact step deltaT / 30; that step runs 20 steps and
    restarts (DEM time = fluid time at 0.003). (b) A restart with deltaT 5e-4 after 1e-3:
    refused, naming deltaT 0.001 as the way to restart and a new run from time 0 for the new
    deltaT; deltaT 0.001 put back restarts. (c) voidFraction divided -> centre at a restart:
    the written voidfraction differs from the deposit, and the warning names the changed
    setting (it blamed the written precision, already 17 digits)."""
    case = runner.fresh_case("neutral_particle", "step_near_divisor", [
        ("system/controlDict", "endTime         0.1;", "endTime         0.002;"),
        ("system/controlDict", "deltaT          1e-3;", "deltaT          1e-4;"),
        ("system/controlDict", "writeInterval   0.05;", "writeInterval   0.001;"),
        ("particle.yaml", "  step: 2e-5 ", "  step: 3.333333e-6 ")])
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    m = re.search(r"or set the scene's time.step (\S+) \(deltaT / 30\)", log)
    checks.expect(m is not None and "30.000003 DEM steps" in log,
                  f"time.step 3.333333e-6, deltaT 1e-4: refused, offering the exact step "
                  f"({m.group(1) if m else None})")
    if m:
        with open(os.path.join(case, "particle.yaml")) as f:
            text = f.read()
        with open(os.path.join(case, "particle.yaml"), "w") as f:
            f.write(text.replace("step: 3.333333e-6", "step: " + m.group(1)))
        runner.run(case, "grainFoam.advised", runner.solver)
        set_keys(case, "system/controlDict", startFrom="latestTime", endTime="0.003")
        runner.run(case, "grainFoam.restart", runner.solver)
        fluid, index, dem, step = fluid_and_dem_time(case, "0.003")
        checks.expect(index == 30 and step == 900 and abs(dem - fluid) < 1e-12,
                      f"the offered step runs and restarts: at 0.003 index {index:g}, DEM step "
                      f"{step:g} (30, 900), DEM t - fluid t = {dem - fluid:.3g} (< 1e-12)")

    case = runner.fresh_case("neutral_particle", "restart_delta_t", SHORT)
    runner.solve(case, 1)
    set_keys(case, "system/controlDict", startFrom="latestTime", endTime="0.003", deltaT="5e-4")
    log = runner.run(case, "grainFoam.restart", runner.solver, expect_failure=True)
    checks.expect("This time was run with 50 DEM steps per fluid step, deltaT 0.001 s" in log
                  and "set deltaT 0.001 in system/controlDict" in log
                  and "start a new run from time 0" in log,
                  "restart with deltaT 5e-4 after 1e-3: refused, naming deltaT 0.001 to restart "
                  "and a new run from time 0 for another deltaT")
    set_keys(case, "system/controlDict", deltaT="0.001")
    runner.run(case, "grainFoam.advised", runner.solver)
    fluid, index, dem, step = fluid_and_dem_time(case, "0.003")
    checks.expect(index == 3 and step == 150 and abs(dem - fluid) < 1e-12,
                  f"advice rerun (deltaT 0.001): at 0.003 index {index:g}, DEM step {step:g}")

    case = runner.fresh_case("neutral_particle", "restart_void_fraction", SHORT)
    runner.solve(case, 1)
    set_keys(case, "system/controlDict", startFrom="latestTime", endTime="0.003")
    set_keys(case, "constant/couplingProperties", voidFraction="centre")
    log = runner.run(case, "grainFoam.restart", runner.solver)
    checks.expect("constant/couplingProperties changed since this time was written: "
                  "voidFraction divided then, centre now" in log and "fewer than 17 digits" not in log,
                  "voidFraction divided -> centre at a restart: the warning names the change, "
                  "not the precision")


def checkpoint_keeping(runner, checks):
    """DEM checkpoints against the time folders OpenFOAM keeps (cases/neutral_particle,
    1 ms steps written each). (a) purgeWrite 2, run to 0.004 (folders 0.003, 0.004), restarted
    to 0.006: OpenFOAM keeps 0.003 and 0.004 (its purge list is the run's own) besides 0.005
    and 0.006; every kept folder's checkpoint is kept (150 and 200 had been deleted), only
    those of the purged folders go, and 0.004 restarts. (b) A fresh run (time 0) into that
    case says that particles/ holds an earlier run's snapshots and checkpoints, and names the
    time folders that name them."""
    case = runner.fresh_case("neutral_particle", "purge_restart", [
        ("system/controlDict", "endTime         0.1;", "endTime         0.004;"),
        ("system/controlDict", "writeInterval   0.05;", "writeInterval   0.001;"),
        ("system/controlDict", "purgeWrite      0;", "purgeWrite      2;")])
    runner.solve(case, 1)
    set_keys(case, "system/controlDict", startFrom="latestTime", endTime="0.006")
    runner.run(case, "grainFoam.restart", runner.solver)
    folders = time_folders(case)
    particles = os.path.join(case, "particles")
    kept = sorted(n for n in os.listdir(particles) if n.startswith("checkpoint_"))
    named = []
    for folder in folders:
        with open(os.path.join(case, folder, "uniform", "grainflowCheckpoint")) as f:
            named.append(re.search(r"^checkpoint\s+(\S+);", f.read(), re.M).group(1))
    checks.expect(folders == ["0.003", "0.004", "0.005", "0.006"] and kept == sorted(named),
                  f"purgeWrite 2 and a restart: folders {folders}, checkpoints {kept}, each "
                  f"folder's {named} kept and no other")
    set_keys(case, "system/controlDict", startFrom="startTime", startTime="0.004",
             endTime="0.005")
    log = runner.run(case, "grainFoam.from_0.004", runner.solver)
    checks.expect("restart at time 0.004" in log, "restarted from the kept folder 0.004")

    set_keys(case, "system/controlDict", startTime="0", endTime="0.001", purgeWrite="0")
    log = runner.run(case, "grainFoam.fresh", runner.solver)
    m = re.search(r"note: \S+particles holds (\d+) snapshot\(s\) and (\d+) checkpoint\(s\) of an "
                  r"earlier run; this run starts at time 0 and writes its own over those of the "
                  r"same names.*time folder\(s\) ([^;]*) name checkpoints there", log)
    checks.expect(m is not None and int(m.group(2)) == len(kept) and "0.004" in m.group(3),
                  f"a fresh run into the case: the note names the earlier run's files and the "
                  f"folders naming them ({m.group(0)[:80] if m else None} ...)")


def setup_messages(runner, checks):
    """Start-up messages a user acts on. (a) diffusionBandwidth 60 m on 2 mm cells: its 2.7e9
    explicit steps overflowed an int (the log said 1 step, almost no averaging) and 5 m asked
    for 1.9e7 passes per field and step: refused naming the key, the file, the steps and the
    allowed range, whose upper end then runs. (b) mpirun -np 2 without -parallel: refused,
    saying to add -parallel (it blamed the decomposition, and decomposePar did not help).
    (c) rho 998.2, nu 1.0034e-6 against fluid.viscosity 1.0016e-3: refused printing rho*nu to
    12 digits; the printed value typed into the scene runs (6 digits were refused again)."""
    for b in ("60", "5"):
        case = runner.fresh_case("neutral_particle", f"bandwidth_{b}", SHORT + [
            ("constant/couplingProperties", "sampling        cell;",
             f"diffusionBandwidth {b};\nsampling        cell;")])
        runner.run(case, "blockMesh", "blockMesh")
        log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
        m = re.search(r"diffusionBandwidth " + b + r" m would take \S+ explicit diffusion steps "
                      r"per field and fluid step on this mesh; allowed: 0 \(none\) or 0 < b <= "
                      r"(\S+) m \(at most 1000 steps", log)
        checks.expect(m is not None and "couplingProperties" in log,
                      f"diffusionBandwidth {b} m: refused naming the file, the steps and the "
                      f"range (b <= {m.group(1) if m else None} m)")
    if m:
        case = runner.fresh_case("neutral_particle", "bandwidth_largest", SHORT + [
            ("constant/couplingProperties", "sampling        cell;",
             f"diffusionBandwidth {m.group(1)};\nsampling        cell;")])
        log = runner.solve(case, 1)
        checks.expect("in 1000 explicit steps" in log,
                      f"the largest allowed b = {m.group(1)} m runs in 1000 steps")

    case = runner.fresh_case("periodic_box", "no_parallel", [])
    runner.run(case, "blockMesh", "blockMesh")
    runner.run(case, "decomposePar", "decomposePar")
    r = subprocess.run([runner.foam_env, runner.mpiexec, "-np", "2", "--oversubscribe",
                        runner.solver, "-case", case], cwd=case, env=runner.env, text=True,
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=300)
    checks.expect(r.returncode != 0 and "started on 2 MPI ranks without -parallel" in r.stdout
                  and "Add -parallel" in r.stdout and "shared decomposition" not in r.stdout,
                  f"mpirun -np 2 without -parallel: exit {r.returncode}, says to add -parallel")

    case = runner.fresh_case("neutral_particle", "viscosity_digits", SHORT + [
        ("particle.yaml", "  density: 1000\n", "  density: 998.2\n"),
        ("particle.yaml", "viscosity: 1e-3", "viscosity: 1.0016e-3")])
    set_keys(case, "constant/transportProperties", rho="998.2", nu="1.0034e-6")
    runner.run(case, "blockMesh", "blockMesh")
    log = runner.run(case, "grainFoam", runner.solver, expect_failure=True)
    m = re.search(r"fluid\.viscosity is 0\.0010016 Pa s but the fluid solver's rho\*nu is (\S+) Pa s", log)
    checks.expect(m is not None and m.group(1) == "0.00100159388",
                  f"fluid.viscosity 1.0016e-3 against rho*nu: refused, printing rho*nu as "
                  f"{m.group(1) if m else None} (0.00100159388)")
    if m:
        with open(os.path.join(case, "particle.yaml")) as f:
            text = f.read()
        with open(os.path.join(case, "particle.yaml"), "w") as f:
            f.write(text.replace("viscosity: 1.0016e-3", "viscosity: " + m.group(1)))
        runner.run(case, "grainFoam.advised", runner.solver)
        checks.expect(True, "the printed rho*nu typed as fluid.viscosity runs")


# --- coupling.coupled_inputs -------------------------------------------------------------

def run_refused(runner, checks, case, what, ranks=1, log="grainFoam"):
    """grainFoam on a set-up it must refuse; returns its log. A run that ends with exit 0 is a
    failed check (the later checks of the test still run)."""
    try:
        return runner.run(case, log, runner.solver, ranks=ranks, expect_failure=True)
    except RuntimeError:
        checks.expect(False, f"{what}: refused (it ran, exit 0)")
        with open(os.path.join(case, "log." + log)) as f:
            return f.read()


def coupled_inputs(runner, checks):
    """Inputs grainFoam took without a word, and messages that did not say where or what.

    1. The scene's `parallel` block: the DEM's decomposition is the fluid mesh's. On 2 ranks
       `parallel: {balance: true}` moved the DEM's cut planes off the mesh's (45 % of a bed's
       volume then went undeposited, exit 0) and `grid` was replaced silently: both refused
       at particles.yaml's line naming system/decomposeParDict; the advice (remove it) runs,
       and the void fraction holds the particles' volume (relative difference <= 1e-12 at
       every report, docs/coupling.md). `reproducible: true` and `balance: false` apply and run.
    2. constant/transportProperties: `transportModel BirdCarreau;` with its coefficients ran
       as Newtonian: both refused at their lines (12 and 13); `transportModel Newtonian;` runs, and Cp
       without the scene's heat is named as having no effect.
    3. An end that is not a whole number of fluid steps from the start (deltaT 1e-3 s,
       time.end 0.0056 s): OpenFOAM takes the nearest whole number of steps (6) and ends at
       0.006 s; the start-up and the last line said 0.0056. Now both say 0.006 s, which the
       last Time line and the last snapshot's time confirm, and the note's advice (time.end
       0.006) ends exactly there. The same for controlDict's endTime 0.0054 (ends at 0.005).
    4. couplingProperties values out of range or unknown are refused with the key's line
       (the file: line said "from line 9 to line 13").
    5. The scene's path is expanded as OpenFOAM expands file names: "$FOAM_CASE/..." and
       "<case>/..." run (also on 2 ranks); an unset variable, a '$' left after expansion and
       a directory are each refused saying so."""
    # 1. parallel
    case = runner.fresh_case("periodic_box", "parallel_balance", [
        ("particles.yaml", "fluid:\n", "parallel: {balance: true}\nfluid:\n")])
    runner.run(case, "blockMesh", "blockMesh")
    runner.run(case, "decomposePar", "decomposePar")
    log = run_refused(runner, checks, case, "parallel.balance: true on 2 ranks", ranks=2)
    checks.expect(re.search(r"particles\.yaml:31: error: parallel\.balance: true cannot apply to a "
                            r"coupled run: the DEM follows the fluid's decomposition "
                            r"\(system/decomposeParDict\)", log) is not None,
                  "parallel.balance: true on 2 ranks: refused at particles.yaml:31, naming "
                  "system/decomposeParDict")
    with open(os.path.join(case, "particles.yaml")) as f:
        text = f.read()
    with open(os.path.join(case, "particles.yaml"), "w") as f:
        f.write(text.replace("parallel: {balance: true}\n", ""))
    log = runner.run(case, "grainFoam.advised", runner.solver, ranks=2)
    diffs = [v[-1] for v in void_lines(log)]
    checks.expect(len(diffs) >= 2 and max(diffs) <= 1e-12,
                  f"the advice (remove it) runs on 2 ranks with every particle's volume "
                  f"deposited: relative differences {diffs} (<= 1e-12)")
    case = runner.fresh_case("neutral_particle", "parallel_grid", SHORT + [
        ("particle.yaml", "fluid:\n", "parallel:\n  grid: [2, 1, 1]\nfluid:\n")])
    runner.run(case, "blockMesh", "blockMesh")
    log = run_refused(runner, checks, case, "parallel.grid [2, 1, 1]")
    checks.expect(re.search(r"particle\.yaml:17: error: parallel\.grid is not used by a coupled "
                            r"run: the DEM's processor grid is the fluid's decomposition "
                            r"\(system/decomposeParDict", log) is not None,
                  "parallel.grid (serial): refused at particle.yaml:17, naming "
                  "system/decomposeParDict")
    case = runner.fresh_case("neutral_particle", "parallel_allowed", SHORT + [
        ("particle.yaml", "fluid:\n", "parallel: {reproducible: true, balance: false}\nfluid:\n")])
    runner.solve(case, 1)  # raises unless it runs to its end
    checks.expect(True, "parallel: {reproducible: true, balance: false} runs")

    # 2. transportProperties
    model = ("constant/transportProperties", "nu      1e-6;",
             "nu      1e-6;\ntransportModel BirdCarreau;\n"
             "BirdCarreauCoeffs { nu0 1e-06; nuInf 1e-06; k 0; n 1; }")
    case = runner.fresh_case("neutral_particle", "transport_model", SHORT + [model])
    runner.run(case, "blockMesh", "blockMesh")
    log = run_refused(runner, checks, case, "transportModel BirdCarreau")
    checks.expect(re.search(r"transportModel BirdCarreau at line 12: grainFoam solves a Newtonian "
                            r"fluid \(constant nu\); set transportModel Newtonian or remove it",
                            log) is not None
                  and re.search(r"transportProperties at line 12\.", log) is not None,
                  "transportModel BirdCarreau: refused at line 12")
    # Newtonian, with the inert coefficient block of another model (as OpenFOAM's tutorials
    # keep it) and a helper value a $name refers to: runs, each other key named as not read.
    case = runner.fresh_case("neutral_particle", "transport_newtonian", SHORT + [
        ("constant/transportProperties", "nu      1e-6;",
         "nuWater 1e-6;\nnu      $nuWater;\ntransportModel Newtonian;\nCp      4180;\n"
         "BirdCarreauCoeffs { nu0 1e-06; nuInf 1e-06; k 0; n 1; }")])
    log = runner.solve(case, 1)
    checks.expect("grainFoam: warning: Cp (constant/transportProperties) has no effect: the "
                  "scene has no heat: block" in log
                  and "'BirdCarreauCoeffs' at line 15 is not read by grainFoam" in log
                  and "'nuWater' at line 11 is not read by grainFoam" in log,
                  "transportModel Newtonian with another model's coefficients and a $name "
                  "runs; Cp without heat named as having no effect, the other keys as not read")

    # 3. an end between two fluid steps (deltaT 1e-3 s)
    for label, edits, says, last_line, advice in (
            ("end_scene", [("particle.yaml", "  end: 1\n", "  end: 0.0056\n")],
             r"grainFoam: ends at t = 0\.006 s, the fluid step nearest the scene's time\.end "
             r"0\.0056 s \(\S*particle\.yaml:9\), before system/controlDict's endTime 0\.1 s",
             r"grainFoam: stopped at t = 0\.006 s, the fluid step nearest the scene's time\.end "
             r"0\.0056 s \(\S*particle\.yaml:9\), before system/controlDict's endTime 0\.1 s; to "
             r"run longer, raise both\nEnd",
             r"grainFoam: note: the scene's time\.end 0\.0056 s \(\S*particle\.yaml:9\) is 5\.6 "
             r"fluid steps of deltaT 0\.001 s from the start \(t = 0 s\), not a whole number: the "
             r"run takes 6 steps, the nearest whole number, and ends at t = 0\.006 s, after it\. "
             r"To end exactly at time\.end, set it to a whole number of steps from the start, "
             r"e\.g\. 0\.005 \(5 steps\) or (\S+) \(6 steps\)"),
            ("end_control", [("system/controlDict", "endTime         0.1;",
                              "endTime         0.0054;"),
                             ("system/controlDict", "writeInterval   0.05;",
                              "writeInterval   0.001;")],
             r"grainFoam: ends at t = 0\.005 s, the fluid step nearest system/controlDict's "
             r"endTime 0\.0054 s \(the scene's time\.end",
             r"grainFoam: stopped at t = 0\.005 s, the fluid step nearest system/controlDict's "
             r"endTime 0\.0054 s\nEnd",
             r"the run takes 5 steps, the nearest whole number, and ends at t = 0\.005 s, before "
             r"it\. To end exactly at endTime, set it to a whole number of steps from the start, "
             r"e\.g\. (\S+) \(5 steps\) or 0\.006 \(6 steps\)")):
        case = runner.fresh_case("neutral_particle", label, edits + [
            ("particle.yaml", "fluid:\n", "output: {snapshot_interval: 0.001}\nfluid:\n")])
        log = runner.solve(case, 1)
        steps = re.findall(r"^Time = (\S+)$", log, re.MULTILINE)
        end = 0.006 if label == "end_scene" else 0.005
        snaps = snapshots(case)
        checks.expect(steps and abs(float(steps[-1]) - end) < 1e-12 and snaps
                      and abs(snaps[-1][0] - end) < 1e-12,
                      f"{label}: the last fluid step and snapshot at t = "
                      f"{steps[-1] if steps else None}, {snaps[-1][0] if snaps else None} ({end})")
        checks.expect(re.search(says, log) is not None,
                      f"{label}: the start-up says the run ends at t = {end} s, the step nearest")
        checks.expect(re.search(last_line, log) is not None,
                      f"{label}: the last line says it stopped at t = {end} s")
        m = re.search(advice, log)
        checks.expect(m is not None, f"{label}: a note says the end is not whole, and how to "
                                     f"end exactly there ({m.group(1) if m else None})")
        if label == "end_scene" and m:
            again = runner.fresh_case("neutral_particle", "end_advised", [
                ("particle.yaml", "  end: 1\n", f"  end: {m.group(1)}\n")])
            log = runner.solve(again, 1)
            checks.expect(re.search(r"grainFoam: stopped at the scene's time\.end, t = 0\.006 s",
                                    log) is not None and "grainFoam: note:" not in log
                          and "nearest" not in log,
                          f"the advice, time.end {m.group(1)}, ends exactly there, without a note")
        if label == "end_control":
            # Started again from its last time (0.005, past endTime 0.0054 by less than half
            # a step): nothing to run, said once; it had also said it "ends at t = 0.0054 s".
            set_keys(case, "system/controlDict", startFrom="latestTime")
            log = runner.run(case, "grainFoam.again", runner.solver)
            checks.expect("grainFoam: nothing to run: the run starts at t = 0.005 s, at its end, "
                          "t = 0.0054 s, system/controlDict's endTime" in log
                          and "grainFoam: ends at" not in log,
                          "end_control again from latestTime: 'nothing to run', no 'ends at' line")

    # 4. couplingProperties values: refused at the key's line.
    for label, old, new, words, line in (
            ("min_void_fraction", "minVoidFraction 0.2;", "minVoidFraction 0.1;",
             "minVoidFraction 0.1 is outside [0.2, 1)", 12),
            ("divided_resolution", "ddtVoidFraction on;", "ddtVoidFraction on;\ndividedResolution 16;",
             "dividedResolution 16 is outside [2, 15]", 14),
            ("void_fraction_method", "voidFraction    divided;", "voidFraction    Divided;",
             "voidFraction: ", 10)):
        case = runner.fresh_case("neutral_particle", label, [
            ("constant/couplingProperties", old, new)])
        runner.run(case, "blockMesh", "blockMesh")
        log = run_refused(runner, checks, case, label)
        checks.expect(words in log and re.search(
            rf"file: \S*constant/couplingProperties at line {line}\.", log) is not None,
                      f"{label}: refused, naming couplingProperties at line {line}")
    # The message of an unknown method names the allowed ones; the original, as advised, runs
    # (refuses_bad_setup and the other tests run it).

    # 5. The scene's path.
    for label, path, ranks in (("scene_foam_case", "$FOAM_CASE/particle.yaml", 1),
                               ("scene_case_tag", "<case>/particle.yaml", 1),
                               ("scene_foam_case_ranks", "$FOAM_CASE/particles.yaml", 2)):
        source = "periodic_box" if ranks == 2 else "neutral_particle"
        scene = "particles.yaml" if ranks == 2 else "particle.yaml"
        case = runner.fresh_case(source, label, (SHORT if ranks == 1 else []) + [
            ("constant/couplingProperties", f'"{scene}"', f'"{path}"')])
        try:
            log = runner.solve(case, ranks)
        except RuntimeError as e:  # main's grainFoam: "no such file .../$FOAM_CASE/..."
            log = str(e)
        checks.expect(re.search(r"grainFoam coupling: scene \"?" + re.escape(case) + "/" +
                                re.escape(scene), log) is not None,
                      f"scene \"{path}\" on {ranks} rank(s): expanded to the case's {scene}, runs")
    for label, path, words in (
            ("scene_unset", "$GRAINFLOW_UNSET_VARIABLE/particle.yaml",
             "scene \"$GRAINFLOW_UNSET_VARIABLE/particle.yaml\" (line 9): cannot be expanded: "
             "variable 'GRAINFLOW_UNSET_VARIABLE' is not set in the environment"),
            ("scene_dollar_left", "$(FOAM_CASE)/particle.yaml",
             "; the path still holds a '$' after expansion"),
            ("scene_directory", "constant",
             "is a directory, not a scene file; name the scene's YAML file (it holds no .yaml "
             "file)")):
        case = runner.fresh_case("neutral_particle", label, [
            ("constant/couplingProperties", '"particle.yaml"', f'"{path}"')])
        runner.run(case, "blockMesh", "blockMesh")
        log = run_refused(runner, checks, case, label)
        checks.expect(words in log and re.search(
            r"file: \S*constant/couplingProperties at line 9\.", log) is not None,
                      f"scene \"{path}\": refused at line 9 saying so")


TESTS = {f.__name__: f for f in (void_fraction_volume, exchange_balance, neutrally_buoyant,
                                  cellpoint_ranks,
                                 refuses_bad_setup, hostile_fields, restart, restart_files, restart_bed_surface, stop_signal, nan_guard,
                                 scene_output, heat_equilibrium, heat_parcels, heat_balance,
                                 heat_front, balanced_decomposition,
                                 diffusion_smoothing, restart_unwritten_time, run_time_edits,
                                 restart_time_step, checkpoint_keeping, setup_messages,
                                 restart_lost_snapshots, coupled_inputs)}


if __name__ == "__main__":
    sys.exit(main(TESTS, "coupling", __doc__))
