#!/bin/bash
# Under mpirun every rank reads its own command line and scene file. A rank that cannot (a
# scene on standard input, which mpirun gives to rank 0 only; a file missing on one node; an
# option given to one rank of a mixed launch) must stop every rank with a message and exit
# code 2, not leave the others waiting for it.
#   rank_agreement.sh GRAIN SCENE WORKDIR MPIEXEC
set -u
grain=$1 scene=$2 work=$3 mpiexec=$4
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0
# expect NAME CODE REGEX -- COMMAND...: the command ends within 60 s with CODE, its output
# matching REGEX (grep -E), and writes no output folder.
expect() {
  local name=$1 code=$2 regex=$3
  shift 4
  timeout 60 "$@" > "$name.txt" 2>&1
  local rc=$?
  if [ $rc -eq 124 ]; then
    echo "FAIL $name: still running after 60 s (a rank waits for the others)"; failures=$((failures + 1))
  elif [ $rc -ne "$code" ] || ! grep -Eq "$regex" "$name.txt"; then
    echo "FAIL $name: exit $rc (expected $code), output:"; cat "$name.txt"; failures=$((failures + 1))
  elif [ -e out ]; then
    echo "FAIL $name: wrote the output folder"; failures=$((failures + 1)); rm -rf out
  else
    echo "ok $name: exit $rc, $(grep -E -m1 "$regex" "$name.txt" | cut -c1-150)"
  fi
}
two=("$mpiexec" -np 2 --oversubscribe)
one=("$mpiexec" -np 1 --oversubscribe)
expect stdin 2 "^grain \(rank 1 of 2\): /dev/stdin:1:1: error: the scene is empty" -- \
  bash -c "cat '$scene' | ${two[*]} '$grain' run /dev/stdin --output out --no-progress"
grep -q "standard input, which mpirun gives to rank 0 only" stdin.txt ||
  { echo "FAIL stdin: no word of standard input"; failures=$((failures + 1)); }
expect option_on_one_rank 2 "^grain \(rank 1 of 2\): grain: unknown option '--bogus' for 'run'" -- \
  "${one[@]}" "$grain" run "$scene" --output out --no-progress : \
  -np 1 "$grain" run "$scene" --output out --no-progress --bogus
expect scene_missing_on_one_rank 2 "^grain \(rank 1 of 2\): nosuch\.yaml: error: cannot open the scene file" -- \
  "${one[@]}" "$grain" run "$scene" --output out --no-progress : \
  -np 1 "$grain" run nosuch.yaml --output out --no-progress
expect other_options_on_one_rank 2 "the ranks differ in their command lines \(or working directories\) \(rank 0" -- \
  "${one[@]}" "$grain" run "$scene" --output out --no-progress : -np 1 "$grain" run "$scene" --output out
expect help_on_one_rank 2 "the ranks differ in their command lines" -- \
  "${one[@]}" "$grain" --help : -np 1 "$grain" check "$scene"
expect other_environment 2 "the ranks differ in their GRAINFLOW_\* environment variables" -- \
  "${one[@]}" "$grain" run "$scene" --output out --no-progress : \
  -np 1 env GRAINFLOW_SNAPSHOT_MPIIO=1 "$grain" run "$scene" --output out --no-progress
# A file the scene names, missing in one rank's working directory (as on a node that does not
# see it): refused before any rank waits for another (it had hung, or crashed in MPI when the
# two files differed).
mkdir -p a b
printf 'x,y,z,radius\n0.005,0.005,0.005,4e-4\n' > a/beads.csv
for d in a b; do
  cat > $d/csv.yaml << 'YAML'
domain: {min: [0, 0, 0], max: [0.01, 0.01, 0.02]}
gravity: [0, 0, -9.81]
time: {rayleigh_fraction: 0.2, end: 0.002}
materials: [{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.25, density: 2500}]
interactions: [{materials: [glass, glass], restitution: 0.5, friction: 0.3}]
contact: {normal: hertz}
walls: [{type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass}]
insert: [{type: csv, file: beads.csv, material: glass}]
output: {directory: /tmp/grainflow_rank_agreement_never_made}
YAML
done
expect file_missing_on_one_rank 2 "the ranks differ in their command lines \(or working directories\), files the scene or --restart names" -- \
  "${one[@]}" -wdir "$work/a" "$grain" run csv.yaml --no-progress : \
  -np 1 -wdir "$work/b" "$grain" run csv.yaml --no-progress
[ ! -e /tmp/grainflow_rank_agreement_never_made ] ||
  { echo "FAIL file_missing_on_one_rank: wrote the output folder"; failures=$((failures + 1)); }
# A checkpoint of the same size but other contents on one rank (as a node's stale copy): it
# had been compared by its size only, and each rank restored its own copy's particles.
cp a/beads.csv b/beads.csv
sed 's/end: 0.002/end: 0.004/; s#output: {directory: [^}]*}#output: {directory: ck, checkpoint_interval: 0.001}#' \
  a/csv.yaml > a/ck.yaml
timeout 60 "$grain" run a/ck.yaml --output a/ck --no-progress > ck_run.txt 2>&1 ||
  { echo "FAIL checkpoint run:"; cat ck_run.txt; failures=$((failures + 1)); }
first=$(ls a/ck/checkpoint_*.h5 | head -1)
cp a/ck.yaml b/ck.yaml && cp "$first" a/ckpt.h5 && cp "$first" b/ckpt.h5
python3 - b/ckpt.h5 << 'PY'
import sys
with open(sys.argv[1], "r+b") as f:  # one byte of the file's last part (particle data) flipped
    f.seek(-100, 2); b = f.read(1); f.seek(-100, 2); f.write(bytes([b[0] ^ 0xFF]))
PY
# The same path must hold the same bytes on both ranks: rank 1 sees b's copy through a bind
# mount in its own mount namespace (where unshare is allowed; skipped otherwise).
if unshare -m true 2> /dev/null; then
  expect checkpoint_differs_on_one_rank 2 "the ranks differ in their files the scene or --restart names" -- \
    "${one[@]}" "$grain" run a/ck.yaml --restart a/ckpt.h5 --output out --no-progress : \
    -np 1 unshare -m bash -c "mount --bind b/ckpt.h5 a/ckpt.h5 && exec '$grain' run a/ck.yaml --restart a/ckpt.h5 --output out --no-progress"
else
  echo "skip checkpoint_differs_on_one_rank: no mount namespaces here"
fi
expect checkpoint_alike 0 "^done:" -- \
  "${one[@]}" "$grain" run a/ck.yaml --restart a/ckpt.h5 --output ck2 --no-progress : \
  -np 1 "$grain" run a/ck.yaml --restart a/ckpt.h5 --output ck2 --no-progress
rm -rf ck2
# Agreeing ranks still run, and --version and usage errors print once.
expect version_once 0 "^grain \(grainflow\)" -- "${two[@]}" "$grain" --version
[ "$(grep -c "grain (grainflow)" version_once.txt)" = 1 ] ||
  { echo "FAIL version_once: printed $(grep -c "grain (grainflow)" version_once.txt) times"; failures=$((failures + 1)); }
expect usage_once 2 "unknown option '--bogus'" -- "${two[@]}" "$grain" run "$scene" --bogus
[ "$(grep -c "^usage: grain" usage_once.txt)" = 1 ] ||
  { echo "FAIL usage_once: the usage printed $(grep -c "^usage: grain" usage_once.txt) times"; failures=$((failures + 1)); }
timeout 120 "${two[@]}" "$grain" run "$scene" --output ran --no-progress > ran.txt 2>&1 &&
  grep -q "^done:" ran.txt && echo "ok agreeing ranks run" ||
  { echo "FAIL agreeing ranks: "; cat ran.txt; failures=$((failures + 1)); }
[ $failures -eq 0 ] || { echo "$failures failure(s)"; exit 1; }
echo "every disagreement stops all ranks with a message"
