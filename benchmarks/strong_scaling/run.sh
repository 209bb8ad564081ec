#!/usr/bin/env bash
# Strong scaling, 1 -> 2 ranks, side by side: alternates the two rank counts over
# several rounds (machine noise hits both alike) and writes the medians to
# docs/parallel-scaling.md.
#   benchmarks/strong_scaling/run.sh [particles] [steps] [rounds]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BIN="${GRAINFLOW_BUILD_DIR:-$ROOT/build}/bin/bench_strong_scaling"
N="${1:-100000}" STEPS="${2:-300}" ROUNDS="${3:-3}"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
out="$(mktemp)"
for round in $(seq "$ROUNDS"); do
  for np in 1 2; do
    mpirun -np "$np" --bind-to core "$BIN" --particles "$N" --steps "$STEPS" | tee -a "$out"
  done
done
/usr/bin/python3 - "$out" "$ROOT/docs/parallel-scaling.md" <<'PY'
import re, statistics, subprocess, sys, datetime, platform
rows = [dict(kv.split("=") for kv in line.split()) for line in open(sys.argv[1]) if line.startswith("ranks=")]
by = {}
for r in rows:
    by.setdefault(int(r["ranks"]), []).append(float(r["particle_steps_per_second"]))
med = {k: statistics.median(v) for k, v in by.items()}
cpu = subprocess.run(["sh", "-c", "grep -m1 'model name' /proc/cpuinfo | cut -d: -f2"], capture_output=True, text=True).stdout.strip()
r0 = rows[0]
with open(sys.argv[2], "w") as f:
    f.write("# Parallel DEM: strong scaling\n\n")
    f.write(f"Machine: {cpu}, {platform.system()} (the project's 2-core machine), {datetime.date.today()}.\n\n")
    f.write(f"Scene: a dense bed of {r0['particles']} spheres (r = 1 mm, an FCC lattice compressed so that every "
            "sphere touches its 12 neighbours, 74 % solids, on a floor, periodic along x and y), Hertz + tangential history, "
            f"dt = 0.15 t_R; {r0['steps']} timed steps after 200 warm-up steps; median of "
            f"{len(by[1])} alternating rounds (`benchmarks/strong_scaling/run.sh`).\n\n")
    f.write("| ranks | particle-steps/s (median) | all rounds | speed-up |\n|---:|---:|---|---:|\n")
    for k in sorted(med):
        f.write(f"| {k} | {med[k]:.3g} | {', '.join(f'{x:.3g}' for x in by[k])} | {med[k]/med[1]:.2f} |\n")
    f.write("\nThe 2-rank grid is chosen automatically (least cut area); pairs that straddle the "
            "cut are computed on both ranks (see docs/parallel.md), which is the price of exact "
            "force symmetry without a reverse communication. Past two ranks: "
            "[scaling-model.md](scaling-model.md).\n")
print(open(sys.argv[2]).read())
PY
