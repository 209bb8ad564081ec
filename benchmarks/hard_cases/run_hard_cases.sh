#!/usr/bin/env bash
# Runs the stress suite of issue 8 (tests/dem/stress/) at a longer horizon: the same
# test binaries, with GRAINFLOW_STRESS_SCALE multiplying every test's step count.
#   benchmarks/hard_cases/run_hard_cases.sh [build-dir] [scale]
# Defaults: build-dir = build-stress, scale = 10. Output: one log per case in
# <build-dir>/hard_cases/, and a pass/fail line per case on the terminal.
set -u
here=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$here/build-stress}
scale=${2:-10}
export GRAINFLOW_STRESS_SCALE=$scale
export OMPI_ALLOW_RUN_AS_ROOT=${OMPI_ALLOW_RUN_AS_ROOT:-1}
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=${OMPI_ALLOW_RUN_AS_ROOT_CONFIRM:-1}
serial=(stiff_contacts_test high_speed_impact_test mesh_impact_test wide_size_distribution_test
        too_large_step_test)
parallel=(fast_crossing_mpi4_test boundary_resting_mpi4_test periodic_side_many_ranks_mpi4_test)
ninja -C "$build" -j2 "${serial[@]}" "${parallel[@]}" || exit 1
mkdir -p "$build/hard_cases"
status=0
for t in "${serial[@]}" "${parallel[@]}"; do
  log=$build/hard_cases/$t.log
  start=$(date +%s)
  if [[ $t == *_mpi4_test ]]; then
    mpirun -np 4 --oversubscribe "$build/tests/$t" >"$log" 2>&1
  else
    "$build/tests/$t" >"$log" 2>&1
  fi
  rc=$?
  [[ $rc -ne 0 ]] && status=1
  printf '%-40s %s  (%ss, log %s)\n' "$t" "$([[ $rc -eq 0 ]] && echo passed || echo FAILED)" \
    "$(( $(date +%s) - start ))" "$log"
  # The measured figures each test prints (one line per case).
  grep -E '^(dt =|glass|soft|[0-9]+ (spheres|steps)|rain|one sphere)' "$log" | sort -u | sed 's/^/    /'
done
exit $status
