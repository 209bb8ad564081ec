#!/bin/bash
# The NaN guard in `grain run`: a restart from a checkpoint in which one particle's velocity
# is NaN stops at once with exit code 1, a message naming that particle, and a diagnostic
# snapshot.   nan_guard.sh GRAIN SCENE WORKDIR PYTHON
set -u
grain=$1 scene=$2 work=$3 python=$4
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
"$grain" run "$scene" --output out --no-progress > first.txt 2>&1 || { cat first.txt; exit 1; }
checkpoint=$(ls out/checkpoint_*.h5 | head -1)
[ -n "$checkpoint" ] || { echo "FAIL: no checkpoint written"; exit 1; }
id=$("$python" - "$checkpoint" << 'PY'
import sys, h5py
with h5py.File(sys.argv[1], "r+") as f:
    f["particles/velocity"][7, 0] = float("nan")
    print(f["particles/id"][7])
PY
) || { echo "FAIL: could not poison the checkpoint"; exit 1; }
"$grain" run "$scene" --output out --no-progress --restart "$checkpoint" > run.txt 2>&1
code=$?
cat run.txt
[ $code -eq 1 ] || { echo "FAIL: exit code $code, expected 1"; exit 1; }
grep -q "particle $id (rank 0) has a non-finite velocity; position (" run.txt ||
  { echo "FAIL: message does not name particle $id"; exit 1; }
grep -q "force (" run.txt || { echo "FAIL: message does not give the force"; exit 1; }
[ -f out/diagnostic_000000.h5 ] || { echo "FAIL: no diagnostic snapshot"; exit 1; }
echo "PASS"
