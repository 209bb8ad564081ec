#!/usr/bin/env python3
"""kill -9 during checkpoint writes, repeatedly (docs/reliability.md, issue 9).

    kill_during_checkpoint.py GRAIN SCENE WORKDIR [KILLS]

Runs `grain run SCENE` (20 000 particles, a 3 MB checkpoint every 10 steps, the newest 2
kept) and kills it with SIGKILL KILLS times, restarting each time from the newest complete
checkpoint. Most kills are sent the moment the kernel reports (inotify) that a
`checkpoint_*.h5.part` file was created, i.e. while rank 0 is writing it; every fourth is
sent after a random delay instead, landing anywhere (start-up, steps, log or checkpoint
writes). After each kill:
  - every `checkpoint_<9 digits>.h5` in the directory opens with h5py and holds all
    20 000 particles, once each (ids 1 .. 20 000), with its step in its name;
  - at least one complete checkpoint exists (the first one was written before the first
    kill);
  - the restart from the newest one runs: it must delete the stale `.part` the kill left
    (inotify IN_DELETE before its first checkpoint) and go on to write new checkpoints,
    and it must never take a `.part` as a checkpoint (`--restart X.part` is refused).
A kill "hit a write in progress" when the `.part` file still exists after the process died:
only the writer itself renames or deletes it. At least MIN_HITS kills must hit. The last
restart is stopped with SIGTERM and must exit 0 with a checkpoint.
"""
import ctypes
import ctypes.util
import os
import random
import re
import select
import signal
import struct
import subprocess
import sys
import time

import h5py
import numpy as np

MIN_HITS = 5
PARTICLES = 20000
IN_CREATE, IN_DELETE, IN_MOVED_TO = 0x100, 0x200, 0x80
CHECKPOINT = re.compile(r"^checkpoint_(\d{9})\.h5$")
PARTIAL = re.compile(r"^checkpoint_(\d{9})\.h5\.part$")


class Inotify:
    """The kernel's file events in one directory (Linux inotify through ctypes)."""

    def __init__(self, directory):
        libc = ctypes.CDLL(ctypes.util.find_library("c"), use_errno=True)
        self.fd = libc.inotify_init1(os.O_CLOEXEC)
        if self.fd < 0 or libc.inotify_add_watch(
                self.fd, directory.encode(), IN_CREATE | IN_DELETE | IN_MOVED_TO) < 0:
            raise OSError(ctypes.get_errno(), "inotify")
        self.pending = []

    def next(self, timeout):
        """The next (mask, name), or None after `timeout` seconds."""
        if not self.pending:
            if not select.select([self.fd], [], [], timeout)[0]:
                return None
            data = os.read(self.fd, 65536)
            at = 0
            while at < len(data):
                _, mask, _, length = struct.unpack_from("iIII", data, at)
                name = data[at + 16:at + 16 + length].rstrip(b"\0").decode()
                self.pending.append((mask, name))
                at += 16 + length
        return self.pending.pop(0)


def fail(message, log=None):
    if log and os.path.exists(log):
        sys.stdout.write(open(log).read())
    print("FAIL: " + message)
    sys.exit(1)


def complete_checkpoints(out):
    return sorted(n for n in os.listdir(out) if CHECKPOINT.match(n))


def check_checkpoints(out, kill):
    """Every complete checkpoint reads back whole; returns their names."""
    names = complete_checkpoints(out)
    for name in names:
        path = os.path.join(out, name)
        try:
            with h5py.File(path, "r") as f:
                ids = f["particles/id"][()]
                positions = f["particles/position"][()]
                step = int(f.attrs["step"])
                fmt = f.attrs["format"]
        except Exception as e:  # noqa: BLE001 - any failure to read is the finding
            fail(f"after kill {kill}: {path} does not read back: {e}")
        if ids.shape != (PARTICLES,) or positions.shape != (PARTICLES, 3):
            fail(f"after kill {kill}: {path} holds {ids.shape[0]} particles, not {PARTICLES}")
        if not np.array_equal(np.sort(ids), np.arange(1, PARTICLES + 1)):
            fail(f"after kill {kill}: {path}: particle ids are not 1 .. {PARTICLES} once each")
        if not np.all(np.isfinite(positions)):
            fail(f"after kill {kill}: {path} holds non-finite positions")
        if step != int(CHECKPOINT.match(name).group(1)) or fmt != b"grainflow-checkpoint-3":
            fail(f"after kill {kill}: {path}: step {step} / format {fmt!r} do not match")
    return names


def main():
    grain, scene, work = sys.argv[1:4]
    kills = int(sys.argv[4]) if len(sys.argv) > 4 else 20
    rng = random.Random(20261123)  # which kill waits for which event: reproducible
    subprocess.run(["rm", "-rf", work], check=True)
    out = os.path.join(work, "out")
    os.makedirs(out)
    os.chdir(work)
    events = Inotify(out)

    def start(restart, log):
        cmd = [grain, "run", scene, "--output", "out", "--no-progress"]
        if restart:
            cmd += ["--restart", restart]
        return subprocess.Popen(cmd, stdout=open(log, "w"), stderr=subprocess.STDOUT)

    def wait_event(proc, log, wanted, timeout=30):
        """Waits for an event accepted by `wanted(mask, name)`; fails if grain exits."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            event = events.next(0.05)
            if event and wanted(*event):
                return event
            if event is None and proc.poll() is not None:
                fail(f"grain exited with code {proc.returncode} on its own", log)
        fail(f"no expected file event within {timeout} s", log)

    # The first run: its first checkpoint is complete before the first kill.
    log = "run_00.txt"
    proc = start(None, log)
    wait_event(proc, log, lambda m, n: m & IN_MOVED_TO and CHECKPOINT.match(n))
    write_times = []
    hits = 0
    stale = None  # the .part a kill left behind, which the next restart must delete
    started = time.monotonic()
    for kill in range(1, kills + 1):
        at_random = kill % 4 == 0
        if at_random:
            time.sleep(rng.uniform(0.0, 0.6))
        else:
            # Kill on the n-th new .part (n = 1..3), so that the run advances between kills;
            # the writes let through are timed from creation to rename.
            n = rng.randint(1, 3)
            for k in range(n):
                _, part = wait_event(proc, log, lambda m, n: m & IN_CREATE and PARTIAL.match(n))
                if k < n - 1:
                    created = time.monotonic()
                    wait_event(proc, log, lambda m, n: m & IN_MOVED_TO and n == part[:-5])
                    write_times.append(time.monotonic() - created)
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        if proc.returncode != -signal.SIGKILL:
            fail(f"kill {kill}: grain ended with {proc.returncode} before the SIGKILL", log)
        partial = sorted(n for n in os.listdir(out) if PARTIAL.match(n))
        hit = bool(partial)
        hits += hit
        names = check_checkpoints(out, kill)
        if not names:
            fail(f"after kill {kill}: no complete checkpoint left")
        print(f"kill {kill:2d} ({'random delay' if at_random else 'on .part creation'}): "
              f"{'hit a write in progress (' + partial[0] + ' left)' if hit else 'no write in progress'}; "
              f"complete: {', '.join(names)}")
        if hit and kill == 1:
            # A .part is never a checkpoint: grain refuses to restart from it.
            refused = subprocess.run([grain, "run", scene, "--output", "out", "--no-progress",
                                      "--restart", os.path.join("out", partial[0])],
                                     capture_output=True, text=True)
            if refused.returncode != 1 or "a .part file is a checkpoint that was being written" \
                    not in refused.stderr:
                fail(f"--restart {partial[0]}: exit {refused.returncode}, "
                     f"{refused.stdout + refused.stderr}")
            print(f"--restart {partial[0]} refused: {refused.stderr.strip()}")
        stale = partial[0] if hit else None
        # Restart from the newest complete checkpoint; it is the next kill's target.
        log = f"run_{kill:02d}.txt"
        events.pending.clear()
        while events.next(0) is not None:
            pass
        proc = start(os.path.join("out", names[-1]), log)
        if stale:
            seen = wait_event(proc, log, lambda m, n: (m & IN_DELETE and n == stale) or
                              (m & IN_CREATE and PARTIAL.match(n)))
            if not seen[0] & IN_DELETE:
                fail(f"the restart after kill {kill} did not delete the stale {stale} first", log)
    # The last restart must run on: it writes a new checkpoint, then SIGTERM stops it cleanly.
    wait_event(proc, log, lambda m, n: m & IN_MOVED_TO and CHECKPOINT.match(n))
    proc.send_signal(signal.SIGTERM)
    code = proc.wait(timeout=30)
    text = open(log).read()
    if code != 0 or "wrote the checkpoint" not in text:
        fail(f"the last restart did not stop cleanly on SIGTERM (exit {code})", log)
    check_checkpoints(out, "the SIGTERM")
    leftovers = [n for n in os.listdir(out) if n.endswith(".part")]
    if leftovers:
        fail(f"partial files left after a clean stop: {leftovers}")
    elapsed = time.monotonic() - started
    if write_times:
        print(f"checkpoint writes let through: {len(write_times)}, creation to rename "
              f"median {1e3 * float(np.median(write_times)):.1f} ms, "
              f"min {1e3 * min(write_times):.1f} ms")
    print(f"{kills} kills in {elapsed:.1f} s, {hits} hit a checkpoint write in progress "
          f"(required: {MIN_HITS}); every checkpoint left read back with all {PARTICLES} "
          f"particles; the last restart stopped cleanly on SIGTERM")
    if hits < MIN_HITS:
        fail(f"only {hits} kills hit a checkpoint write (at least {MIN_HITS} required)")
    print("PASS")


if __name__ == "__main__":
    main()
