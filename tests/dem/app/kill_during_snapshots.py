#!/usr/bin/env python3
"""kill -9 while snapshots and the XDMF index are written, repeatedly (docs/reliability.md).

    kill_during_snapshots.py GRAIN SCENE WORKDIR [KILLS]

Runs `grain run SCENE` (300 beads, a snapshot with all 13 fields every 10 steps, about 10 ms
apart, a checkpoint every 100 steps) and kills it with SIGKILL KILLS times at a random moment
0 to 0.3 s after the run has written (a restart: rewritten) its index, restarting each time
from the newest checkpoint (or afresh when there is none yet). After each kill, `particles.xdmf`:
  - parses (Python's xml.etree, i.e. expat) as one Temporal Collection;
  - lists particles_000000 .. particles_<n-1> in order, times strictly increasing;
  - every file it lists exists and opens with h5py, with the listed time (exactly), count
    and the listed datasets with the listed shapes and number types.
The last restart is stopped with SIGTERM and must exit 0 with an index that lists, in the
same way, at least the snapshots up to its last checkpoint.
"""
import os
import random
import re
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

import h5py

CHECKPOINT = re.compile(r"^checkpoint_(\d{9})\.h5$")
RUNNING = []  # the grain process under test, killed when the test fails


def fail(message, log=None):
    for proc in RUNNING:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    if log and os.path.exists(log):
        sys.stdout.write(open(log).read())
    print("FAIL: " + message)
    sys.exit(1)


def check_index(out, when):
    """Parses out/particles.xdmf and opens every file it lists; returns the number listed."""
    path = os.path.join(out, "particles.xdmf")
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as e:
        fail(f"{when}: {path} does not parse: {e}\n{open(path, errors='replace').read()}")
    (series,) = root.findall("Domain/Grid")
    if series.get("CollectionType") != "Temporal":
        fail(f"{when}: {path}: the series is not a Temporal Collection")
    grids = series.findall("Grid")
    last_time = None
    for k, step in enumerate(grids):  # one Spatial collection per time
        name = f"particles_{k:06d}"
        if step.get("Name") != name or step.get("CollectionType") != "Spatial":
            fail(f"{when}: {path}: time step {k} is {step.get('Name')} "
                 f"({step.get('CollectionType')}), expected the Spatial collection {name}")
        t = float(step.find("Time").get("Value"))
        if last_time is not None and t <= last_time:
            fail(f"{when}: {path}: {name} at t = {t} after t = {last_time}")
        last_time = t
        grid = step.find("Grid[@Name='particles']")  # none when the snapshot is empty
        count = 0 if grid is None else int(grid.find("Topology").get("NumberOfElements"))
        items = [] if grid is None else [grid.find("Geometry/DataItem")] + [
            a.find("DataItem") for a in grid.findall("Attribute")]
        with h5py.File(os.path.join(out, name + ".h5"), "r") as f:
            if float(f.attrs["time"]) != t or int(f.attrs["count"]) != count:
                fail(f"{when}: {name}.h5 holds t = {f.attrs['time']}, {f.attrs['count']} "
                     f"particles; the index says t = {t}, {count}")
            for item in items:
                file_name, dataset = item.text.strip().split(":")
                if file_name != name + ".h5":
                    fail(f"{when}: grid {name} refers to {file_name}")
                dims = tuple(int(d) for d in item.get("Dimensions").split())
                data = f[dataset]
                kind = "Float" if data.dtype.kind == "f" else "Int"
                if data.shape != dims or kind != item.get("NumberType") or \
                        data.dtype.itemsize != int(item.get("Precision")):
                    fail(f"{when}: {name}.h5:{dataset} is {data.shape} {data.dtype}; the index "
                         f"says {dims} {item.get('NumberType')} {item.get('Precision')}")
                data[()]  # reads (and checks the Fletcher32 checksums of) every chunk
    return len(grids)


def main():
    grain, scene, work = sys.argv[1:4]
    kills = int(sys.argv[4]) if len(sys.argv) > 4 else 8
    rng = random.Random(20261202)
    subprocess.run(["rm", "-rf", work], check=True)
    out = os.path.join(work, "out")
    os.makedirs(work)
    os.chdir(work)

    def start(log):
        checkpoints = sorted(n for n in os.listdir(out) if CHECKPOINT.match(n)) \
            if os.path.isdir(out) else []
        cmd = [grain, "run", scene, "--output", "out", "--no-progress"]
        if checkpoints:
            cmd += ["--restart", os.path.join("out", checkpoints[-1])]
        RUNNING[:] = [subprocess.Popen(cmd, stdout=open(log, "w"), stderr=subprocess.STDOUT)]
        return RUNNING[0], checkpoints[-1] if checkpoints else None

    index = os.path.join(out, "particles.xdmf")

    def index_version():
        try:
            st = os.stat(index)
            return (st.st_ino, st.st_mtime_ns, st.st_size)
        except FileNotFoundError:
            return None

    def wait_for_new_index(proc, log, before):
        """Waits until this run has written the index (a restart rewrites it whole)."""
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            now = index_version()
            if now is not None and now != before:
                return
            if proc.poll() is not None:
                fail(f"grain exited with code {proc.returncode} on its own", log)
            time.sleep(0.002)
        fail("no index within 60 s", log)

    listed = []
    started = time.monotonic()
    for kill in range(1, kills + 1):
        log = f"run_{kill:02d}.txt"
        before = index_version()
        proc, restart = start(log)
        wait_for_new_index(proc, log, before)
        time.sleep(rng.uniform(0.0, 0.3))
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        if proc.returncode != -signal.SIGKILL:
            fail(f"kill {kill}: grain ended with {proc.returncode} before the SIGKILL", log)
        n = check_index(out, f"after kill {kill}")
        listed.append(n)
        print(f"kill {kill:2d} ({'restart from ' + restart if restart else 'fresh start'}): "
              f"index parses, lists {n} snapshots, each opens with the listed time and shapes")

    log = "run_last.txt"
    before = index_version()
    proc, restart = start(log)
    if not restart:
        fail("no checkpoint was written before the last restart", log)
    # Runs on until its index has been rewritten and appended to, then stops cleanly.
    wait_for_new_index(proc, log, before)
    time.sleep(0.3)
    proc.send_signal(signal.SIGTERM)
    code = proc.wait(timeout=60)
    if code != 0:
        fail(f"the last restart did not stop cleanly on SIGTERM (exit {code})", log)
    n = check_index(out, "after the SIGTERM")
    restart_step = int(CHECKPOINT.match(os.path.basename(restart)).group(1))
    if n < restart_step // 10 + 1:
        fail(f"the restart from step {restart_step} lists only {n} snapshots")
    print(f"{kills} kills in {time.monotonic() - started:.1f} s (index sizes {listed}); the "
          f"restart from {restart} stopped on SIGTERM with {n} snapshots listed")
    print("PASS")


if __name__ == "__main__":
    main()
