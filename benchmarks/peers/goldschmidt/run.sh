#!/usr/bin/env bash
# grainFoam against OpenFOAM v1912's DPMFoam on DPMFoam's own example `Goldschmidt`
# (Debian packages openfoam + openfoam-examples; installed when missing): writes both cases
# from description.yaml (make_cases.py), runs them in interleaved rounds on one core each,
# checks that both simulated the same thing and prints the table (compare.py).
#   benchmarks/peers/goldschmidt/run.sh [--rounds N] [--description FILE] [--compare-only]
# --description: another description (default description.yaml; description_lattice.yaml runs
# the example's own start); its runs go to output/goldschmidt_<name after "description_">.
# GRAINFLOW_BUILD_DIR: the build with bin/grainFoam and lib/libgrainflowFoamBCs.so
# (default: build). Cases and runs go to benchmarks/peers/output/goldschmidt/ (git-ignored).
# Default: settle the bed once (DEM only, a few CPU minutes, cached), then 3 rounds of 0.008
# simulated seconds; one round takes about 4 CPU minutes (DPMFoam ~3, grainFoam ~0.5 each).
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../../.." && pwd)"
BUILD="$(realpath "${GRAINFLOW_BUILD_DIR:-$ROOT/build}")"  # absolute: the runs cd into their cases
FOAM="$ROOT/scripts/foam_env.sh"
rounds=3
compare_only=0
description="$HERE/description.yaml"
while [ $# -gt 0 ]; do
  case "$1" in
    --rounds) rounds="${2:?--rounds needs a number}"; shift 2 ;;
    --description) description="$(realpath "${2:?--description needs a file}")"; shift 2 ;;
    --compare-only) compare_only=1; shift ;;
    *) echo "run.sh: unknown argument '$1' (allowed: --rounds N, --description FILE, --compare-only)" >&2; exit 2 ;;
  esac
done
[ -f "$description" ] || { echo "run.sh: description $description not found" >&2; exit 2; }
name="$(basename "$description" .yaml)"
OUT="$ROOT/benchmarks/peers/output/goldschmidt${name#description}"
[ -x "$BUILD/bin/grain" ] || { echo "run.sh: $BUILD/bin/grain not found (it settles the bed); build the target grain" >&2; exit 1; }
[ -x "$BUILD/bin/grainFoam" ] || { echo "run.sh: $BUILD/bin/grainFoam not found; build the targets grainFoam grainflowFoamBCs or set GRAINFLOW_BUILD_DIR" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "run.sh: /usr/bin/time is needed (Debian package 'time')" >&2; exit 1; }

if [ "$compare_only" -eq 0 ]; then
  if ! dpkg -s openfoam-examples >/dev/null 2>&1 || [ ! -x /usr/bin/DPMFoam ]; then
    echo "run.sh: installing the Debian packages openfoam and openfoam-examples (DPMFoam, v1912)"
    as_root() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }
    export DEBIAN_FRONTEND=noninteractive
    as_root apt-get install -y -qq --no-install-recommends openfoam openfoam-examples ||
      { as_root apt-get update -qq &&
        as_root apt-get install -y -qq --no-install-recommends openfoam openfoam-examples; }
  fi
  "$ROOT/scripts/python.sh" "$HERE/make_cases.py" "$description" "$OUT/cases"
  start=$("$ROOT/scripts/python.sh" --needs yaml -c "import yaml,sys; print(yaml.safe_load(open(sys.argv[1]))['start'])" "$description")
  if [ "$start" = settled ]; then
    # The settled bed is cached in $OUT/settled.h5 (delete it to settle again).
    if [ ! -f "$OUT/settled.h5" ]; then
      echo "run.sh: settling the example's particles (grain run, DEM only; a few minutes)"
      (cd "$OUT/cases/settle" && "$BUILD/bin/grain" run settle.yaml > log.settle 2>&1) ||
        { tail -20 "$OUT/cases/settle/log.settle"; exit 1; }
      last=$(ls "$OUT"/cases/settle/output/particles_*.h5 | sort | tail -1)
      cp "$last" "$OUT/settled.h5"
    fi
    "$ROOT/scripts/python.sh" "$HERE/make_cases.py" "$description" "$OUT/cases" --positions "$OUT/settled.h5"
  fi
  codes=($(/usr/bin/python3 -c "import json,sys; print(' '.join(json.load(open(sys.argv[1]))['codes']))" "$OUT/cases/setup.json"))
  for code in "${codes[@]}"; do
    "$FOAM" blockMesh -case "$OUT/cases/$code" > "$OUT/cases/$code/log.blockMesh" 2>&1 ||
      { tail -20 "$OUT/cases/$code/log.blockMesh"; exit 1; }
  done
  rm -rf "$OUT/runs"
  mkdir -p "$OUT/runs"
  export LD_LIBRARY_PATH="$BUILD/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  for r in $(seq 1 "$rounds"); do
    # Reverse the order every other round so that no code always runs first.
    order=("${codes[@]}")
    if [ $((r % 2)) -eq 0 ]; then order=($(printf '%s\n' "${codes[@]}" | tac)); fi
    for code in "${order[@]}"; do
      run="$OUT/runs/${code}_$r"
      cp -r "$OUT/cases/$code" "$run"
      if [ "$code" = dpmfoam ]; then prog=(/usr/bin/DPMFoam); log=log.DPMFoam
      else prog=("$BUILD/bin/grainFoam"); log=log.grainFoam; fi
      echo "run.sh: round $r/$rounds, $code"
      (cd "$run" && /usr/bin/time -o time.txt -f "%U %S %e %M" "$FOAM" "${prog[@]}" > "$log" 2>&1) ||
        { tail -30 "$run/$log"; exit 1; }
    done
  done
fi
"$ROOT/scripts/python.sh" "$HERE/compare.py" "$OUT"
