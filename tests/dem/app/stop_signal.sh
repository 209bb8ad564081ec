#!/bin/bash
# SIGTERM stops `grain run` cleanly: exit code 0, a message naming the checkpoint, and a
# checkpoint that reads back with every particle.
#   stop_signal.sh GRAIN SCENE WORKDIR PYTHON [MPIEXEC NP]
set -u
grain=$1 scene=$2 work=$3 python=$4
launcher=()
[ $# -ge 6 ] && launcher=("$5" -np "$6" --oversubscribe)
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
"${launcher[@]}" "$grain" run "$scene" --output out --no-progress > run.txt 2>&1 &
pid=$!
# Wait for the first log row: the signal handlers are installed by then.
for _ in $(seq 100); do
  [ "$(wc -l 2> /dev/null < out/log.csv || echo 0)" -ge 2 ] && break
  sleep 0.1
done
sleep 1
# Under mpiexec the ranks get the signal, as from a batch scheduler (Open MPI's mpiexec
# forwards a SIGTERM sent to it, but then exits 1 itself).
targets=$pid
if [ ${#launcher[@]} -gt 0 ]; then
  targets=$(pgrep -P $pid)
  for p in $targets; do targets="$targets $(pgrep -P "$p")"; done
  targets=$(for p in $targets; do [ "$(cat /proc/$p/comm 2> /dev/null)" = grain ] && echo $p; done)
fi
kill -TERM $targets
wait $pid
code=$?
cat run.txt
[ $code -eq 0 ] || { echo "FAIL: exit code $code, expected 0"; exit 1; }
checkpoint=$(sed -n 's/.*wrote the checkpoint \([^;]*\);.*/\1/p' run.txt)
[ -n "$checkpoint" ] || { echo "FAIL: no message naming the checkpoint"; exit 1; }
[ -f "$checkpoint" ] || { echo "FAIL: checkpoint '$checkpoint' does not exist"; exit 1; }
"$python" - "$checkpoint" << 'PY' || { echo "FAIL: checkpoint does not read back"; exit 1; }
import sys, h5py
with h5py.File(sys.argv[1], "r") as f:
    n = f["particles/id"].shape[0]
    print(f"checkpoint {sys.argv[1]}: {n} particles, step {f.attrs['step']}")
    sys.exit(0 if n == 300 else 1)
PY
echo "PASS"
