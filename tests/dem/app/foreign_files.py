#!/usr/bin/env python3
"""A restart into a folder that also holds another scene's run (grain.foreign_files;
docs/scene-reference.md, "One run per output folder").

    foreign_files.py GRAIN SCENE WORKDIR

SCENE (tests/data/scenes/stop_signal.yaml: 300 beads, snapshots every 0.5 s, checkpoints
every 1 s) is turned into two scenes that write into one folder, as a user does who reuses it:
  A  300 beads, end 0.3 s, a snapshot every 0.01 s (31 files), a checkpoint every 0.1 s
     (the newest two kept: t = 0.2 and 0.3 s);
  B  150 beads, end 1.2 s, snapshots until 1 s: at 0, 0.5 and 1 s, over A's files 0-2, and a
     checkpoint at 1 s; then B continued from that checkpoint to 3 s (checkpoints at 2 and 3 s,
     checkpoint_keep 2), as a run stopped at 1 s (SIGTERM) is continued.
A's files 3-30 hold steps below B's checkpoint. Checks:
  * the restart takes over B's three snapshots only: particles.xdmf lists t = 0, 0.5, ... 3 s,
    every listed file holds 150 particles, and the restart's note names particles_000003.h5
    as another scene's;
  * A's two checkpoints are still there after B's series has kept its newest two, and the
    restart's notes name them;
  * B's final state is the uninterrupted B's (a run of B to 3 s in a clean folder), bit for bit;
  * B's checkpoint continued in a third folder, where A ran (A's log.csv, whose steps are all
    below the checkpoint's): that folder's log.csv is the uninterrupted B's row for row (every
    column but the wall clock), with a note that A's rows were replaced; before, A's rows
    stayed in front of B's continuation.
A last run checks gaps: A again, its snapshot 5 deleted and 9 cut short, continued from its
checkpoint: both named as gaps, the index lists the other 29, each number at its own time.
And A continued with snapshots every 0.02 s: the older files 21-30 it leaves are named.
Exit 0 when every check holds.
"""
import glob
import os
import re
import shutil
import subprocess
import sys

import h5py
import numpy as np

grain, scene_path, work = (os.path.abspath(a) for a in sys.argv[1:4])
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
base = open(scene_path).read()
failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


def scene(name, count, end, snapshots, checkpoints, stop=None):
    text = base.replace("count: 300", f"count: {count}").replace("end: 5}", f"end: {end}}}")
    text = text.replace("snapshot_interval: 0.5", f"snapshot_interval: {snapshots}" +
                        (f", stop: {stop}" if stop else ""))
    text = text.replace("checkpoint_interval: 1,", f"checkpoint_interval: {checkpoints},")
    with open(os.path.join(work, name), "w") as f:
        f.write(text)
    return name


def grain_run(name, out, *extra):
    r = subprocess.run([grain, "run", name, "--output", out, "--no-progress", *extra], cwd=work,
                       capture_output=True, text=True, timeout=300)
    if r.returncode != 0:
        sys.exit(f"grain run {name} {' '.join(extra)}: exit {r.returncode}\n{r.stdout[-2000:]}"
                 f"{r.stderr[-2000:]}")
    return r.stdout + r.stderr


def last_state(out):
    """The state in the last snapshot particles.xdmf lists (the folder may hold A's files with
    higher numbers)."""
    index = open(os.path.join(work, out, "particles.xdmf")).read()
    last = os.path.join(work, out, re.findall(r"particles_\d+\.h5", index)[-1])
    with h5py.File(last, "r") as f:
        order = np.argsort(f["id"][:])
        return float(f.attrs["time"]), f["position"][:][order], f["velocity"][:][order]


grain_run(scene("a.yaml", 300, 0.3, 0.01, 0.1), "out")
a_checkpoints = sorted(glob.glob(os.path.join(work, "out", "checkpoint_*.h5")))
check(len(a_checkpoints) == 2, f"A left {len(a_checkpoints)} checkpoints (2)")
grain_run(scene("b.yaml", 150, 1.2, 0.5, 1, stop=1.0), "out")
b_checkpoint = sorted(set(glob.glob(os.path.join(work, "out", "checkpoint_*.h5"))) -
                      set(a_checkpoints))
check(len(b_checkpoint) == 1, f"B's run to 1.2 s wrote one checkpoint ({b_checkpoint})")
if not b_checkpoint:
    sys.exit(1)
scene("b3.yaml", 150, 3, 0.5, 1)
log = grain_run("b3.yaml", "out", "--restart", os.path.relpath(b_checkpoint[0], work))

m = re.search(r"continuing \S+ and the snapshot series after (\d+) earlier snapshot", log)
check(m is not None and m.group(1) == "3",
      f"the restart continues after B's 3 snapshots ({m.group(1) if m else 'no line'})")
check("note: out/particles_000003.h5 was written by another scene's run" in log,
      "the restart's note names A's particles_000003.h5")
index = open(os.path.join(work, "out", "particles.xdmf")).read()
times = [float(t) for t in re.findall(r'<Time Value="([^"]+)"', index)]
check(len(times) == 7 and np.allclose(times, np.arange(0, 3.01, 0.5), atol=1e-4),
      f"particles.xdmf lists t = {[round(t, 3) for t in times]} (0, 0.5, ... 3 s)")
listed = sorted(set(re.findall(r"particles_\d+\.h5", index)))
counts = []
for name in listed:
    with h5py.File(os.path.join(work, "out", name), "r") as f:
        counts.append(int(f.attrs["count"]))
check(counts == [150] * 7, f"every file the index lists holds 150 particles ({counts})")
kept = [os.path.exists(p) for p in a_checkpoints]
check(all(kept), f"A's checkpoints survive B's series: {kept}")
for p in a_checkpoints:
    check(f"note: out/{os.path.basename(p)} was written by another scene's run" in log,
          f"the restart's note names {os.path.basename(p)}")
ours = sorted(set(glob.glob(os.path.join(work, "out", "checkpoint_*.h5"))) - set(a_checkpoints))
check(len(ours) == 2, f"B's series keeps its newest 2 checkpoints ({len(ours)})")

grain_run("a.yaml", "other")
other = grain_run("b3.yaml", "other", "--restart", os.path.relpath(b_checkpoint[0], work))
check("note: other/log.csv held rows that the checkpoint's run did not write" in other,
      "the restart in A's folder says that A's log rows were replaced")


def log_rows(out):
    """log.csv's rows without the wall-clock column (the last of the usual ten)."""
    lines = open(os.path.join(work, out, "log.csv")).read().splitlines()
    return [",".join(line.split(",")[:9]) for line in lines]


grain_run("b3.yaml", "clean")
clean_rows, other_rows = log_rows("clean"), log_rows("other")
check(other_rows == clean_rows,
      f"log.csv of B continued in A's folder is the uninterrupted B's row for row "
      f"({len(other_rows)} and {len(clean_rows)} lines; first difference at line "
      f"{next((i for i, (a, b) in enumerate(zip(other_rows, clean_rows)) if a != b), None)})")
check(log_rows("out") == clean_rows, "so is log.csv of B continued in its own folder")
t1, x1, v1 = last_state("out")
t2, x2, v2 = last_state("clean")
check(t1 == t2 and np.array_equal(x1, x2) and np.array_equal(v1, v2),
      f"B continued beside A's files ends as B alone, bit for bit (t = {t1:g} and {t2:g} s; "
      f"largest position difference {np.abs(x1 - x2).max() if x1.shape == x2.shape else 'n/a'})")
# Gaps: A run again in a folder of its own, its snapshot 5 deleted and 9 cut short, then
# continued from its checkpoint at 0.2 s (step of snapshot 20) to 0.3 s. The takeover ended at
# the first gap (the index lost 18 of A's snapshots, and the restart wrote over numbers 5-14
# with later times); now it steps over both, naming them, and every number keeps its time.
grain_run("a.yaml", "gaps")
index_before = open(os.path.join(work, "gaps", "particles.xdmf")).read()
times_before = [float(t) for t in re.findall(r'<Time Value="([^"]+)"', index_before)]
os.remove(os.path.join(work, "gaps", "particles_000005.h5"))
with open(os.path.join(work, "gaps", "particles_000009.h5"), "r+b") as f:
    f.truncate(100)
a_checkpoint = sorted(glob.glob(os.path.join(work, "gaps", "checkpoint_*.h5")))[0]
out = grain_run("a.yaml", "gaps", "--restart", os.path.relpath(a_checkpoint, work))
check("note: gaps/particles_000005.h5 (missing) is a gap" in out and
      "note: gaps/particles_000009.h5 (unreadable) is a gap" in out,
      "the restart names the deleted and the damaged snapshot as gaps")
index = open(os.path.join(work, "gaps", "particles.xdmf")).read()
listed = re.findall(r"particles_(\d+)\.h5", index)
numbers = sorted({int(n) for n in listed})
check(numbers == [n for n in range(31) if n not in (5, 9)],
      f"particles.xdmf lists 0-30 but 5 and 9 ({len(numbers)} files)")
times = {}
for n in numbers:
    with h5py.File(os.path.join(work, "gaps", f"particles_{n:06d}.h5"), "r") as f:
        times[n] = float(f.attrs["time"])
check(all(abs(times[n] - times_before[n]) < 1e-9 for n in numbers),
      "every number holds the time the uninterrupted run gave it")
# A longer snapshot interval after the restart: A continued from its checkpoint at 0.1 s with
# snapshots every 0.02 s writes numbers 11-20 (t = 0.12 ... 0.3 s), and the stopped run's 21-30
# stay. The restart says so at its end, naming them (they were left without a word, and a
# script taking the last file by name read t = 0.3 s from the run before the restart).
scene("a_longer.yaml", 300, 0.3, 0.02, 0.1)
grain_run("a.yaml", "longer")
a_checkpoint = sorted(glob.glob(os.path.join(work, "longer", "checkpoint_*.h5")))[0]
out = grain_run("a_longer.yaml", "longer", "--restart", os.path.relpath(a_checkpoint, work))
check("note: longer still holds 10 snapshot(s) numbered after this run's last "
      "(particles_000021.h5 to particles_000030.h5), written before the restart" in out,
      "a restart with a longer snapshot interval names the 10 older files left after its series")
listed = sorted({int(n) for n in re.findall(r"particles_(\d+)\.h5",
                                            open(os.path.join(work, "longer", "particles.xdmf")).read())})
check(listed == list(range(21)), f"its particles.xdmf lists 0-20 ({len(listed)} files)")
print(f"grain.foreign_files: {len(failures)} failed checks")
sys.exit(1 if failures else 0)
