#!/usr/bin/env python3
"""Coarse-grained parcels in a packed bed against Ergun, pour after pour (issue 23, validation 2).

The case of the test `coupling.parcel_bed_ergun` (tests/coupling/cases/parcel_bed,
tests/coupling/parcel_bed.py): glass beads of real d = 1 mm poured (fill volume fraction 0.12
of a 120 mm tall column, periodic sideways) onto a distributor, air at 0.2 m/s superficial
(0.37 U_mf) from the start, drag gidaspow, void fraction divided, sampling cell,
dragVoidFraction sharpInterface, 4 mm cells, DEM step k x 1e-5 s, 20 DEM steps per fluid step,
0.2 s. Here the column's width may change (--width-cells N: N x N cells of 4 mm; the test's
N = 6, 24 mm: about 15 850 real beads), and each (k, fill seed) is one pour.

Per pour, as the test measures it: the inlet pressure drop averaged over the last 0.03 s against
Ergun (1952) with the real d and the bed's own core eps and mass-equivalent height from the last
snapshot (parcel_bed.bed_geometry), and grainFoam's CPU seconds (ExecutionTime).
Per k: every pour's error, their mean, standard deviation and range.

usage: packed_bed.py [--ks 1,2,3] [--seeds 1-7] [--width-cells 6] [--jobs 2]
                     [--work DIR] [--build DIR] [--analyse-only]
Cases <work>/w<N>_k<k>_seed<s>; rows appended to <work>/packed_bed.csv.
--jobs J runs J pours at once (each on 1 rank; CPU seconds are each run's own).
"""
import argparse
import concurrent.futures
import csv
import math
import os
import re
import statistics
import sys
import types

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tests", "coupling"))
sys.path.insert(0, os.path.join(ROOT, "tests", "support"))
import parcel_bed  # noqa: E402
from grainfoam_driver import Runner, snapshots  # noqa: E402

CELL = 4e-3  # the test's cells [m]


def parse_list(text):
    out = []
    for part in text.split(","):
        if "-" in part:
            a, b = part.split("-")
            out += list(range(int(a), int(b) + 1))
        else:
            out.append(part)
    return out


def make_case(runner, n, k, seed, end):
    width = n * CELL
    dt = k * parcel_bed.DT
    mm = f"{width * 1e3:g}"
    edits = [("particles.yaml", "max: [0.024, 0.024, 0.12]", f"max: [{width:g}, {width:g}, 0.12]"),
             ("particles.yaml", "max: [0.024, 0.024, 0.12]", f"max: [{width:g}, {width:g}, 0.12]"),
             ("particles.yaml", "coarse_grain: 1", f"coarse_grain: {k}"),
             ("particles.yaml", "seed: 7", f"seed: {seed}"),
             ("particles.yaml", "step: 1e-5", f"step: {dt:g}"),
             ("system/controlDict", "endTime         0.2;", f"endTime         {end:g};"),
             ("system/controlDict", "deltaT          2e-4;", f"deltaT          {20 * dt:g};"),
             ("system/controlDict", "writeInterval   0.05;", f"writeInterval   {end / 5:g};"),
             ("system/blockMeshDict", "(0 0 0) (24 0 0) (24 24 0) (0 24 0)",
              f"(0 0 0) ({mm} 0 0) ({mm} {mm} 0) (0 {mm} 0)"),
             ("system/blockMeshDict", "(0 0 120) (24 0 120) (24 24 120) (0 24 120)",
              f"(0 0 120) ({mm} 0 120) ({mm} {mm} 120) (0 {mm} 120)"),
             ("system/blockMeshDict", "(6 6 30)", f"({n} {n} 30)")]
    return runner.fresh_case("parcel_bed", f"w{n}_k{k}_seed{seed}", edits)


def analyse(case, n, end):
    width = n * CELL
    t, last = snapshots(case)[-1]
    eps, height, _ = parcel_bed.bed_geometry(last, width * width)
    dp = parcel_bed.inlet_dp(case, end - parcel_bed.AVERAGE)
    ref = parcel_bed.ergun(eps, height)
    with open(os.path.join(case, "log.grainFoam")) as f:
        cpu = float(re.findall(r"ExecutionTime = (\S+) s", f.read())[-1])
    real = int(last["real_count"].sum()) if "real_count" in last else len(last["id"])
    speed = float(np.linalg.norm(last["velocity"], axis=1).mean())
    return dict(parcels=len(last["id"]), real=real, eps=eps, height=height, dp=dp, ergun=ref,
                error=dp / ref - 1, cpu=cpu, mean_speed=speed, time=t)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--ks", default="1,2,3")
    parser.add_argument("--seeds", default="1-7")
    parser.add_argument("--width-cells", type=int, default=6)
    parser.add_argument("--end", type=float, default=parcel_bed.END)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--work", default="/tmp/packed_bed_bench")
    parser.add_argument("--build", default=os.environ.get("GRAINFLOW_BUILD_DIR", os.path.join(ROOT, "build")))
    parser.add_argument("--analyse-only", action="store_true")
    args = parser.parse_args()
    ks = [int(k) for k in parse_list(args.ks)]
    seeds = [int(s) for s in parse_list(args.seeds)]
    n = args.width_cells
    os.makedirs(args.work, exist_ok=True)
    runner = Runner(types.SimpleNamespace(
        foam_env=os.path.join(ROOT, "scripts", "foam_env.sh"),
        solver=os.path.join(args.build, "bin", "grainFoam"), mpiexec="mpiexec",
        lib_dir=os.path.join(args.build, "lib"),
        cases=os.path.join(ROOT, "tests", "coupling", "cases"), work=args.work))
    runner.env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    runner.env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    pours = [(k, s) for s in seeds for k in ks]

    def pour(ks_):
        k, seed = ks_
        if not args.analyse_only:
            case = make_case(runner, n, k, seed, args.end)
            runner.solve(case, 1)
        return ks_, analyse(os.path.join(args.work, f"w{n}_k{k}_seed{seed}"), n, args.end)

    results = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        for (k, seed), row in pool.map(pour, pours):
            results[(k, seed)] = row
            print(f"  w{n} k={k} seed {seed}: {row['parcels']} parcels ({row['real']} beads), "
                  f"eps {row['eps']:.4f}, H {row['height'] * 1e3:.2f} mm, dp {row['dp']:.2f} Pa, "
                  f"Ergun {row['ergun']:.2f} Pa, error {100 * row['error']:+.2f} %, "
                  f"CPU {row['cpu']:.1f} s, mean speed {row['mean_speed']:.2g} m/s", flush=True)
    width_mm = n * CELL * 1e3
    print(f"\ncolumn {width_mm:g} x {width_mm:g} mm ({n} x {n} cells of 4 mm), seeds {args.seeds}")
    print("  k  parcels  errors per pour [%]                      mean %   sd %  range   CPU s")
    csv_path = os.path.join(args.work, "packed_bed.csv")
    new = not os.path.exists(csv_path)
    with open(csv_path, "a", newline="") as f:
        out = csv.writer(f)
        if new:
            out.writerow(["width_cells", "k", "seed", "parcels", "real", "eps", "height_m",
                          "dp_Pa", "ergun_Pa", "error", "cpu_s"])
        for k in ks:
            rows = [results[(k, s)] for s in seeds]
            errs = [100 * r["error"] for r in rows]
            for s, r in zip(seeds, rows):
                out.writerow([n, k, s, r["parcels"], r["real"], f"{r['eps']:.5f}",
                              f"{r['height']:.6g}", f"{r['dp']:.4f}", f"{r['ergun']:.4f}",
                              f"{r['error']:.5f}", f"{r['cpu']:.2f}"])
            sd = statistics.stdev(errs) if len(errs) > 1 else math.nan
            print(f"  {k}  {statistics.mean(r['parcels'] for r in rows):7.0f}  "
                  f"{', '.join(f'{e:+.1f}' for e in errs):40s} {statistics.mean(errs):+6.2f} "
                  f"{sd:6.2f} {max(errs) - min(errs):5.1f} "
                  f"{statistics.mean(r['cpu'] for r in rows):7.1f}")
    print(f"rows appended to {csv_path}")


if __name__ == "__main__":
    main()
