#!/usr/bin/env bash
# The coupled hard cases (tests/coupling_stress/) at full length: every case of the CTest
# suite, with the cases that evolve in time (the dense bed under 10 U_mf, the convected slab
# that empties and refills cells and crosses ranks) run SCALE times longer, with the same
# invariants checked at every write. Logs, fields and snapshots stay in <build>/hard_cases/coupled/.
#
#   benchmarks/hard_cases/coupled/run.sh [build-dir] [scale]     (defaults: build, 10)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)"
BUILD="$(cd "${1:-$ROOT/build}" && pwd)"
SCALE="${2:-10}"
WORK="$BUILD/hard_cases/coupled"
export GRAINFLOW_STRESS_SCALE="$SCALE"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export GRAINFLOW_FOAM_BASHRC="${GRAINFLOW_FOAM_BASHRC:-/usr/share/openfoam/etc/bashrc}"
mkdir -p "$WORK"  # the logs go beside it, $WORK.<case>.log
status=0
for case in dense_bed_10x_umf particles_larger_than_cells on_faces_and_corners_2ranks \
            crowded_cell_2ranks emptied_and_refilled_cells fast_crossing_ranks; do
  echo "== $case (scale $SCALE)"
  "$ROOT/scripts/python.sh" "$ROOT/tests/coupling_stress/stress_cases.py" "$case" \
    --foam-env "$ROOT/scripts/foam_env.sh" --solver "$BUILD/bin/grainFoam" \
    --mpiexec mpiexec --lib-dir "$BUILD/lib" --cases "$ROOT/tests/coupling_stress/cases" \
    --work "$WORK/$case" | tee "$WORK.$case.log" | grep -E "^  (ok|FAIL)|failed checks" || status=1
  grep -q " 0 failed checks" "$WORK.$case.log" || status=1
done
exit $status
