#!/usr/bin/env bash
# Times `grain run` on settling_bed.yaml: K=1 without the key and with `coarse_grain: 1`,
# and K = 2, 3 (COUNT/K^3 parcels). Usage: run.sh [grain binary] [reference grain binary]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
grain="${1:-$here/../../build/bin/grain}"
reference="${2:-}"
work="$(mktemp -d /tmp/coarse_grain_bench.XXXXXX)"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
make_scene() {  # count key-line
  sed -e "s/COUNT/$1/" -e "s|#KEY|$2|" "$here/settling_bed.yaml" > "$work/scene.yaml"
}
time_run() {  # label binary: wall and user CPU seconds (CPU is steadier on a shared machine)
  local t0 t1 cpu
  t0=$(date +%s.%N)
  cpu=$( { TIMEFORMAT=%U; time "$2" run "$work/scene.yaml" --output "$work/out" --no-progress \
           > "$work/log.txt"; } 2>&1 )
  t1=$(date +%s.%N)
  printf '%-34s wall %7.2f s  cpu %7.2f s  %s\n' "$1" "$(echo "$t1 - $t0" | bc)" "$cpu" \
    "$(grep -o 'done: [0-9]* steps' "$work/log.txt")"
}
for rep in 1 2 3; do
  make_scene 4000 ""
  [ -n "$reference" ] && time_run "reference, no key (run $rep)" "$reference"
  time_run "no key (run $rep)" "$grain"
  make_scene 4000 "    coarse_grain: 1"
  time_run "coarse_grain: 1 (run $rep)" "$grain"
done
for k in 2 3; do
  make_scene $((4000 / (k * k * k))) "    coarse_grain: $k"
  time_run "coarse_grain: $k ($((4000 / (k * k * k))) parcels)" "$grain"
done
rm -rf "$work"
