#!/bin/bash
# SIGTERM stops `grain run` cleanly: exit code 0, a message naming the checkpoint, and a
# checkpoint that reads back with every particle. The restart from it (to 0.02 s after the
# stop) continues the log as a run that wrote a checkpoint at that step does: the stopped
# run's rows up to the stop, without the row the stop added at its step (a log row every
# 0.01 s: no row off that grid but the last), then its own.
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
cp out/log.csv stopped_log.csv
stop_time=$(sed -n 's/.*stopped after step [0-9]* (t = \([^ ]*\) s).*/\1/p' run.txt)
stop_step=$(sed -n 's/.*stopped after step \([0-9]*\) .*/\1/p' run.txt)
end=$("$python" -c "print($stop_time + 0.02)")
sed "s/end: 5}/end: $end}/" "$scene" > restart.yaml
"${launcher[@]}" "$grain" run restart.yaml --restart "$checkpoint" --output out --no-progress \
  > restart.txt 2>&1 || { cat restart.txt; echo "FAIL: the restart exited $?"; exit 1; }
"$python" - "$stop_step" << 'PY' || { echo "FAIL: the restarted log"; exit 1; }
import sys
stop = int(sys.argv[1])
def rows(path):
    lines = open(path).read().splitlines()
    return lines[0], [l.split(",") for l in lines[1:]]
header, stopped = rows("stopped_log.csv")
_, restarted = rows("out/log.csv")
steps = [int(r[1]) for r in restarted]
times = [float(r[0]) for r in restarted]
ok = True
def check(cond, what):
    global ok
    print(("ok    " if cond else "FAIL  ") + what)
    ok &= cond
check(int(stopped[-1][1]) == stop, f"the stopped run's log ends with a row at the stop, step "
      f"{stop} ({stopped[-1][1]})")
check(all(b > a for a, b in zip(steps, steps[1:])), "the restarted log's steps increase")
off_grid = [t for t in times[:-1] if abs(t / 0.01 - round(t / 0.01)) > 0.01]  # dt ~ 3e-6 s
check(not off_grid, f"no row off the 0.01 s grid but the last (off: {off_grid})")
kept = [r for r in restarted if int(r[1]) <= stop]
check(kept == [r for r in stopped if int(r[1]) < stop],
      f"the {len(kept)} rows up to the stop are the stopped run's before it, unchanged")
check(len(restarted) > len(kept) + 1, f"the restart wrote {len(restarted) - len(kept)} rows")
sys.exit(0 if ok else 1)
PY
echo "PASS"
