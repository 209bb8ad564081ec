#!/bin/bash
# A full disk and an unwritable output directory, on real small file systems (tmpfs mounts;
# needs root or CAP_SYS_ADMIN, else the test is skipped with exit code 77).
#   disk_full.sh GRAIN SCENE WORKDIR PYTHON MPIEXEC
# SCENE (tests/data/scenes/disk_full.yaml): 4000 beads, 100 steps on 2 ranks, a 436 kB
# snapshot every 10 steps (kept) and a 633 kB checkpoint every 20 steps (newest one kept).
#  1. Reference: the whole run on the build directory's disk.
#  2. A 2600 kB file system fills at the snapshot of step 40: exit code 1 on both ranks, no
#     hang, a message naming the file and "No space left on device", no partial file left,
#     checkpoint_000000020.h5 intact; after growing the file system (remount), the restart
#     from it ends exactly where the reference ends.
#  3. A 3100 kB file system fills during the checkpoint of step 40: the same, for a failed
#     checkpoint write (its .part deleted, the previous checkpoint untouched).
#  4. A read-only file system, and one already full: a clear error before the run starts.
set -u
grain=$1 scene=$2 work=$3 python=$4 mpiexec=$5
mnt=$work/mnt
[ -d "$mnt" ] && mountpoint -q "$mnt" && umount "$mnt"
rm -rf "$work" && mkdir -p "$mnt" && cd "$work" || exit 1
if ! mount -t tmpfs -o size=2600k tmpfs "$mnt" 2> mount.txt; then
  echo "SKIP: cannot mount a small tmpfs to fill ($(cat mount.txt)); the test needs root or CAP_SYS_ADMIN"
  exit 77
fi
trap 'cd /; mountpoint -q "$mnt" && umount "$mnt"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# grain on 2 ranks, each rank's exit code appended to ranks.txt; a hang ends at 120 s (124).
# orte_abort_on_non_zero_status 0: mpiexec must not kill the other rank when the first one
# exits with 1 (that race once left rank 1 unrecorded); each rank has to stop on its own.
run2() {
  rm -f ranks.txt
  timeout 120 "$mpiexec" -np 2 --oversubscribe --mca orte_abort_on_non_zero_status 0 sh -c \
    '"$0" "$@"; c=$?; echo "rank $OMPI_COMM_WORLD_RANK exit $c" >> ranks.txt; exit $c' \
    "$grain" run "$scene" --no-progress "$@" > run.txt 2>&1
  code=$?
  cat run.txt
  [ $code -ne 124 ] || fail "grain hung (killed after 120 s)"
  # mpiexec itself exits 0 with that setting: the run's code is the worst rank's.
  if [ -f ranks.txt ] && [ "$(wc -l < ranks.txt)" -eq 2 ]; then
    code=$(awk '$4 > m {m = $4} END {print m + 0}' ranks.txt)
  else
    code=99  # a rank that never reported
  fi
}

# The last snapshot of `$1` equals the reference's, particle by particle (==).
same_end() {
  "$python" - ref/out/particles_000010.h5 "$1/particles_000010.h5" << 'PY'
import sys, h5py, numpy as np
def state(path):
    with h5py.File(path, "r") as f:
        order = np.argsort(f["id"][()])
        return (f["id"][()][order], f["position"][()][order], f["velocity"][()][order],
                f["angular_velocity"][()][order], f.attrs["step"])
a, b = state(sys.argv[1]), state(sys.argv[2])
same = all(np.array_equal(x, y) for x, y in zip(a, b))
print(f"{sys.argv[2]}: step {b[4]}, {len(b[0])} particles, equal to the reference: {same}")
sys.exit(0 if same and len(b[0]) == 4000 else 1)
PY
}

# The checkpoint `$1` reads back with all 4000 particles once each.
intact() {
  "$python" - "$1" << 'PY'
import sys, h5py, numpy as np
with h5py.File(sys.argv[1], "r") as f:
    ids = f["particles/id"][()]
    ok = np.array_equal(np.sort(ids), np.arange(1, 4001)) and f.attrs["step"] == 20
    print(f"{sys.argv[1]}: step {f.attrs['step']}, {len(ids)} particles, intact: {ok}")
sys.exit(0 if ok else 1)
PY
}

# Fills the file system until a failure at `$1` (regex), then checks and continues.
full_disk_case() {
  local size=$1 what=$2 regex=$3
  mountpoint -q "$mnt" && umount "$mnt"
  mount -t tmpfs -o size="$size" tmpfs "$mnt" || fail "mount"
  echo "--- $size file system: the $what write of step 40 fails"
  run2 --output mnt/out
  [ $code -ne 0 ] || fail "exit code 0 on a full disk"
  [ "$(sort ranks.txt | tr '\n' ' ')" = "rank 0 exit 1 rank 1 exit 1 " ] ||
    fail "not every rank stopped with exit code 1: $(cat ranks.txt)"
  grep -Eq "$regex" run.txt || fail "no message matching: $regex"
  df -k "$mnt" | tail -1
  leftovers=$(ls mnt/out | grep -E '\.(part|tmp)$')
  [ -z "$leftovers" ] || fail "partial files left: $leftovers"
  [ ! -e mnt/out/checkpoint_000000040.h5 ] || fail "a checkpoint of step 40 exists"
  intact mnt/out/checkpoint_000000020.h5 || fail "the last good checkpoint is damaged"
  # Space freed (the file system grown): the restart goes on to the end, as the reference.
  mount -o remount,size=20m "$mnt" || fail "remount"
  run2 --output mnt/out --restart mnt/out/checkpoint_000000020.h5
  [ $code -eq 0 ] || fail "the restart after freeing space failed (exit $code)"
  same_end mnt/out || fail "the restart does not end where the reference ends"
}

echo "--- reference run"
run2 --output ref/out
[ $code -eq 0 ] || fail "reference run failed"

full_disk_case 2600k snapshot \
  "grain: error: cannot write snapshot 'mnt/out/particles_000004.h5': .*No space left on device.*The newest complete checkpoint is 'mnt/out/checkpoint_000000020.h5'"
full_disk_case 3100k checkpoint \
  "grain: error: cannot write checkpoint 'mnt/out/checkpoint_000000040.h5': .*No space left on device.*The newest complete checkpoint is 'mnt/out/checkpoint_000000020.h5'"

echo "--- read-only file system"
umount "$mnt" && mount -t tmpfs -o ro,size=1m tmpfs "$mnt" || fail "mount read-only"
run2 --output mnt/out
[ "$(sort ranks.txt | tr '\n' ' ')" = "rank 0 exit 1 rank 1 exit 1 " ] ||
  fail "not every rank stopped with exit code 1: $(cat ranks.txt)"
grep -q "grain: error: output directory 'mnt/out': cannot create directory: Read-only file system" run.txt ||
  fail "no clear message for a read-only file system"
! grep -q "^particles:" run.txt || fail "the run started before the error"

echo "--- file system already full"
umount "$mnt" && mount -t tmpfs -o size=1m tmpfs "$mnt" || fail "mount"
dd if=/dev/zero of="$mnt/filler" bs=64k 2> /dev/null
run2 --output mnt/out
[ "$(sort ranks.txt | tr '\n' ' ')" = "rank 0 exit 1 rank 1 exit 1 " ] ||
  fail "not every rank stopped with exit code 1: $(cat ranks.txt)"
grep -q "grain: error: output directory 'mnt/out': cannot write to a file in it: No space left on device" run.txt ||
  fail "no clear message for a full file system"
! grep -q "^particles:" run.txt || fail "the run started before the error"
echo "PASS"
