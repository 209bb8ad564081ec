#!/bin/bash
# The "continue with:" line after SIGTERM, run literally, continues the same run: same output
# folder (given with --output, not the scene's output.directory), snapshot numbering going on.
#   continue_command.sh GRAIN SCENE WORKDIR PYTHON [MPIEXEC NP]
# SCENE (tests/data/scenes/continue_command.yaml): 0.2 s, a snapshot every 0.01 s, so the
# whole series is particles_000000 .. particles_000020 at t = 0.01 k (within one step).
set -u
grain=$1 scene=$2 work=$3 python=$4
launcher=()
[ $# -ge 6 ] && launcher=("$5" -np "$6" --oversubscribe)
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
"${launcher[@]}" "$grain" run "$scene" --output elsewhere --no-progress > first.txt 2>&1 &
pid=$!
# Stopped after a few snapshots (the signal handlers are installed by the first log row).
for _ in $(seq 300); do
  [ -f elsewhere/particles_000003.h5 ] && break
  sleep 0.1
done
targets=$pid
if [ ${#launcher[@]} -gt 0 ]; then  # the ranks get the signal, as from a batch scheduler
  targets=$(pgrep -P $pid)
  for p in $targets; do targets="$targets $(pgrep -P "$p")"; done
  targets=$(for p in $targets; do [ "$(cat /proc/$p/comm 2> /dev/null)" = grain ] && echo $p; done)
fi
kill -TERM $targets
wait $pid
code=$?
cat first.txt
[ $code -eq 0 ] || fail "exit code $code after SIGTERM, expected 0"
command=$(sed -n 's/.*; continue with: //p' first.txt)
[ -n "$command" ] || fail "no 'continue with:' line"
stopped=$(ls elsewhere/particles_*.h5 | wc -l)
[ "$stopped" -lt 21 ] || fail "the run was not stopped before its end ($stopped snapshots)"
echo "--- running: $command"
eval "$command" > second.txt 2>&1
code=$?
cat second.txt
[ $code -eq 0 ] || fail "the printed command failed (exit $code)"
grep -q "^done: " second.txt || fail "the printed command did not run to the end"
grep -q "restart: from .* continuing elsewhere/log.csv and the snapshot series after" second.txt ||
  fail "the printed command did not continue in 'elsewhere'"
[ ! -e scene_out ] || fail "the printed command wrote into the scene's output.directory"
"$python" - elsewhere << 'PY' || fail "the snapshot series is not the uninterrupted one's"
import glob, re, sys, h5py
files = sorted(glob.glob(sys.argv[1] + "/particles_*.h5"))
names = [f"{sys.argv[1]}/particles_{k:06d}.h5" for k in range(21)]
print(f"{len(files)} snapshots: {files[0]} .. {files[-1]}")
if files != names:
    sys.exit(f"expected {names[0]} .. {names[-1]} without gaps")
steps = []
for k, name in enumerate(files):
    with h5py.File(name, "r") as f:
        t, step, dt_bound = f.attrs["time"], int(f.attrs["step"]), 1e-4  # dt is 2.7e-6 s
        steps.append(step)
        if abs(t - 0.01 * k) > dt_bound or f["id"].shape[0] != 300:
            sys.exit(f"{name}: t = {t} s, {f['id'].shape[0]} particles; expected t = {0.01 * k}")
if any(b <= a for a, b in zip(steps, steps[1:])):
    sys.exit(f"steps do not increase: {steps}")
index = open(sys.argv[1] + "/particles.xdmf").read()
if sorted(set(re.findall(r"particles_\d{6}\.h5", index))) != [n.split("/")[-1] for n in names]:
    sys.exit("the XDMF index does not list the 21 snapshots")
PY
echo "PASS"
