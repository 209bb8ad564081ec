#!/usr/bin/env bash
# The time split DEM / coupling / fluid of the CFD-DEM tutorials on 2 ranks: each tutorial
# (fluidisedBed, ergunPackedBed, settlingParticle; the full case, not --short) run from its
# start to END_TIME with a write at WRITE_INTERVAL, on a fresh copy; prints grainFoam's
# wall-clock and CPU time splits of the run (docs/performance.md, "The coupling's share").
#   benchmarks/coupling_cost/run.sh CASE END_TIME WRITE_INTERVAL [-np N (2)]
#   e.g. benchmarks/coupling_cost/run.sh fluidisedBed 0.03 0.03
# GRAINFLOW_BUILD_DIR: the build with bin/grainFoam (default: build). Runs go to
# benchmarks/coupling_cost/output/CASE (git-ignored).
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
BUILD="${GRAINFLOW_BUILD_DIR:-$ROOT/build}"
[ $# -ge 3 ] || { sed -n '2,9p' "$0" >&2; exit 2; }
case="$1" end="$2" interval="$3"
shift 3
np=2
[ "${1:-}" = -np ] && np="${2:?-np needs a number}"
BUILD="$(cd "$BUILD" 2> /dev/null && pwd || echo "$BUILD")"  # Allrun runs in the case folder
[ -x "$BUILD/bin/grainFoam" ] || { echo "run.sh: $BUILD/bin/grainFoam not found; build it (scripts/build.sh) or set GRAINFLOW_BUILD_DIR" >&2; exit 1; }
[ -d "$ROOT/tutorials/cfd-dem/$case" ] || { echo "run.sh: no tutorial tutorials/cfd-dem/$case" >&2; exit 2; }
work="$HERE/output/$case"
rm -rf "$work"
mkdir -p "$work/cfd-dem"
cp "$ROOT/tutorials/cfd-dem/run_case.sh" "$work/cfd-dem/"
cp -r "$ROOT/tutorials/cfd-dem/$case" "$work/cfd-dem/"
cd "$work/cfd-dem/$case"
./Allclean > /dev/null 2>&1 || true
# The run alone: no picture, no analysis (they need the whole run).
sed -i '/^pvbatch_sh=/,/^fi$/d; /analyse.py/d' Allrun
# writeInterval counts time steps in fluidisedBed (writeControl timeStep), seconds elsewhere.
if grep -q "^writeControl *timeStep;" system/controlDict; then
  interval=$(/usr/bin/python3 -c "import re,sys; d=open('system/controlDict').read(); \
dt=float(re.search(r'^deltaT\s+(\S+);', d, re.M).group(1)); print(round(float(sys.argv[1])/dt))" "$interval")
fi
sed -i -e "s/^endTime .*/endTime         $end;/" -e "s/^writeInterval .*/writeInterval   $interval;/" system/controlDict
GRAINFLOW_SOURCE_DIR="$ROOT" GRAINFLOW_BUILD_DIR="$BUILD" ./Allrun -np "$np" > log.Allrun 2>&1 ||
  { tail -20 log.Allrun >&2; exit 1; }
echo "$case on $np ranks to t = $end s ($work/cfd-dem/$case/log.grainFoam):"
grep -E "^grainFoam (CPU )?time split:" log.grainFoam | tail -2
