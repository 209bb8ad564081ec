#!/usr/bin/env python3
"""What a user's files and folders may not silently do (docs/scene-reference.md, "Files").

    user_files.py GRAIN WORKDIR

Each case writes a small scene (50 beads dropped on a floor), runs grain and checks its exit
code, its message and what is on disk afterwards:
  * overwrite_csv: a CSV insertion named log.csv in the output folder '.': refused (exit 1),
    naming the file and the output folder, the CSV unchanged (its bytes);
  * overwrite_snapshot: a snapshot insertion out/particles_000001.h5 with the output in out/:
    refused, unchanged; with --output elsewhere the same scene runs;
  * overwrite_scene: the scene file itself saved as out/log.csv with the output in out/, or
    linked into the output folder as particles.xdmf (symbolic or hard link): refused (exit 1),
    unchanged;
  * hard_linked_backup: a run into a folder whose files are hard-linked into a backup (`cp
    -al`), reading a snapshot from the backup, runs and leaves the backup's bytes (log.csv too);
  * failed_start_writes_nothing: a fill that cannot place its particles (into a/b/out) and a
    refused time step leave no output folder behind (nor x/ of --output x/../y); a folder that
    was there is kept, empty (also one named through a link and '..'), and so is a symbolic
    link to nowhere given as the output folder;
  * signal_during_start: SIGTERM while a fill of 400 000 particles is placed: a message, exit
    143, no folder left;
  * second_document: keys after a '---' line: refused (exit 2) at that line, not dropped;
  * tilde: '~' in output.directory and in --output=~/x: refused (exit 2), no folder '~' made;
  * input_named: `grain check` and `grain run` name each particle file they read with its
    absolute path;
  * help: `grain run --help` and `grain check --help` print the usage, exit 0;
  * restart_mesh: a mesh wall's STL file moved to another folder restarts; its contents
    changed, the restart is refused naming the file (it had run on with the new mesh);
  * restart_other_physics: a restart into a folder of a run with another gravity (same
    insertions) takes over none of its snapshots and keeps its checkpoints;
  * restart_smaller_skin: a restart with a tenth of the run's neighbour skin ends where the
    uninterrupted run does (positions to 1e-12 m across the periodic sides);
  * hostile_text: a CSV and an ASCII STL with a UTF-8 byte-order mark are read; an invisible
    character in a key is named by its code point; merge keys, a 200 000-character value, a
    count of 1e20, a device as the particle file and a folder as the scene get clear errors;
    a 200 000-character model name, number or wall name is shown by its first 60 characters;
  * restart_advice: the summary's "continue with" command, time.end raised, ends bit for bit
    where one longer run ends; a restart into another folder says so; a snapshot given to
    --restart is named as one, by its contents (renamed state.h5 too; a checkpoint copied to
    particles_backup.h5 restarts);
  * restart_output_series: restarts from every periodic checkpoint of 14 scenes whose output
    intervals are odd numbers of half steps write the uninterrupted run's snapshots and log
    rows, at the same steps under the same numbers;
  * restart_lost_snapshots: the last two snapshots before the checkpoint deleted, the one at
    its step truncated, or that one and all later ones deleted: the restart keeps the
    uninterrupted run's numbers and names the gaps;
  * restart_at_end: a restart whose time.end is the checkpoint's time runs nothing and leaves
    log.csv, particles.xdmf and every snapshot as they were (bytes), where it had cut the log
    back to the checkpoint;
  * restart_other_step_setting: a restart whose time.rayleigh_fraction is not its run's, or
    that gives one where the run gave time.step, is refused (run and check) naming the value
    that restarts; followed, it runs;
  * restart_other_domain: a domain changed before a restart is named (domain.max[2]), not
    taken for a damaged checkpoint;
  * check_restart: `grain check --restart` verifies a checkpoint against the scene as the
    restart would: a good one passes with the steps the restart then runs (it runs exactly
    those), a changed gravity and a flipped byte are refused as `run --restart` refuses them,
    and the output folder keeps its bytes (check writes nothing);
  * restart_missing_csv: a CSV insertion's file deleted after the run: a restart runs (with a
    note), a new run and `check` are refused naming the file.
"""
import hashlib
import os
import re
import shutil
import signal
import subprocess
import sys
import time

SCENE = """domain: {{min: [0, 0, 0], max: [0.01, 0.01, 0.02], periodic: [true, true, false]}}
gravity: [0, 0, -9.81]
time: {{rayleigh_fraction: 0.2, end: {end}}}
materials: [{{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.25, density: 2500}}]
interactions: [{{materials: [glass, glass], restitution: 0.5, friction: 0.3}}]
contact: {{normal: hertz, tangential: history}}
walls: [{{type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass}}]
insert:
{insert}
output: {{directory: {directory}, progress: false, snapshot_interval: 0.001{extra}}}
"""
FILL = ("  - {type: fill, region: {box: {min: [0, 0, 0.001], max: [0.01, 0.01, 0.019]}}, "
        "count: 50, material: glass, radius: 4e-4}")
CSV = "x,y,z,radius\n0.005,0.005,0.005,4e-4\n0.005,0.005,0.006,4e-4\n"

failures = []


def fail(case, message):
    failures.append(f"{case}: {message}")
    print(f"FAIL {case}: {message}")


def scene(folder, name="scene.yaml", insert=FILL, directory="out", end=0.004, extra=""):
    text = SCENE.format(insert=insert, directory=directory, end=end, extra=extra)
    with open(os.path.join(folder, name), "w") as out:
        out.write(text)
    return text


def grain(folder, *args):
    p = subprocess.run([GRAIN, *args], cwd=folder, capture_output=True, text=True, timeout=120)
    return p.returncode, p.stdout + p.stderr


def digest(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def first_checkpoint(d, out="out"):
    """The first checkpoint the run in folder d wrote into `out`, as a path relative to d."""
    return os.path.join(out, sorted(n for n in os.listdir(os.path.join(d, out))
                                    if n.startswith("checkpoint_"))[0])


def fresh(case):
    folder = os.path.join(WORK, case)
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    return folder


def expect(case, got, code, pattern):
    rc, out = got
    if rc != code or not re.search(pattern, out):
        fail(case, f"exit {rc} (expected {code}), output does not match {pattern!r}:\n{out}")


def overwrite_csv():
    case = "overwrite_csv"
    d = fresh(case)
    with open(os.path.join(d, "log.csv"), "w") as out:
        out.write(CSV)
    scene(d, insert="  - {type: csv, file: log.csv, material: glass}", directory='"."')
    before = digest(os.path.join(d, "log.csv"))
    for command in (["run", "scene.yaml"], ["check", "scene.yaml"]):
        expect(case, grain(d, *command), 1,
               r"scene\.yaml:9: error: the CSV file 'log\.csv' is in the output folder '\.' under "
               r"a name the run writes there: the run would overwrite it")
    if digest(os.path.join(d, "log.csv")) != before:
        fail(case, "the CSV was changed")


def overwrite_snapshot():
    case = "overwrite_snapshot"
    d = fresh(case)
    scene(d, name="stage1.yaml")
    expect(case, grain(d, "run", "stage1.yaml"), 0, r"done:")
    scene(d, insert="  - {type: snapshot, file: out/particles_000001.h5}")
    before = digest(os.path.join(d, "out", "particles_000001.h5"))
    expect(case, grain(d, "run", "scene.yaml"), 1,
           r"scene\.yaml:9: error: the snapshot file 'out/particles_000001\.h5' is in the output "
           r"folder 'out' under a name the run writes there")
    if digest(os.path.join(d, "out", "particles_000001.h5")) != before:
        fail(case, "the snapshot was changed")
    expect(case, grain(d, "run", "scene.yaml", "--output", "stage2"), 0, r"done:")


def overwrite_scene():
    """The scene file itself under a name the run writes, in its output folder."""
    case = "overwrite_scene"
    d = fresh(case)
    os.makedirs(os.path.join(d, "out"))
    scene(d, name=os.path.join("out", "log.csv"))
    before = digest(os.path.join(d, "out", "log.csv"))
    for command in (["run", "out/log.csv"], ["check", "out/log.csv"]):
        expect(case, grain(d, *command), 1,
               r"out/log\.csv: error: the scene file 'out/log\.csv' is in the output folder "
               r"'out' under a name the run writes there: the run would overwrite it\. Move or "
               r"copy it out of that folder under another name")
    if digest(os.path.join(d, "out", "log.csv")) != before:
        fail(case, "the scene file was changed")
    if sorted(os.listdir(os.path.join(d, "out"))) != ["log.csv"]:
        fail(case, f"out/ holds {sorted(os.listdir(os.path.join(d, 'out')))}")
    # Linked into the folder under such a name: a symbolic link (run as the link or as its
    # target) and a hard link would be written through.
    scene(d, name="keep.yaml")
    before = digest(os.path.join(d, "keep.yaml"))
    for link, kind in (("sym", "symbolic"), ("hard", "hard")):
        os.makedirs(os.path.join(d, link))
        target = os.path.join(d, link, "particles.xdmf")
        if kind == "symbolic":
            os.symlink(os.path.join("..", "keep.yaml"), target)
        else:
            os.link(os.path.join(d, "keep.yaml"), target)
        expect(case, grain(d, "run", "keep.yaml", "--output", link), 1,
               rf"keep\.yaml: error: the scene file 'keep\.yaml' is linked as '.*{link}/particles"
               rf"\.xdmf' in the output folder '{link}' under a name the run writes there")
        if kind == "symbolic":
            expect(case, grain(d, "run", f"{link}/particles.xdmf", "--output", link), 1,
                   rf"the scene file '{link}/particles\.xdmf' is a link in the output folder")
        os.remove(target)  # the advice: remove that link
        expect(case, grain(d, "run", "keep.yaml", "--output", link), 0, r"done:")
    if digest(os.path.join(d, "keep.yaml")) != before:
        fail(case, "the linked scene file was written over")


def failed_start_writes_nothing():
    """A start that fails (a fill that cannot place its particles, a refused time step)
    leaves no output folder behind, nested ones included; a folder that was there is kept."""
    case = "failed_start_writes_nothing"
    d = fresh(case)
    crowded = FILL.replace("count: 50", "count: 2500")
    scene(d, insert=crowded, directory="a/b/out")
    expect(case, grain(d, "run", "scene.yaml"), 2, r"error: could place only \d+ particles")
    if os.path.exists(os.path.join(d, "a")):
        fail(case, "the failed fill left the folder a/ (or a/b/out) behind")
    text = scene(d).replace("rayleigh_fraction: 0.2", "step: 1e-3")
    with open(os.path.join(d, "scene.yaml"), "w") as out:
        out.write(text)
    expect(case, grain(d, "run", "scene.yaml"), 1, r"refusing to run with this time step")
    if os.path.exists(os.path.join(d, "out")):
        fail(case, "the refused time step left out/ behind")
    os.makedirs(os.path.join(d, "out"))
    expect(case, grain(d, "run", "scene.yaml"), 1, r"refusing to run with this time step")
    if not os.path.isdir(os.path.join(d, "out")) or os.listdir(os.path.join(d, "out")):
        fail(case, "the folder that was there before was removed or written to")
    # A path through a folder that is not there: "x/../y" makes x too, which goes again;
    # "x/../out" names the folder that was there, which stays.
    for given in ("x/../y", "x/../out"):
        expect(case, grain(d, "run", "scene.yaml", "--output", given), 1,
               r"refusing to run with this time step")
        if os.path.exists(os.path.join(d, "x")) or os.path.exists(os.path.join(d, "y")):
            fail(case, f"--output {given}: the failed start left x/ or y/ behind")
        if not os.path.isdir(os.path.join(d, "out")):
            fail(case, f"--output {given}: the folder out/ that was there was removed")
    # Through a symbolic link and up again: L/b/../../c names other/c once L/b is made, a
    # folder the user had (empty); only L/b, made by the run, goes.
    os.makedirs(os.path.join(d, "other", "a2"))
    os.makedirs(os.path.join(d, "other", "c"))
    os.symlink(os.path.join(d, "other", "a2"), os.path.join(d, "L"))
    expect(case, grain(d, "run", "scene.yaml", "--output", "L/b/../../c"), 1,
           r"refusing to run with this time step")
    if not os.path.isdir(os.path.join(d, "other", "c")):
        fail(case, "--output L/b/../../c: the failed start removed the user's folder other/c")
    if os.path.exists(os.path.join(d, "other", "a2", "b")):
        fail(case, "--output L/b/../../c: the failed start left L/b behind")
    # A symbolic link to a folder that does not exist is the user's: kept.
    os.symlink(os.path.join(d, "nowhere"), os.path.join(d, "results"))
    expect(case, grain(d, "run", "scene.yaml", "--output", "results"), 1,
           r"output directory 'results': is a symbolic link to '.*nowhere': that folder does "
           r"not exist")
    if not os.path.islink(os.path.join(d, "results")):
        fail(case, "the failed start removed the user's symbolic link 'results'")
    scene(d)  # a scene that starts, into the link once its folder exists (the advice)
    os.makedirs(os.path.join(d, "nowhere"))
    expect(case, grain(d, "run", "scene.yaml", "--output", "results"), 0, r"done:")
    if not os.path.isfile(os.path.join(d, "nowhere", "log.csv")):
        fail(case, "the run through the link did not write into its folder")


def signal_during_start():
    """SIGTERM while a large fill places its particles (before the first step, where the run
    loop would write a checkpoint): a message, exit 143, and no folder left behind."""
    case = "signal_during_start"
    d = fresh(case)
    big = FILL.replace("count: 50", "count: 400000").replace("[0.01, 0.01, 0.019]",
                                                             "[0.1, 0.1, 0.19]")
    text = scene(d, insert=big, directory="a/b/out").replace("[0.01, 0.01, 0.02]",
                                                             "[0.1, 0.1, 0.2]")
    with open(os.path.join(d, "scene.yaml"), "w") as out:
        out.write(text)
    p = subprocess.Popen([GRAIN, "run", "scene.yaml"], cwd=d, stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, text=True)
    lock = os.path.join(d, "a", "b", "out", ".grain.lock")
    for _ in range(600):  # the lock is taken just before the particles are placed
        if os.path.exists(lock) or p.poll() is not None:
            break
        time.sleep(0.01)
    p.send_signal(signal.SIGTERM)
    out, _ = p.communicate(timeout=120)
    expect(case, (p.returncode, out), 143,
           r"grain: received SIGTERM during start-up \(placing the particles, preparing the first "
           r"step\); stopped before "
           r"the first step: nothing was run, no checkpoint or snapshot was written")
    if os.path.exists(os.path.join(d, "a")):
        fail(case, f"the stopped start left a/ behind: {sorted(os.listdir(os.path.join(d, 'a')))}")


def restart_output_series():
    """A restart writes the snapshots and log rows of the uninterrupted run, at the same steps
    and under the same numbers, also when its checkpoint sits half a step before an output
    target (an interval of an odd number of half steps): random intervals of 3 to 13 half
    steps, restarted from every periodic checkpoint. Those ties had skipped or repeated a
    snapshot and a log row (e.g. dt = 3e-4 s, interval 1.05e-3 s, checkpoint at step 10)."""
    import random
    import h5py
    case = "restart_output_series"
    d = fresh(case)
    with open(os.path.join(d, "p.csv"), "w") as out:
        out.write("x,y,z,radius,vx,vy,vz\n0.5,0.5,0.5,0.001,0.3,0,0.2\n")

    def series(folder):
        steps = []
        for name in sorted(os.listdir(folder)):
            if name.startswith("particles_") and name.endswith(".h5"):
                with h5py.File(os.path.join(folder, name), "r") as f:
                    steps.append((name, int(f.attrs["step"]), float(f.attrs["time"])))
        with open(os.path.join(folder, "log.csv")) as f:
            rows = [line.split(",")[1] for line in f.read().split()[1:]]
        return steps, rows

    # Values as a user types them (decimal, 6 digits): (step, output interval, checkpoint
    # interval, end). The first two are the ties found first.
    combos = [("3e-4", "0.00105", "0.003", "0.01"), ("3e-4", "0.00165", "0.0048", "0.012")]
    rng = random.Random(7)
    while len(combos) < 14:
        dt = rng.choice([3e-4, 1e-3, 7e-5, 1.1e-4, 2.5e-4, 3.3e-5])
        combos.append((f"{dt:.6g}", f"{dt * rng.randrange(3, 14, 2) / 2:.6g}",
                       f"{dt * rng.randrange(5, 30):.6g}", f"{dt * rng.randrange(40, 80):.6g}"))
    checked = 0
    for n, (dt, every, check, end) in enumerate(combos):
        text = (f"domain: {{min: [-100, -100, -100], max: [100, 100, 100]}}\n"
                f"gravity: [0, 0, -9.81]\ntime: {{step: {dt}, end: {end}}}\n"
                f"materials: [{{name: glass, density: 2500}}]\n"
                f"insert: [{{type: csv, file: p.csv, material: glass}}]\n"
                f"output: {{progress: false, snapshot_interval: {every}, log_interval: {every}, "
                f"checkpoint_interval: {check}, checkpoint_keep: 1000}}\n")
        with open(os.path.join(d, f"s{n}.yaml"), "w") as out:
            out.write(text)
        full = f"full{n}"
        expect(case, grain(d, "run", f"s{n}.yaml", "--output", full), 0, r"done:")
        want = series(os.path.join(d, full))
        for name in sorted(os.listdir(os.path.join(d, full))):
            if not name.startswith("checkpoint_"):
                continue
            again = f"again{n}_{name[11:20]}"
            shutil.copytree(os.path.join(d, full), os.path.join(d, again))
            expect(case, grain(d, "run", f"s{n}.yaml", "--output", again, "--restart",
                               f"{again}/{name}"), 0, r"done:")
            got = series(os.path.join(d, again))
            checked += 1
            if got != want:
                fail(case, f"dt {dt}, interval {every} s, restart from {name}: snapshots "
                           f"{[g[1] for g in got[0]]} and log steps {got[1]}, the uninterrupted "
                           f"run's {[w[1] for w in want[0]]} and {want[1]}")
    print(f"ok {case}: {checked} restarts from {len(combos)} scenes, each the uninterrupted series")


def restart_lost_snapshots():
    """Snapshots lost before a restart's checkpoint (the last two deleted, or the one at the
    checkpoint's own step truncated): the restart writes its snapshots under the uninterrupted
    run's numbers, with the lost ones named as gaps (particles.xdmf dates them). They had been
    numbered over, shifting every later file by the count lost."""
    import h5py
    case = "restart_lost_snapshots"
    d = fresh(case)
    scene(d, end=0.012, extra=", checkpoint_interval: 0.006, checkpoint_keep: 10")
    with open(os.path.join(d, "scene.yaml")) as f:
        text = f.read().replace("snapshot_interval: 0.001", "snapshot_interval: 0.002")
    with open(os.path.join(d, "scene.yaml"), "w") as f:
        f.write(text)
    expect(case, grain(d, "run", "scene.yaml"), 0, r"done:")

    def series(folder):
        out = {}
        for name in sorted(os.listdir(os.path.join(d, folder))):
            if name.startswith("particles_") and name.endswith(".h5"):
                try:
                    with h5py.File(os.path.join(d, folder, name), "r") as f:
                        out[name] = round(float(f.attrs["time"]), 9)
                except OSError:
                    out[name] = None
        return out

    want = series("out")
    checkpoint = sorted(n for n in os.listdir(os.path.join(d, "out")) if n.startswith("checkpoint_"))[0]
    with h5py.File(os.path.join(d, "out", checkpoint), "r") as f:
        t_check = float(f.attrs["time"])
    before = sorted(n for n, t in want.items() if t <= t_check + 1e-9)
    assert len(before) >= 3, before
    # The last two before the checkpoint deleted; the one at its step truncated; that one and
    # every later file deleted (no file after it is left to show the gap: the index does).
    after = sorted(n for n in want if n not in before)
    lost = {"deleted": before[-2:], "truncated": before[-1:],
            "deleted_to_the_end": before[-1:] + after}
    for how, names in lost.items():
        folder = f"out_{how}"
        shutil.copytree(os.path.join(d, "out"), os.path.join(d, folder))
        for name in names:
            path = os.path.join(d, folder, name)
            if how.startswith("deleted"):
                os.remove(path)
            else:
                os.truncate(path, 1000)
        rc, out = grain(d, "run", "scene.yaml", "--output", folder, "--restart",
                        f"{folder}/{checkpoint}")
        expect(case, (rc, out), 0, r"done:")
        for name in names:
            if name in after:  # the stopped run's, after the checkpoint: written again
                continue
            if not re.search(rf"note: {folder}/{name} \((missing|unreadable)\) is a gap", out):
                fail(case, f"{how}: no note names {name} as a gap:\n{out}")
        got = series(folder)
        for name, t in want.items():
            if name in names and name not in after:
                continue
            if got.get(name) != t:
                fail(case, f"{how} {names}: {name} holds t = {got.get(name)}, the uninterrupted "
                           f"run's holds {t}")


def hard_linked_backup():
    """A backup of an output folder made of hard links (`cp -al out backup`): a new run into
    the folder, reading a snapshot from the backup, runs (snapshots and checkpoints are renamed
    into place, which replaces a link) and leaves every backup file as it was, log.csv too."""
    case = "hard_linked_backup"
    d = fresh(case)
    scene(d, name="stage1.yaml", extra=", checkpoint_interval: 0.002")
    expect(case, grain(d, "run", "stage1.yaml"), 0, r"done:")
    os.makedirs(os.path.join(d, "backup"))
    for name in os.listdir(os.path.join(d, "out")):
        if not name.startswith("."):
            os.link(os.path.join(d, "out", name), os.path.join(d, "backup", name))
    before = {n: digest(os.path.join(d, "backup", n)) for n in os.listdir(os.path.join(d, "backup"))}
    scene(d, insert="  - {type: snapshot, file: backup/particles_000001.h5}", end=0.003)
    expect(case, grain(d, "run", "scene.yaml"), 0, r"done:")
    after = {n: digest(os.path.join(d, "backup", n)) for n in os.listdir(os.path.join(d, "backup"))}
    if after != before:
        fail(case, "backup files changed: "
             + str(sorted(n for n in before if before[n] != after.get(n))))


def second_document():
    case = "second_document"
    d = fresh(case)
    text = scene(d)
    with open(os.path.join(d, "scene.yaml"), "w") as out:
        out.write(text.replace("gravity:", "---\ngravity:"))
    expect(case, grain(d, "check", "scene.yaml"), 2,
           r"scene\.yaml:2:1: error: a second YAML document starts here \(a '---' line after")
    # A document-end marker '...' before keys: yaml-cpp read the scene up to it and dropped
    # the rest (output.directory after it was not used, without a word).
    with open(os.path.join(d, "scene.yaml"), "w") as out:
        out.write(text.replace("gravity:", "...\ngravity:"))
    expect(case, grain(d, "check", "scene.yaml"), 2,
           r"scene\.yaml:2:1: error: the YAML document ends here \(a '\.\.\.' line\), and the "
           r"keys after it, from line 3, would not be read")
    # At the end, with only comments after it, it ends the scene as YAML allows.
    with open(os.path.join(d, "scene.yaml"), "w") as out:
        out.write(text + "...\n# the end\n")
    expect(case, grain(d, "check", "scene.yaml"), 0, r"")


def coupled_checkpoint():
    """`grain run --restart` of a checkpoint grainFoam wrote (a time folder of the case names it
    in uniform/grainflowCheckpoint): refused, saying to restart with grainFoam. Followed, as
    h5_summary.py once advised for a damaged index, it ran the coupled scene without its fluid
    and wrote hundreds of DEM-only snapshots over the case's. A DEM run's checkpoint kept in a
    grainFoam case (a pour before the fluid), which no time folder names, restarts."""
    case = "coupled_checkpoint"
    d = fresh(case)
    scene(d, extra=", checkpoint_interval: 0.002")
    expect(case, grain(d, "run", "scene.yaml"), 0, r"done:")
    for sub, name in (("system", "controlDict"), ("constant", "couplingProperties")):
        os.makedirs(os.path.join(d, sub), exist_ok=True)
        with open(os.path.join(d, sub, name), "w") as f:
            f.write("// a grainFoam case\n")
    checkpoint = first_checkpoint(d)
    # The pour: no time folder names the checkpoint.
    expect(case, grain(d, "run", "scene.yaml", "--restart", checkpoint), 0, r"done:")
    os.makedirs(os.path.join(d, "0.002", "uniform"))
    with open(os.path.join(d, "0.002", "uniform", "grainflowCheckpoint"), "w") as f:
        f.write(f"checkpoint      {os.path.basename(checkpoint)};\n")
    before = sorted(os.listdir(os.path.join(d, "out")))
    expect(case, grain(d, "run", "scene.yaml", "--restart", checkpoint), 2,
           r"--restart \S+ is a checkpoint grainFoam wrote in the case \S+ \(a time folder's "
           r"uniform/grainflowCheckpoint names it\): restart it with grainFoam")
    if sorted(os.listdir(os.path.join(d, "out"))) != before:
        fail(case, "the refused restart changed the output folder")


def end_beyond_count():
    """time.end of 1e14 s at a step of about 3.5e-6 s is 2.9e19 steps, beyond what a run
    counts: it had wrapped to one step, which `grain check` called "the nearest whole number"
    and `grain run` ran, exit 0. Refused at time.end with the largest end; that end, typed
    back, is taken (check prints its step count)."""
    case = "end_beyond_count"
    d = fresh(case)
    scene(d, end="1e14")
    for command in ("check", "run"):
        expect(case, grain(d, command, "scene.yaml"), 1,
               r"scene\.yaml:3: error: time\.end 1e\+14 s is \S+ steps of dt = \S+ s "
               r"\(scene\.yaml:3\), more than the 9e15 steps a run can count; give a time\.end "
               r"of at most \S+ s")
    if os.path.exists(os.path.join(d, "out")):
        fail(case, "the refused run made its output folder")
    rc, out = grain(d, "check", "scene.yaml")
    most = re.search(r"of at most (\S+) s", out)
    if most:
        scene(d, end=most.group(1))
        rc, out = grain(d, "check", "scene.yaml")
        steps = re.search(r"steps to reach t_end = \S+ s: (\d+)", out)
        if rc != 0 or not steps or not 1e15 < int(steps.group(1)) <= 9e15:
            fail(case, f"the advised end {most.group(1)}: exit {rc}, {out[-400:]}")


def tilde():
    case = "tilde"
    d = fresh(case)
    scene(d, directory='"~/results"')
    expect(case, grain(d, "check", "scene.yaml"), 2,
           r"scene\.yaml:10:\d+: error: output\.directory: '~' is not expanded in a scene file")
    scene(d)
    expect(case, grain(d, "run", "scene.yaml", "--output=~/results"), 2,
           r"option '--output': '~' in '~/results' is not expanded")
    if os.path.exists(os.path.join(d, "~")):
        fail(case, "a folder named '~' was made")


def input_named():
    case = "input_named"
    d = fresh(case)
    os.makedirs(os.path.join(d, "case"))
    with open(os.path.join(d, "case", "beads.csv"), "w") as out:
        out.write(CSV)
    scene(os.path.join(d, "case"), insert="  - {type: csv, file: beads.csv, material: glass}")
    path = re.escape(os.path.join(os.path.realpath(d), "case", "beads.csv"))
    for command in ("check", "run"):  # from the folder above the scene's
        expect(case, grain(d, command, "case/scene.yaml"), 0,
               r"input: case/scene\.yaml:9 reads " + path + r" \(modified \d{4}-\d\d-\d\d ")


def help_option():
    case = "help"
    d = fresh(case)
    for command in ("run", "check"):
        expect(case, grain(d, command, "--help"), 0, r"^usage: grain <command>")


def restart_at_end():
    case = "restart_at_end"
    d = fresh(case)
    scene(d, end=0.004, extra=", checkpoint_interval: 0.002")
    expect(case, grain(d, "run", "scene.yaml"), 0, r"done:")
    out = os.path.join(d, "out")
    checkpoints = sorted(n for n in os.listdir(out) if n.startswith("checkpoint_"))
    if not checkpoints:
        fail(case, "no checkpoint written")
        return
    first = os.path.join("out", checkpoints[0])
    files = sorted(n for n in os.listdir(out) if not n.startswith("."))
    before = {n: digest(os.path.join(out, n)) for n in files}
    # The checkpoint's time as the new end: its step is the nearest whole number of steps.
    import h5py
    with h5py.File(os.path.join(d, first), "r") as f:
        t = float(f.attrs["time"])
    scene(d, end=repr(t), extra=", checkpoint_interval: 0.002")
    expect(case, grain(d, "run", "scene.yaml", "--restart", first), 0,
           r"nothing to run, nothing in out changed")
    after = {n: digest(os.path.join(out, n)) for n in sorted(os.listdir(out))
             if not n.startswith(".")}
    if after != before:
        changed = sorted(n for n in set(before) | set(after) if before.get(n) != after.get(n))
        fail(case, f"files changed: {changed}")


def run_then_change(case, old, new):
    """A run with a checkpoint in folder `case`; then its scene, 2 ms longer, with `old`
    replaced by `new`. Returns the folder, the first checkpoint and the unchanged text."""
    d = fresh(case)
    scene(d, end=0.004, extra=", checkpoint_interval: 0.002")
    expect(case, grain(d, "run", "scene.yaml"), 0, r"done:")
    first = first_checkpoint(d)
    text = scene(d, end=0.006, extra=", checkpoint_interval: 0.002")
    with open(os.path.join(d, "scene.yaml"), "w") as out:
        out.write(text.replace(old, new))
    return d, first, text


def restart_other_step_setting():
    """A restart keeps its run's step: a scene whose time.rayleigh_fraction differs from the
    run's, or that gives one where the run gave time.step, is refused by run and check with
    the value that restarts; followed, the restart runs."""
    case = "restart_other_step_setting"
    d, first, text = run_then_change(case, "rayleigh_fraction: 0.2", "rayleigh_fraction: 0.1")
    for command in ("run", "check"):
        expect(case, grain(d, command, "scene.yaml", "--restart", first), 1,
               r"scene\.yaml:3: error: time\.rayleigh_fraction = 0\.1, but checkpoint "
               r"'out/checkpoint_\d+\.h5' was written by a run with time\.rayleigh_fraction = "
               r"0\.2 .*set time\.rayleigh_fraction to 0\.2 to restart")
    # A damaged attribute is named as damage, not offered as the value to set.
    import h5py
    damaged = os.path.join(d, "damaged.h5")
    shutil.copy(os.path.join(d, first), damaged)
    with h5py.File(damaged, "r+") as f:
        f.attrs["rayleigh_fraction"] = 0.1
    expect(case, grain(d, "run", "scene.yaml", "--output", "x", "--restart", "damaged.h5"), 1,
           r"root group's attributes \(.*rayleigh_fraction\) do not match their checksum")
    with open(os.path.join(d, "scene.yaml"), "w") as out:
        out.write(text)  # the advice: the run's 0.2
    expect(case, grain(d, "run", "scene.yaml", "--restart", first), 0, r"done:")
    # A run with time.step, restarted with a fraction: refused, naming the step.
    d = fresh(case + "_step")
    text = scene(d, end=0.004, extra=", checkpoint_interval: 0.002")
    with open(os.path.join(d, "scene.yaml"), "w") as out:
        out.write(text.replace("rayleigh_fraction: 0.2", "step: 2e-6"))
    expect(case, grain(d, "run", "scene.yaml"), 0, r"done:")
    first = first_checkpoint(d)
    scene(d, end=0.006, extra=", checkpoint_interval: 0.002")
    expect(case, grain(d, "run", "scene.yaml", "--restart", first), 1,
           r"was written by a run with time\.step = 2e-06 s .*set time\.step to 2e-06 to restart")


def restart_other_domain():
    """A domain changed before a restart is named as the key that changed, not as a damaged
    checkpoint (the decomposition's cuts no longer fit it)."""
    case = "restart_other_domain"
    d, first, text = run_then_change(case, "max: [0.01, 0.01, 0.02], periodic",
                                     "max: [0.01, 0.01, 0.03], periodic")
    for command in ("run", "check"):
        got = grain(d, command, "scene.yaml", "--restart", first)
        expect(case, got, 1, r"scene\.yaml:1: error: domain\.max\[2\] is 0\.03 here, 0\.02 in the "
                             r"run that wrote checkpoint .* Restore domain\.max\[2\] to 0\.02")
        if "damaged" in got[1]:
            fail(case, "the message still blames the checkpoint")
    with open(os.path.join(d, "scene.yaml"), "w") as out:
        out.write(text)  # the advice: domain.max[2] restored
    expect(case, grain(d, "run", "scene.yaml", "--restart", first), 0, r"done:")


def check_restart():
    case = "check_restart"
    d = fresh(case)
    scene(d, end=0.004, extra=", checkpoint_interval: 0.002")
    expect(case, grain(d, "run", "scene.yaml"), 0, r"done:")
    out = os.path.join(d, "out")
    checkpoint = first_checkpoint(d)
    before = {n: digest(os.path.join(out, n)) for n in sorted(os.listdir(out))}
    text = scene(d, end=0.006, extra=", checkpoint_interval: 0.002")
    rc, said = grain(d, "check", "scene.yaml", "--restart", checkpoint)
    m = re.search(r"restart: out/checkpoint_\d+\.h5 holds step (\d+) \(t = [^)]*\), 50 particles, "
                  r"and matches the scene; the restart runs (\d+) steps of dt", said)
    if rc != 0 or not m:
        fail(case, f"check --restart: exit {rc}, no 'matches the scene' line:\n{said}")
        return
    steps = int(m.group(1)) + int(m.group(2))
    # A changed model and a damaged checkpoint: refused by check as by run, same message.
    with open(os.path.join(d, "scene.yaml"), "w") as f:
        f.write(text.replace("-9.81", "-5"))
    for command in ("check", "run"):
        expect(case, grain(d, command, "scene.yaml", "--restart", checkpoint), 1,
               r"gravity\[2\] is -5 here, -9\.81 in the run that wrote checkpoint")
    with open(os.path.join(d, "scene.yaml"), "w") as f:
        f.write(text)
    damaged = os.path.join(d, "damaged.h5")
    shutil.copy(os.path.join(d, checkpoint), damaged)
    import h5py
    with h5py.File(damaged, "r") as f:  # one bit of the first position's bytes, on disk
        at = f["particles/position"].id.get_chunk_info(0).byte_offset + 3
    with open(damaged, "r+b") as f:
        f.seek(at)
        byte = f.read(1)[0]
        f.seek(at)
        f.write(bytes([byte ^ 0x10]))
    for command in ("check", "run"):
        args = ["--output", "x"] if command == "run" else []
        expect(case, grain(d, command, "scene.yaml", *args, "--restart", "damaged.h5"), 1,
               r"damaged\.h5[^\n]*(checksum|changed or damaged)")
    after = {n: digest(os.path.join(out, n)) for n in sorted(os.listdir(out))}
    if after != before:
        fail(case, "check --restart changed the output folder: " +
             str(sorted(n for n in set(before) | set(after) if before.get(n) != after.get(n))))
    # The restart it checked runs the steps it said.
    rc, said = grain(d, "run", "scene.yaml", "--restart", checkpoint)
    if rc != 0 or f"done: {steps} steps" not in said:  # done: counts from t = 0
        fail(case, f"the restart after check: exit {rc}, not ending at step {steps}:\n{said}")


def restart_missing_csv():
    """A restart reads no insertion file: the CSV of a `type: csv` insertion, deleted after the
    run, no longer blocks it (a note says so); a new run still needs it."""
    case = "restart_missing_csv"
    d = fresh(case)
    with open(os.path.join(d, "beads.csv"), "w") as out:
        out.write(CSV)
    scene(d, insert="  - {type: csv, file: beads.csv, material: glass}", end=0.004,
          extra=", checkpoint_interval: 0.002")
    expect(case, grain(d, "run", "scene.yaml"), 0, r"done:")
    checkpoint = first_checkpoint(d)
    os.remove(os.path.join(d, "beads.csv"))
    scene(d, insert="  - {type: csv, file: beads.csv, material: glass}", end=0.006,
          extra=", checkpoint_interval: 0.002")
    missing = r"particle file 'beads\.csv' not found"
    expect(case, grain(d, "check", "scene.yaml"), 2, missing)
    expect(case, grain(d, "run", "scene.yaml", "--output", "fresh"), 2, missing)
    note = r"note: scene\.yaml:\d+: the particle file '[^']*beads\.csv' is missing; a restart"
    expect(case, grain(d, "check", "scene.yaml", "--restart", checkpoint), 0, note)
    expect(case, grain(d, "run", "scene.yaml", "--restart", checkpoint), 0, note + r"(.|\n)*done:")


PLATE = """solid plate
facet normal 0 0 1
 outer loop
  vertex -1 -1 0
  vertex 1 -1 0
  vertex 1 1 0
 endloop
endfacet
facet normal 0 0 1
 outer loop
  vertex -1 -1 0
  vertex 1 1 0
  vertex -1 1 0
 endloop
endfacet
endsolid plate
"""


def restart_mesh():
    """A mesh wall is in the model by its file's contents: the same file moved restarts, a
    changed one is refused naming it."""
    case = "restart_mesh"
    d = fresh(case)
    with open(os.path.join(d, "plate.stl"), "w") as out:
        out.write(PLATE)
    text = scene(d, extra=", checkpoint_interval: 0.002")
    wall = "walls: [{type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass}]"
    mesh = ("walls: [{type: mesh, name: floor, file: %s, scale: 0.01, translate: [0.005, 0.005, 0], "
            "material: glass}]")
    with open(os.path.join(d, "scene.yaml"), "w") as out:
        out.write(text.replace(wall, mesh % "plate.stl"))
    expect(case, grain(d, "run", "scene.yaml"), 0, r"done:")
    checkpoint = first_checkpoint(d)
    os.makedirs(os.path.join(d, "meshes"))
    shutil.move(os.path.join(d, "plate.stl"), os.path.join(d, "meshes", "floor.stl"))
    with open(os.path.join(d, "scene.yaml"), "w") as out:
        out.write(text.replace(wall, mesh % "meshes/floor.stl"))
    expect(case, grain(d, "run", "scene.yaml", "--output", "moved", "--restart", checkpoint), 0,
           r"done:")
    with open(os.path.join(d, "meshes", "floor.stl"), "w") as out:
        out.write(PLATE.replace("1 1 0", "0.6 0.6 0"))
    expect(case, grain(d, "run", "scene.yaml", "--output", "changed", "--restart", checkpoint), 1,
           r"scene\.yaml:7: error: the STL file '[^']*meshes/floor\.stl' of walls\[0\] is not the "
           r"one the run that wrote checkpoint '[^']*' read \(fnv1a64 [0-9a-f]{16}, \d+ bytes here, "
           r"fnv1a64 [0-9a-f]{16}, \d+ bytes then\)\. A restart continues that run with its walls")


def restart_other_physics():
    """A restart into a folder holding a run of the same insertions but another gravity takes
    over none of its snapshots and neither adopts nor deletes its checkpoints (it had mixed
    them into its series and deleted them)."""
    case = "restart_other_physics"
    d = fresh(case)
    text = scene(d, extra=", checkpoint_interval: 0.001, checkpoint_keep: 1")
    expect(case, grain(d, "run", "scene.yaml", "--output", "full"), 0, r"done:")
    with open(os.path.join(d, "heavy.yaml"), "w") as out:
        out.write(text.replace("gravity: [0, 0, -9.81]", "gravity: [0, 0, -50]"))
    expect(case, grain(d, "run", "heavy.yaml", "--output", "heavy"), 0, r"done:")
    theirs = sorted(n for n in os.listdir(os.path.join(d, "heavy")) if n.startswith("checkpoint_"))
    first = os.path.join("full", sorted(n for n in os.listdir(os.path.join(d, "full"))
                                        if n.startswith("checkpoint_"))[0])
    before = {n: digest(os.path.join(d, "heavy", n)) for n in theirs}
    expect(case, grain(d, "run", "scene.yaml", "--output", "heavy", "--restart", first), 0,
           r"heavy/particles_000000\.h5 was written by another scene's run[^\n]*\n"
           r"(.|\n)*heavy/checkpoint_\d+\.h5 was written by another scene's run \(its record of "
           r"insertions or model differs\)")
    left = [n for n in theirs if not os.path.exists(os.path.join(d, "heavy", n))]
    if left:
        fail(case, f"the other run's checkpoints {left} were deleted")


GAS = """domain: {min: [0, 0, 0], max: [0.01, 0.01, 0.01], periodic: [true, true, true]}
gravity: [0, 0, 0]
time: {rayleigh_fraction: 0.15, end: 0.004}
materials: [{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}]
interactions: [{materials: [glass, glass], restitution: 0.9, friction: 0.3}]
contact: {normal: hertz, tangential: history}
neighbour: {skin: SKIN}
insert:
  - {type: fill, region: {box: {min: [0, 0, 0], max: [0.01, 0.01, 0.01]}}, count: 100,
     material: glass, radius: 3e-4, velocity: [3, 2, 1]}
output: {snapshot_interval: 0.001, checkpoint_interval: 0.001, checkpoint_keep: 10, progress: false}
"""


def restart_smaller_skin():
    """neighbour may change at a restart: a gas of beads crossing a periodic box restarted
    with a tenth of the run's skin ends where the uninterrupted run ends (its centres, up to
    half the run's skin past the sides, had been refused as a damaged checkpoint)."""
    case = "restart_smaller_skin"
    d = fresh(case)
    with open(os.path.join(d, "gas.yaml"), "w") as out:
        out.write(GAS.replace("SKIN", "0.002"))
    with open(os.path.join(d, "small.yaml"), "w") as out:
        out.write(GAS.replace("SKIN", "0.0002"))
    expect(case, grain(d, "run", "gas.yaml", "--output", "full"), 0, r"done:")
    import h5py
    import numpy as np
    with h5py.File(os.path.join(d, "full", "particles_000004.h5"), "r") as f:
        order = np.argsort(f["id"][()])
        x_full, v_full = f["position"][()][order], f["velocity"][()][order]
    for checkpoint in sorted(n for n in os.listdir(os.path.join(d, "full"))
                             if n.startswith("checkpoint_")):
        out = "r" + checkpoint[11:20]
        expect(case, grain(d, "run", "small.yaml", "--output", out, "--restart",
                           os.path.join("full", checkpoint)), 0, r"done:")
        last = sorted(n for n in os.listdir(os.path.join(d, out)) if n.startswith("particles_"))
        with h5py.File(os.path.join(d, out, last[-1]), "r") as f:
            order = np.argsort(f["id"][()])
            dx = f["position"][()][order] - x_full
            dx -= 0.01 * np.round(dx / 0.01)  # the same point, wrapped at another rebuild
            dv = f["velocity"][()][order] - v_full
        if np.abs(dx).max() > 1e-12 or np.abs(dv).max() > 1e-9:
            fail(case, f"{checkpoint}: ends {np.abs(dx).max():.3g} m, {np.abs(dv).max():.3g} "
                       "m/s from the uninterrupted run")


def hostile_text():
    """Text a user's tools leave in files: a byte-order mark (CSV and ASCII STL, read past),
    an invisible character in a key (named by its code point), a merge key, a value pasted
    whole (shown by its start), a number too large to count, odd paths."""
    case = "hostile_text"
    d = fresh(case)
    with open(os.path.join(d, "beads.csv"), "w", encoding="utf-8-sig") as out:
        out.write(CSV)
    with open(os.path.join(d, "plate.stl"), "w", encoding="utf-8-sig") as out:
        out.write(PLATE)
    csv = "  - {type: csv, file: beads.csv, material: glass}"
    text = scene(d, insert=csv)
    wall = "walls: [{type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass}]"
    with open(os.path.join(d, "scene.yaml"), "w") as out:
        out.write(text.replace(wall, "walls: [{type: mesh, name: floor, file: plate.stl, scale: "
                                     "0.01, translate: [0.005, 0.005, 0], material: glass}]"))
    expect(case, grain(d, "check", "scene.yaml"), 0, r"particles: 2\b")

    def refused(name, new_text, pattern, code=2, command="check"):
        with open(os.path.join(d, name), "w") as out:
            out.write(new_text)
        got = grain(d, command, name)
        expect(case + ":" + name, got, code, pattern)
        if len(got[1]) > 5000:
            fail(case + ":" + name, f"the message is {len(got[1])} characters long")

    refused("hidden.yaml", text.replace("density: 2500", "dens\u200bity: 2500"),
            r"unknown key 'dens.*ity' in materials\[0\].*it holds the character U\+200B, at "
            r"character 5, which may not show: retype it")
    refused("merge.yaml", text.replace("materials: [{name: glass,",
                                       "base: &b {poisson_ratio: 0.25}\nmaterials: [{<<: *b, "
                                       "name: glass,"),
            r"error: (unknown key 'base'|YAML merge keys)")
    refused("merge2.yaml", text.replace("materials: [{name: glass,", "materials: [{<<: {x: 1}, "
                                        "name: glass,"),
            r"YAML merge keys \('<<: \*anchor'\) are not supported in a scene")
    refused("long.yaml", text.replace("restitution: 0.5", "restitution: " + "7" * 200000 + "x"),
            r"got '7{60}\.\.\.' \(200001 characters\)")
    # Every message shortens a long value, not only "got ...": a model's name, a number's
    # digits; and a name (a log.csv column) is at most 100 characters.
    refused("long_model.yaml", text.replace("normal: hertz", "normal: " + "h" * 200000),
            r"unknown normal contact model 'h{59}\.\.\.\(200003 characters\)'; allowed: hertz")
    refused("long_digits.yaml", text.replace("density: 2500", "density: " + "1" * 200000),
            r"value 1{60}\.\.\.\(200000 characters\) is beyond the range of a double")
    refused("long_name.yaml", text.replace("name: floor", "name: " + "f" * 200000),
            r"wall name 'f{60}\.\.\.' is 200000 characters long; a name is at most 100 characters")
    refused("huge.yaml", text.replace(csv, FILL).replace("count: 50", "count: 1e20"),
            r"value 1e20 is too large for a whole number here")
    refused("device.yaml", text.replace("file: beads.csv", "file: /dev/null"),
            r"'/dev/null' \('/dev/null'\) is not a regular file")
    os.makedirs(os.path.join(d, "folder.yaml"), exist_ok=True)
    expect(case, grain(d, "check", "folder.yaml"), 2, r"folder\.yaml: error: is a directory")


def restart_advice():
    """The summary names the newest checkpoint and the command that continues from it; that
    command, with time.end raised, ends where one longer run ends (bit for bit). A restart
    into another folder says so; a snapshot given as the checkpoint is named as one."""
    case = "restart_advice"
    d = fresh(case)
    scene(d, name="long.yaml", end=0.006, extra=", checkpoint_interval: 0.0015")
    expect(case, grain(d, "run", "long.yaml", "--output", "long", "--no-progress"), 0, r"done:")
    scene(d, end=0.004, extra=", checkpoint_interval: 0.0015")
    rc, out = grain(d, "run", "scene.yaml", "--no-progress")
    m = re.search(r"checkpoint: the newest is (out/checkpoint_\d+\.h5) \(none is written at "
                  r"time\.end\); to run longer, raise time\.end and continue with: (.*)", out)
    if rc != 0 or not m:
        fail(case, f"exit {rc}, no checkpoint line:\n{out}")
        return
    command = m.group(2).split()
    if command[0] != GRAIN or command[-2:] != ["--restart", m.group(1)]:
        fail(case, f"the command is {m.group(2)!r}")
        return
    scene(d, end=0.006, extra=", checkpoint_interval: 0.0015")
    expect(case, grain(d, *command[1:]), 0, r"done:")
    import h5py
    import numpy as np
    last = sorted(n for n in os.listdir(os.path.join(d, "long")) if n.startswith("particles_"))[-1]
    with h5py.File(os.path.join(d, "long", last), "r") as a, \
            h5py.File(os.path.join(d, "out", last), "r") as b:
        if a.attrs["time"] != b.attrs["time"] or not all(
                np.array_equal(a[k][()], b[k][()]) for k in ("id", "position", "velocity")):
            fail(case, f"{last}: the extended run is not the longer run bit for bit")
    expect(case, grain(d, "run", "scene.yaml", "--output", "elsewhere", "--restart", m.group(1)),
           0, r"note: the checkpoint is in out, this restart writes into elsewhere, which holds "
              r"none of its run's snapshots")
    expect(case, grain(d, "run", "scene.yaml", "--output", "x", "--restart",
                       "out/particles_000002.h5"), 1,
           r"cannot restart from 'out/particles_000002\.h5': it is a snapshot, not a checkpoint")
    # Told by the contents, not the name: a snapshot renamed state.h5 is still one, and a
    # checkpoint copied to particles_backup.h5 still restarts.
    shutil.copy(os.path.join(d, "out", "particles_000002.h5"), os.path.join(d, "state.h5"))
    for command in ("run", "check"):
        expect(case, grain(d, command, "scene.yaml", "--restart", "state.h5"), 1,
               r"cannot restart from 'state\.h5': it is a snapshot, not a checkpoint")
    shutil.copy(os.path.join(d, m.group(1)), os.path.join(d, "particles_backup.h5"))
    expect(case, grain(d, "run", "scene.yaml", "--output", "backup", "--restart",
                       "particles_backup.h5"), 0, r"done:")


if __name__ == "__main__":
    GRAIN, WORK = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    os.makedirs(WORK, exist_ok=True)
    for check in (overwrite_csv, overwrite_snapshot, overwrite_scene, hard_linked_backup,
                  failed_start_writes_nothing, signal_during_start,
                  second_document, end_beyond_count, coupled_checkpoint, tilde, input_named,
                  help_option, restart_at_end, restart_other_step_setting, restart_other_domain,
                  check_restart,
                  restart_missing_csv, restart_mesh,
                  restart_other_physics, restart_smaller_skin, hostile_text,
                  restart_advice, restart_output_series, restart_lost_snapshots):
        check()
    if failures:
        sys.exit(f"{len(failures)} failure(s)")
    print("all user-file checks hold")
