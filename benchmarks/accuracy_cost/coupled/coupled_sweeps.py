#!/usr/bin/env python3
"""Coupled accuracy-versus-cost sweeps (grainFoam), one knob at a time.

Sweep 1 - void-fraction model x sampling x cell size over particle diameter:
  a bed of 3300 beads (d = 1 mm) is poured once (tutorials/cfd-dem/ergunPackedBed), then for
  every variant re-inserted from that snapshot at rest and air is forced through at 0.2 m/s
  (0.37 U_mf) for 0.06 s. Error: the pressure drop averaged over the last 0.03 s against Ergun
  with the bed's own mean void fraction and height. Cost: grainFoam's coupling seconds and
  total CPU seconds per simulated second.
Sweep 2 - coupling interval (DEM steps per fluid step), two cases:
  the settling sphere of tutorials/cfd-dem/settlingParticle (error: mean settling speed after
  0.05 s against the Schiller-Naumann terminal velocity), and the fixed bed above at 0.2 m/s
  with the divided footprint (error against Ergun).

Writes <work>/coupled_results.csv. Usage: coupled_sweeps.py [--short] [--work DIR] [--build DIR]
--short: sweep 1 on 2 cell sizes with divided/cell only and sweep 2 on 3 intervals, then
         check that every error falls (in magnitude) as its knob is refined: smaller cells,
         fewer DEM steps per fluid step. Exit 1 if not. Timings are not checked.
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

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
FOAM = os.path.join(ROOT, "scripts", "foam_env.sh")

RHO_P, RHO_F, MU, G = 2500.0, 1.2, 1.8e-5, 9.81
AREA = 0.012 * 0.012


def sub(path, pattern, replacement, count=1):
    with open(path) as f:
        text = f.read()
    new, n = re.subn(pattern, replacement, text, count=count, flags=re.M | re.S)
    if n == 0:
        sys.exit(f"coupled_sweeps: pattern {pattern!r} not found in {path}")
    with open(path, "w") as f:
        f.write(new)


def finished(text, case, what):
    """A grainFoam stopped by SIGTERM or SIGINT writes a checkpoint and exits 0 (a batch
    system's time limit): its log then lacks OpenFOAM's closing "End", and its numbers are
    not the full run's."""
    if not re.search(r"^End\s*$", text, re.M):
        sys.exit(f"coupled_sweeps: {what}: grainFoam did not reach its end time (stopped by a "
                 f"signal, or failed), see {case}/log.grainFoam")


def run(case, build, what):
    env = dict(os.environ, LD_LIBRARY_PATH=os.path.join(build, "lib"))
    for cmd, log in ((["blockMesh"], "log.blockMesh"),
                     ([os.path.join(build, "bin", "grainFoam")], "log.grainFoam")):
        with open(os.path.join(case, log), "w") as out:
            rc = subprocess.call([FOAM] + cmd, cwd=case, stdout=out, stderr=subprocess.STDOUT, env=env)
        if rc != 0:
            sys.exit(f"coupled_sweeps: {what}: {cmd[0]} failed, see {case}/{log}")
    text = open(os.path.join(case, "log.grainFoam")).read()
    finished(text, case, what)
    split = re.findall(r"grainFoam time split: DEM (\S+) s .*?coupling (\S+) s .*?fluid (\S+) s", text)
    cpu = re.findall(r"ExecutionTime = (\S+) s", text)
    dem, coupling, fluid = (float(x) for x in split[-1])
    return {"dem_s": dem, "coupling_s": coupling, "fluid_s": fluid, "cpu_s": float(cpu[-1])}


def bed_properties(snapshot):
    with h5py.File(snapshot, "r") as f:
        z = f["position"][:, 2]
        r = f["radius"][:]
    d = 2 * r.mean()
    vp = 4 / 3 * math.pi * r**3
    dz = 0.25e-3
    edges = np.arange(0, z.max() + r.max() + dz, dz)
    a = np.clip(edges[:-1, None] - z[None, :], -r, r)
    b = np.clip(edges[1:, None] - z[None, :], -r, r)
    phi = (math.pi * (r**2 * (b - a) - (b**3 - a**3) / 3)).sum(axis=1) / (AREA * dz)
    mid = 0.5 * (edges[:-1] + edges[1:])
    bulk = np.median(phi[(mid > 3 * d) & (mid < z.max() - 3 * d)])
    top = mid[np.nonzero(phi > 0.5 * bulk)[0][-1]]
    core = (mid > 3 * d) & (mid < top - 3 * d)
    eps = 1 - phi[core].mean()
    return d, eps, vp.sum() / (AREA * (1 - eps))


def ergun(u, d, eps, height):
    return height * (150 * MU * u * (1 - eps) ** 2 / (eps**3 * d**2) +
                     1.75 * RHO_F * u**2 * (1 - eps) / (eps**3 * d))


def pour(work, build, seed=7):
    """The poured bed of ergunPackedBed (its fill's seed 7, or another seed: another pour of
    the same bed, in pour_seed<seed>)."""
    case = os.path.join(work, "pour" if seed == 7 else f"pour_seed{seed}")
    snap = glob.glob(os.path.join(case, "particles", "particles_*.h5"))
    if snap:
        return sorted(snap)[-1]
    shutil.rmtree(case, ignore_errors=True)
    shutil.copytree(os.path.join(ROOT, "tutorials", "cfd-dem", "ergunPackedBed"), case,
                    ignore=shutil.ignore_patterns("particles", "processor*", "postProcessing", "log.*", "*.png"))
    sub(f"{case}/system/controlDict", r"^endTime .*?;", "endTime 0.15;")
    if seed != 7:
        sub(f"{case}/particles.yaml", r"seed: 7\n", f"seed: {seed}\n")
    with open(f"{case}/system/shortRun.U", "w") as f:
        f.write("superficialVelocity constant (0 0 0);\n")
    print("coupled_sweeps: pouring the bed (0.15 s) ...", flush=True)
    run(case, build, "pour")
    return sorted(glob.glob(os.path.join(case, "particles", "particles_*.h5")))[-1]


def bed_case(work, name, snapshot, cells, method, sampling, steps_per_fluid, u=0.2, end=0.06):
    case = os.path.join(work, name)
    shutil.rmtree(case, ignore_errors=True)
    shutil.copytree(os.path.join(ROOT, "tutorials", "cfd-dem", "ergunPackedBed"), case,
                    ignore=shutil.ignore_patterns("particles", "processor*", "postProcessing", "log.*", "*.png"))
    shutil.copy(snapshot, os.path.join(case, "bed.h5"))
    sub(f"{case}/particles.yaml", r"  - type: fill\n.*?seed: 7\n",
        "  - {type: snapshot, file: bed.h5, keep_velocity: false}\n")
    sub(f"{case}/system/blockMeshDict", r"\(6 6 30\)", f"({cells} {cells} {int(round(cells * 5))})")
    sub(f"{case}/system/controlDict", r"^endTime .*?;", f"endTime {end};")
    sub(f"{case}/system/controlDict", r"^deltaT .*?;", f"deltaT {steps_per_fluid * 1e-5:.10g};")
    sub(f"{case}/constant/couplingProperties", r"^voidFraction .*?;", f"voidFraction    {method};")
    sub(f"{case}/constant/couplingProperties", r"^sampling .*?;", f"sampling        {sampling};")
    with open(f"{case}/system/shortRun.U", "w") as f:
        f.write(f"superficialVelocity constant (0 0 {u});\n")
    return case


def bed_dp(case, t_from):
    rows = np.loadtxt(glob.glob(os.path.join(case, "postProcessing", "inletPressure", "*",
                                             "surfaceFieldValue.dat"))[0])
    return RHO_F * rows[rows[:, 0] > t_from, 1].mean()


def settling_case(work, steps_per_fluid, end=0.1):
    case = os.path.join(work, f"settling_n{steps_per_fluid}")
    shutil.rmtree(case, ignore_errors=True)
    shutil.copytree(os.path.join(ROOT, "tutorials", "cfd-dem", "settlingParticle"), case,
                    ignore=shutil.ignore_patterns("particles", "processor*", "log.*", "*.png"))
    sub(f"{case}/particles.yaml", r"  step: 1e-4 .*?\n", "  step: 1e-5\n")
    sub(f"{case}/system/controlDict", r"^endTime .*?;", f"endTime {end};")
    sub(f"{case}/system/controlDict", r"^deltaT .*?;", f"deltaT {steps_per_fluid * 1e-5:.10g};")
    sub(f"{case}/system/controlDict", r"^writeInterval .*?;", "writeInterval 0.005;")
    return case


def terminal_velocity(d=2e-4, rho_p=2500.0, rho_f=1000.0, mu=1e-3):
    def excess(u):
        re_ = rho_f * u * d / mu
        return 0.75 * 24 / re_ * (1 + 0.15 * re_**0.687) * rho_f * u * u / d - (rho_p - rho_f) * G
    lo, hi = 1e-9, 10.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if excess(mid) > 0 else (mid, hi)
    return 0.5 * (lo + hi)


def settling_speed(case, t_from=0.05):
    w = []
    for f in sorted(glob.glob(os.path.join(case, "particles", "particles_*.h5"))):
        with h5py.File(f, "r") as h:
            if h.attrs["time"] > t_from:
                w.append(-h["velocity"][0][2])
    return float(np.mean(w))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--short", action="store_true")
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "accuracy_cost", "coupled"))
    ap.add_argument("--build", default=os.environ.get("GRAINFLOW_BUILD_DIR", os.path.join(ROOT, "build")))
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    rows = []
    started = time.time()

    snapshot = pour(args.work, args.build)
    d, eps, height = bed_properties(snapshot)
    u = 0.2
    reference = ergun(u, d, eps, height)
    print(f"coupled_sweeps: bed eps = {eps:.4f}, height = {height * 1e3:.2f} mm, "
          f"Ergun dp at {u} m/s = {reference:.2f} Pa", flush=True)

    cells_list = [6, 3] if args.short else [6, 4, 3]  # across 12 mm: 2, 3, 4 mm cells
    methods = ["divided"] if args.short else ["centre", "divided", "smoothed"]
    samplings = ["cell"] if args.short else ["cell", "cellPoint"]
    for cells in cells_list:
        for method in methods:
            for sampling in samplings:
                name = f"bed_{method}_{sampling}_c{cells}"
                case = bed_case(args.work, name, snapshot, cells, method, sampling, 20)
                cost = run(case, args.build, name)
                dp = bed_dp(case, 0.03)
                row = dict(sweep="void_fraction", case=name, method=method, sampling=sampling,
                           cell_over_d=round(12 / cells, 3), steps_per_fluid=20,
                           measured=dp, reference=reference, error=dp / reference - 1,
                           sim_seconds=0.06, **cost)
                rows.append(row)
                print(f"  {name}: dp = {dp:.2f} Pa, error {100 * row['error']:+.2f} %, "
                      f"coupling {cost['coupling_s']:.2f} s, cpu {cost['cpu_s']:.1f} s", flush=True)

    u_t = terminal_velocity()
    intervals = [5, 20, 100] if args.short else [1, 5, 10, 20, 50, 100]
    for n in intervals:
        case = settling_case(args.work, n)
        cost = run(case, args.build, f"settling n={n}")
        w = settling_speed(case)
        rows.append(dict(sweep="interval_settling", case=f"settling_n{n}", method="divided",
                         sampling="cell", cell_over_d=10, steps_per_fluid=n, measured=w,
                         reference=u_t, error=w / u_t - 1, sim_seconds=0.1, **cost))
        print(f"  settling, {n} DEM steps per fluid step: {w * 1e3:.3f} mm/s, error "
              f"{100 * (w / u_t - 1):+.2f} %, cpu {cost['cpu_s']:.1f} s", flush=True)
    bed_intervals = [5, 20, 50] if args.short else [2, 5, 10, 20, 50, 100]
    for n in bed_intervals:
        name = f"bed_interval_n{n}"
        # 20 DEM steps per fluid step on 6 cells with divided/cell is sweep 1's run: reused.
        same = [r for r in rows if r["case"] == "bed_divided_cell_c6"] if n == 20 else []
        if same:
            dp = same[0]["measured"]
            cost = {k: same[0][k] for k in ("dem_s", "coupling_s", "fluid_s", "cpu_s")}
        else:
            case = bed_case(args.work, name, snapshot, 6, "divided", "cell", n)
            cost = run(case, args.build, name)
            dp = bed_dp(case, 0.03)
        rows.append(dict(sweep="interval_bed", case=name, method="divided", sampling="cell",
                         cell_over_d=2, steps_per_fluid=n, measured=dp, reference=reference,
                         error=dp / reference - 1, sim_seconds=0.06, **cost))
        print(f"  bed, {n} DEM steps per fluid step: dp = {dp:.2f} Pa, error "
              f"{100 * (dp / reference - 1):+.2f} %, cpu {cost['cpu_s']:.1f} s", flush=True)

    out = os.path.join(args.work, "coupled_results.csv")
    with open(out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print(f"coupled_sweeps: {len(rows)} runs in {time.time() - started:.0f} s -> {out}")
    if args.short:
        sys.exit(0 if monotone(rows) else 1)


def monotone(rows):
    """|error| must not grow as the knob is refined (ties within 0.05 % allowed)."""
    ok = True
    checks = [("void_fraction", "cell_over_d"), ("interval_settling", "steps_per_fluid"),
              ("interval_bed", "steps_per_fluid")]
    for sweep, knob in checks:
        pts = sorted((r[knob], abs(r["error"])) for r in rows if r["sweep"] == sweep)
        errors = [e for _, e in pts]
        good = all(a <= b + 5e-4 for a, b in zip(errors, errors[1:]))
        ok &= good
        print(f"coupled_sweeps: {sweep}: |error| by {knob} " +
              ", ".join(f"{k:g}: {100 * e:.2f} %" for k, e in pts) +
              (" - falls as the knob is refined: ok" if good else " - NOT monotone: FAILED"))
    return ok


if __name__ == "__main__":
    main()
