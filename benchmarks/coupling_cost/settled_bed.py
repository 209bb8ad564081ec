#!/usr/bin/env python3
"""The settled-bed imbalance of the shared decomposition and its remedy (docs/parallel.md,
"Coupled runs: a bed settled at the bottom of a tall column").

The fluidisedBed tutorial (a 60 x 9 x 240 mm column of 20 x 3 x 80 cells) with the beads of
its `--short` form (--beads N poured at 25 % solids from z = 2 mm to 2 + 80 N / 12 000 mm:
2000 beads from 2-15 mm, near the floor by 0.05 s; 12 000 the full tutorial's, from 2-82 mm) is run on 2 ranks from its start to END with a write
at END/2, twice, each on a fresh copy (the inflow starts at 0.2 s: until then the bed rests):

  equal     decomposition `simple (1 1 2)`: two slabs of 40 cell layers, cut at z = 120 mm,
            the bed (6 mm high once settled, 35 mm with 12 000 beads) all on rank 0;
  balanced  scripts/balanced_decomposition.py --axis z with the equal run's snapshot at the
            first write time as the particles and its log as the particle cost
            (--weight-from; or --particle-cost W), then decomposePar and grainFoam on that
            `manual` decomposition.

For each it prints the per-rank lines of the second interval (particles, DEM working and
waiting, coupling, fluid), the whole-run time split (max over ranks), grainFoam's wall time
(ExecutionTime), and what the two must agree on: the particles' mean height and the bed
pressure drop (inlet minus outlet pressure at the end, and its mean over the second
interval) within the statistics of a poured bed, and the momentum exchange balanced to
round-off at every write time.

    scripts/python.sh benchmarks/coupling_cost/settled_bed.py [--end 0.06] [--beads 2000]
                      [--only equal|balanced] [--particle-cost W]

GRAINFLOW_BUILD_DIR: the build with bin/grainFoam (default: build). Runs go to
benchmarks/coupling_cost/output/settled_bed/{equal,balanced} (git-ignored). Run it with
`nice -n 5` on a shared machine.
"""
import argparse
import glob
import os
import pathlib
import re
import shutil
import subprocess
import sys

import h5py
import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
TUTORIAL = ROOT / "tutorials" / "cfd-dem" / "fluidisedBed"
DT = 3e-4  # the tutorial's fluid step (system/controlDict deltaT)

Z_SPLIT = """FoamFile { version 2.0; format ascii; class dictionary; object decomposeParDict; }
// settled_bed.py: two slabs of equal cell counts along z (the bed all on the lower one).
numberOfSubdomains 2;
method          simple;
coeffs          { n (1 1 2); }
"""


def sh(cmd, cwd, log):
    with open(cwd / log, "w") as f:
        r = subprocess.run(cmd, cwd=cwd, stdout=f, stderr=subprocess.STDOUT, env=ENV)
    if r.returncode != 0:
        sys.exit(f"settled_bed.py: {' '.join(map(str, cmd))} failed, see {cwd / log}:\n"
                 + (cwd / log).read_text()[-3000:])
    if log == "log.grainFoam" and not re.search(r"^End\s*$", (cwd / log).read_text(), re.M):
        sys.exit(f"settled_bed.py: grainFoam did not reach its end time (a SIGTERM or SIGINT stops it with exit 0 after a checkpoint); "
                 f"see {cwd / log}")


def fresh(name, end, beads):
    case = HERE / "output" / "settled_bed" / name
    shutil.rmtree(case, ignore_errors=True)
    shutil.copytree(TUTORIAL, case)
    if beads != 12000:  # as Allrun --short: the same scene, fewer beads poured from lower
        scene = case / "particles.yaml"
        text = scene.read_text()
        text = text.replace("    count: 12000\n", f"    count: {beads}\n", 1)
        text = text.replace("max: [0.06, 0.009, 0.082]", f"max: [0.06, 0.009, {0.002 + 0.08 * beads / 12000:.4g}]", 1)
        scene.write_text(text)
    control = case / "system" / "controlDict"
    text = control.read_text()
    text = re.sub(r"^endTime .*$", f"endTime         {end:g};", text, flags=re.M)
    text = re.sub(r"^writeInterval .*$", f"writeInterval   {round(end / 2 / DT)};", text, flags=re.M)
    control.write_text(text)
    sh([FOAM, "blockMesh"], case, "log.blockMesh")
    return case


def solve(case, dict_file):
    sh([FOAM, "decomposePar", "-force", "-decomposeParDict", dict_file], case, "log.decomposePar")
    sh([FOAM, "mpirun", "--oversubscribe", "-np", "2", str(BUILD / "bin" / "grainFoam"), "-parallel",
        "-decomposeParDict", dict_file], case, "log.grainFoam")
    return (case / "log.grainFoam").read_text()


def snapshots(case):
    return sorted(glob.glob(str(case / "particles" / "particles_*.h5")),
                  key=lambda p: float(re.search(r"particles_([0-9.e+-]+)\.h5$", p).group(1)))


def report(name, case, log):
    rank_lines = re.findall(r"^grainFoam rank \d+ since the last write: .*$", log, re.M)
    split = re.findall(r"^grainFoam time split: (.*)$", log, re.M)
    clock = re.findall(r"^ExecutionTime = ([0-9.e+-]+) s", log, re.M)
    cuts = re.findall(r"^  processor grid .*$", log, re.M)
    imbalance = [float(v) for v in re.findall(r"relative imbalance ([-+0-9.eEnaif]+)", log)]
    snaps = snapshots(case)
    with h5py.File(snaps[-1], "r") as f:
        z = f["position"][:, 2]
    p_in = np.loadtxt(glob.glob(str(case / "postProcessing" / "pInlet" / "*" / "surfaceFieldValue.dat"))[0])
    p_out = np.loadtxt(glob.glob(str(case / "postProcessing" / "pOutlet" / "*" / "surfaceFieldValue.dat"))[0])
    dp = p_in[:, 1] - p_out[:, 1]
    t_half = p_in[-1, 0] / 2
    second = p_in[:, 0] > t_half + 1e-9
    print(f"== {name}: {case}")
    for line in cuts[:1]:
        print("  DEM:" + line)
    for line in rank_lines[-2:]:
        print("  " + line)
    # The run as a whole, per rank: the lines' seconds summed over the write times.
    sums = {}
    for r, n, work, wait, coupling, fluid in re.findall(
            r"^grainFoam rank (\d+) since the last write: (\d+) particles; DEM ([0-9.e+-]+) s working "
            r"\+ ([0-9.e+-]+) s waiting for other ranks, coupling ([0-9.e+-]+) s, fluid ([0-9.e+-]+) s",
            log, re.M):
        acc = sums.setdefault(int(r), [0, 0.0, 0.0, 0.0, 0.0])
        acc[0] = int(n)
        for k, v in enumerate((work, wait, coupling, fluid)):
            acc[k + 1] += float(v)
    for r, (n, work, wait, coupling, fluid) in sorted(sums.items()):
        print(f"  whole run, rank {r}: {n} particles at the end; DEM {work:.3g} s working + {wait:.3g} s "
              f"waiting, coupling {coupling:.3g} s, fluid {fluid:.3g} s")
    print(f"  whole run (max over ranks): {split[-1] if split else '?'}")
    print(f"  grainFoam wall time (ExecutionTime): {clock[-1] if clock else '?'} s")
    print(f"  particles {len(z)}, mean height {1e3 * z.mean():.4f} mm ({os.path.basename(snaps[-1])}); "
          f"pressure drop at the end {dp[-1]:.5g}, mean over the second interval {dp[second].mean():.5g} "
          f"(kinematic, m^2/s^2); exchange: worst relative imbalance {max(imbalance):.3g} "
          f"over {len(imbalance)} write times")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--end", type=float, default=0.06, help="end time [s] (default %(default)s)")
    ap.add_argument("--beads", type=int, default=2000, help="beads poured (default %(default)s)")
    ap.add_argument("--only", choices=["equal", "balanced"], help="run one of the two only")
    ap.add_argument("--particle-cost", type=float,
                    help="w for the balanced run instead of the equal run's log")
    args = ap.parse_args()
    if args.only != "balanced":
        case = fresh("equal", args.end, args.beads)
        (case / "system" / "decomposeParDict").write_text(Z_SPLIT)
        report("equal slabs along z", case, solve(case, "system/decomposeParDict"))
    equal = HERE / "output" / "settled_bed" / "equal"
    if args.only == "equal":
        return
    snaps = snapshots(equal)
    if not snaps:
        sys.exit(f"settled_bed.py: no snapshot in {equal}/particles (run without --only first)")
    case = fresh("balanced", args.end, args.beads)
    weight = (["--particle-cost", str(args.particle_cost)] if args.particle_cost
              else ["--weight-from", str(equal / "log.grainFoam")])
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "balanced_decomposition.py"), str(case),
                        "--ranks", "2", "--axis", "z", "--particles", snaps[0], *weight],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=ENV)
    print(r.stdout)
    if r.returncode != 0:
        sys.exit(1)
    report("balanced (scripts/balanced_decomposition.py)", case,
           solve(case, "system/decomposeParDict.balanced"))


BUILD = pathlib.Path(os.environ.get("GRAINFLOW_BUILD_DIR", ROOT / "build")).resolve()
FOAM = str(ROOT / "scripts" / "foam_env.sh")
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           LD_LIBRARY_PATH=os.pathsep.join(p for p in (str(BUILD / "lib"), os.environ.get("LD_LIBRARY_PATH", "")) if p))

if __name__ == "__main__":
    main()
