#!/usr/bin/env python3
"""Checks of scripts/h5_summary.py and scripts/plot_log.py on the files `grain run` writes.

    scripts_test.py CASE --grain build/bin/grain --work DIR

CASE is one of the functions in CASES below; each runs tiny scenes (50 beads or 20 parcels,
0.02 s, well under a second each) into DIR and runs the script on what they wrote. Exit 0 when
every check passes; each failed check is printed. Run by CTest (tests/scripts/tests.cmake).
"""
import argparse
import os
import re
import shutil
import subprocess
import sys

import h5py
import numpy as np

SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPTS = os.path.join(SOURCE, "scripts")

# The 50-bead scene of the tester's reproductions: 5 snapshots (0.005 s apart) and one
# checkpoint at 0.01 s.
SCENE = """\
domain: {{min: [0, 0, 0], max: [{side}, {side}, {height}]}}
gravity: [0, 0, -9.81]
time: {{rayleigh_fraction: 0.1, end: {end}}}
materials:
  - {{name: glass, youngs_modulus: 5e6, poisson_ratio: 0.3, density: 2500}}
interactions:
  - {{materials: [glass, glass], restitution: 0.9, friction: 0.5}}
contact: {{normal: hertz}}
walls:
  - {{type: plane, name: floor, point: [0, 0, 0], normal: [0, 0, 1], material: glass}}
insert:
  - type: fill
    region: {{box: {{min: [0, 0, 0.002], max: [{side}, {side}, {height}]}}}}
    count: {count}
{extra}    material: glass
    radius: {{distribution: uniform, min: 4e-4, max: 6e-4}}
output: {{directory: {out}, snapshot_interval: 0.005, checkpoint_interval: 0.01}}
"""

failures = []


def check(ok, what, output=""):
    print(("ok:     " if ok else "FAILED: ") + what)
    if not ok:
        failures.append(what)
        if output:
            print("  output was:\n    " + "\n    ".join(output.splitlines()[-30:]))


def scene(work, name, out, count=50, end=0.02, side=0.01, height=0.02, coarse_grain=None):
    extra = f"    coarse_grain: {coarse_grain}\n" if coarse_grain else ""
    path = os.path.join(work, name)
    with open(path, "w") as f:
        f.write(SCENE.format(side=side, height=height, end=end, count=count, extra=extra,
                             out=out))
    return path


def grain_run(args, scene_path):
    r = subprocess.run([args.grain, "run", scene_path, "--no-progress"], cwd=args.work,
                       capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"scripts_test: grain run {scene_path} failed ({r.returncode}):\n{r.stdout}{r.stderr}")


def script(args, name, *argv, timeout=60):
    """(exit code, stdout + stderr) of one of the scripts, run by this Python; exit code None
    when it ran past `timeout` seconds (a hang)."""
    try:
        r = subprocess.run([sys.executable, os.path.join(SCRIPTS, name), *argv], cwd=args.work,
                           capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, f"(timed out after {timeout} s)"
    return r.returncode, r.stdout + r.stderr


def edited_copy(args, source, name, edit):
    """A copy of the HDF5 file `source` (under the work folder) as `name`, changed by
    edit(h5py.File) in place; returns `name`."""
    shutil.copy(os.path.join(args.work, source), os.path.join(args.work, name))
    with h5py.File(os.path.join(args.work, name), "r+") as f:
        edit(f)
    return name


def one_line_error(code, text, *expected):
    return (code == 1 and "Traceback" not in text and len(text.strip().splitlines()) == 1
            and all(e in text for e in expected))


def particles_of(text, path):
    """The count on the `particles N` line under `path` in h5_summary's output."""
    m = re.search(re.escape(path) + r"\n(?:  note:.*\n)?  time .* particles (\d+)", text)
    return int(m.group(1)) if m else None


def h5_summary_folder(args):
    """A folder with a checkpoint (50 beads, stored under /particles/) and the snapshots of a
    later, shorter run of 30 beads: the later run's three snapshots are summarised, the two
    left over from the first run are counted and named, the checkpoint reports its 50."""
    grain_run(args, scene(args.work, "first.yaml", "out"))
    grain_run(args, scene(args.work, "second.yaml", "out", count=30, end=0.01))
    code, text = script(args, "h5_summary.py", "out")
    check(code == 0, "h5_summary on the folder exits 0", text)
    check("Traceback" not in text, "no traceback", text)
    check("note: out: 3 snapshot(s) listed in particles.xdmf" in text,
          "the three snapshots particles.xdmf lists are summarised", text)
    check("2 other particles_*.h5 file(s) in out are left over from other runs" in text
          and "particles_000003.h5, particles_000004.h5" in text,
          "the two snapshots left over from the first run are counted and named", text)
    for i in range(3):
        check(particles_of(text, f"out/particles_00000{i}.h5") == 30,
              f"particles_00000{i}.h5 of the second run: 30 particles", text)
    for i in (3, 4):
        check(f"out/particles_00000{i}.h5\n" not in text,
              f"the left-over particles_00000{i}.h5 is not summarised", text)
    checkpoints = sorted(f for f in os.listdir(os.path.join(args.work, "out"))
                         if f.startswith("checkpoint_"))
    check(len(checkpoints) == 1, "the first run left one checkpoint", " ".join(checkpoints))
    for c in checkpoints:
        with h5py.File(os.path.join(args.work, "out", c), "r") as f:
            stored = f["particles/id"].shape[0]
        check(stored == 50, f"{c} stores 50 particles under /particles/")
        check(particles_of(text, f"out/{c}") == stored,
              f"{c} is summarised with its {stored} particles (it said 0)", text)
        check(re.search(re.escape(f"out/{c}") + r"\n  note: left over from another run", text)
              is not None, f"{c} is marked as left over from the first run", text)
    check("materials  glass:30" in text, "materials by name (glass:30)", text)
    # Without the index: the newest file's scene_fingerprint chooses the run.
    os.remove(os.path.join(args.work, "out", "particles.xdmf"))
    code, text = script(args, "h5_summary.py", "out")
    check(code == 0 and "no particles.xdmf; 3 snapshot(s) with the scene_fingerprint" in text
          and "(another scene_fingerprint)" in text,
          "without particles.xdmf: the newest run's 3 snapshots, the 2 others named", text)
    # A folder with no .h5 file: an error, exit 1.
    os.makedirs(os.path.join(args.work, "empty"), exist_ok=True)
    code, text = script(args, "h5_summary.py", "empty")
    check(code == 1 and "empty: no .h5 file in this folder" in text and "Traceback" not in text,
          "a folder without .h5 files: one-line error, exit 1", text)
    code, text = script(args, "h5_summary.py", "first.yaml")
    check(code == 1 and "Traceback" not in text and len(text.strip().splitlines()) == 1,
          "a file that is not HDF5: one-line error, exit 1", text)
    # HDF5 files that are neither a snapshot nor a checkpoint: an error, exit 1 (it printed
    # "time nan s step -1 particles 0", exit 0).
    with h5py.File(os.path.join(args.work, "empty.h5"), "w"):
        pass
    with h5py.File(os.path.join(args.work, "flat.h5"), "w") as f:
        f["particles"] = np.zeros(3)  # /particles a dataset, not a checkpoint's group
    for name in ("empty.h5", "flat.h5"):
        code, text = script(args, "h5_summary.py", name)
        check(one_line_error(code, text, name, "neither a grainflow snapshot",
                             "nor a checkpoint"),
              f"{name}: neither a snapshot nor a checkpoint: one-line error, exit 1", text)

    # Material indices out of the names' range: 2^30 (it built a list of 2^30 names and
    # hung), -1 (it printed the last name) and 7, each reported as not in material_names.
    def bad_materials(f):
        m = f["material"][...]
        m[:3] = [2**30, -1, 7]
        f["material"][...] = m
    name = edited_copy(args, "out/particles_000002.h5", "badmat.h5", bad_materials)
    code, text = script(args, "h5_summary.py", name, timeout=30)
    check(code == 0 and "Traceback" not in text
          and "material 1073741824 (not in material_names):1" in text
          and "material -1 (not in material_names):1" in text
          and "material 7 (not in material_names):1" in text and "glass:27" in text,
          "material indices 2^30, -1, 7: each said not in material_names, promptly", text)


def h5_summary_coarse_grain(args):
    """20 parcels of k = 2: the count of parcels, k, and the real particles they stand for,
    N x k^3 = 160 (the closed form; the snapshot's real_count agrees), the real radius = the
    parcel radius / k, the material by its class name glass[k=2]."""
    grain_run(args, scene(args.work, "cg.yaml", "cg", count=20, side=0.02, height=0.03,
                          coarse_grain=2))
    snaps = sorted(f for f in os.listdir(os.path.join(args.work, "cg"))
                   if f.startswith("particles_") and f.endswith(".h5"))
    last = os.path.join("cg", snaps[-1])
    with h5py.File(os.path.join(args.work, last), "r") as f:
        n = f["id"].shape[0]
        r = f["radius"][...]
        real_count = float(f["real_count"][...].sum())
    k = 2
    check(n == 20, f"the snapshot holds 20 parcels (holds {n})")
    check(real_count == n * k**3, f"real_count sums to N k^3 = {n * k**3}")
    for path in (last, os.path.join("cg", [c for c in os.listdir(os.path.join(args.work, "cg"))
                                           if c.startswith("checkpoint_")][0])):
        code, text = script(args, "h5_summary.py", path)
        check(code == 0 and "Traceback" not in text, f"h5_summary {path} exits 0", text)
        check(f"particles {n} ({n} parcels among them; together {n * k**3} real particles)"
              in text, f"{path}: {n} particles, {n} parcels, {n * k**3} real", text)
        m = re.search(r"coarse grain k (\S+): (\d+) parcels stand for (\d+) real particles "
                      r"\((\S+) each\); radius \[m\] parcels (\S+) to (\S+), "
                      r"real particles (\S+) to (\S+)", text)
        check(m is not None, f"{path}: the line of the k = 2 parcels", text)
        if m:
            check(float(m.group(1)) == k and int(m.group(2)) == n
                  and int(m.group(3)) == n * k**3 and float(m.group(4)) == k**3,
                  f"{path}: k 2, {n} parcels, {n} x 2^3 = {n * k**3} real", m.group(0))
            pr = [float(m.group(i)) for i in (5, 6, 7, 8)]
            check(abs(pr[0] - r.min()) <= 1e-5 * r.min() and abs(pr[1] - r.max()) <= 1e-5 * r.max()
                  and abs(pr[2] - r.min() / k) <= 1e-5 * r.min()
                  and abs(pr[3] - r.max() / k) <= 1e-5 * r.max()
                  and 4e-4 <= pr[2] and pr[3] <= 6e-4,
                  f"{path}: parcel radius {r.min():.6g} to {r.max():.6g}, real = parcel / 2 "
                  "within the insertion's 0.4 to 0.6 mm", m.group(0))
        check(f"materials  glass[k=2]:{n}" in text, f"{path}: material by name glass[k=2]", text)
        check("real radius [m]  min" in text, f"{path}: the real radius line", text)
    # Impossible parcel data: a real_count of 0 (np.average raised ZeroDivisionError) and a
    # coarse_grain of 0 (radius / 0 = inf): one line naming the file and dataset, exit 1.
    def zero(dataset):
        def edit(f):
            f[dataset][...] = np.zeros(f[dataset].shape)
        return edit
    for dataset in ("real_count", "coarse_grain"):
        name = edited_copy(args, last, f"zero_{dataset}.h5", zero(dataset))
        code, text = script(args, "h5_summary.py", name)
        check(one_line_error(code, text, name, f"dataset /{dataset} holds 0"),
              f"{dataset} all 0: one-line error naming {name} and /{dataset}, exit 1", text)
    # k = 1: no parcel lines, the material by name.
    grain_run(args, scene(args.work, "plain.yaml", "plain"))
    code, text = script(args, "h5_summary.py", "plain/particles_000004.h5")
    check(code == 0 and "particles 50\n" in text and "materials  glass:50" in text
          and "coarse grain" not in text and "real" not in text,
          "k = 1: the plain summary, materials by name", text)


def listed(args, folder):
    """The snapshot files a run's particles.xdmf lists (the run's own index: the reference)."""
    import xml.etree.ElementTree as ET
    grid = ET.parse(os.path.join(args.work, folder, "particles.xdmf")).getroot().find("Domain/Grid")
    return [g.get("Name") + ".h5" for g in grid.findall("Grid")]


def summarised(text, folder):
    """The snapshot files h5_summary's output summarises (a `folder/particles_N.h5` line)."""
    return re.findall(r"^" + re.escape(folder) + r"/(particles_\d+\.h5)$", text, re.M)


def grain_restart(args, scene_path, out, checkpoint):
    r = subprocess.run([args.grain, "run", scene_path, "--no-progress", "--output", out,
                        "--restart", os.path.join(out, checkpoint)], cwd=args.work,
                       capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"scripts_test: the restart from {checkpoint} failed ({r.returncode}):\n"
                 f"{r.stdout}{r.stderr}")
    return r.stdout + r.stderr


def h5_summary_no_index(args):
    """Without particles.xdmf, two runs of one scene in one folder (the same scene_fingerprint):
    a 0.02 s run (snapshots 0-4) and then a 0.01 s run (0-2, over the first three). The
    reference is the second run's own index, read before it is removed: 0-2. Snapshots 3 and 4
    lie past the end of log.csv (the second run's, t = 0.01 s): not summarised, named as ones
    it cannot tell apart (it summarised all five as the second run's). Without log.csv it says
    that it cannot tell runs of one scene apart. A single run's particles.xdmf cut short (a
    power loss): its five snapshots, the damaged index named with the remedy, a restart, which
    the test then runs and which rewrites an index listing the five (it summarised nothing,
    exit 1)."""
    long = scene(args.work, "long.yaml", "out", end=0.02)
    short = scene(args.work, "short.yaml", "out", end=0.01)
    grain_run(args, long)
    grain_run(args, short)
    own = listed(args, "out")
    check(own == [f"particles_00000{i}.h5" for i in range(3)],
          "the second run's index lists particles_000000-2", " ".join(own))
    with open(os.path.join(args.work, "out", "log.csv")) as f:
        log_end_time = float(f.read().splitlines()[-1].split(",")[0])
    check(abs(log_end_time - 0.01) < 1e-4, f"log.csv (the second run's) ends at 0.01 s "
          f"({log_end_time})")
    shutil.copytree(os.path.join(args.work, "out"), os.path.join(args.work, "damaged"))
    os.remove(os.path.join(args.work, "out", "particles.xdmf"))
    code, text = script(args, "h5_summary.py", "out")
    check(code == 0 and summarised(text, "out") == own,
          f"no index: the second run's {len(own)} snapshots are summarised, no more "
          f"(summarised {summarised(text, 'out')})", text)
    check("cannot tell whether 2 snapshot(s) of the same scene past the end of out/log.csv"
          in text and "particles_000003.h5, particles_000004.h5" in text,
          "no index: snapshots 3 and 4 past the end of log.csv are named as not told apart",
          text)
    os.remove(os.path.join(args.work, "out", "log.csv"))
    code, text = script(args, "h5_summary.py", "out")
    check(code == 0 and "out/log.csv is missing or holds no complete row: snapshots an earlier "
          "run of the same scene left in the folder cannot be told from this run's" in text,
          "no index, no log.csv: says it cannot tell runs of one scene apart", text)
    # The index of a single 0.02 s run cut short, as an append's blocks lost to a power loss
    # can leave it: its five snapshots (listed before the cut: the reference) are summarised.
    single = scene(args.work, "single.yaml", "damaged", end=0.02)
    grain_run(args, single)
    own = listed(args, "damaged")
    index = os.path.join(args.work, "damaged", "particles.xdmf")
    with open(index, "rb") as f:
        intact = f.read()
    with open(index, "wb") as f:
        f.write(intact[:len(intact) // 2])
    code, text = script(args, "h5_summary.py", "damaged")
    check(code == 0 and summarised(text, "damaged") == own,
          f"damaged index: the run's {len(own)} snapshots are summarised "
          f"(summarised {summarised(text, 'damaged')})", text)
    check("note: damaged/particles.xdmf cannot be read (" in text
          and "A restart (grain run --restart) from one of the folder's checkpoints before the "
          "run's end rewrites the index" in text, "damaged index: named, with the remedy", text)
    checkpoint = sorted(c for c in os.listdir(os.path.join(args.work, "damaged"))
                        if c.startswith("checkpoint_"))[0]
    grain_restart(args, single, "damaged", checkpoint)
    check(listed(args, "damaged") == own, "the remedy holds: a restart from "
          f"{checkpoint} rewrote particles.xdmf, which lists {own[0]} ... {own[-1]}")
    # The same folder as a grainFoam case's particles/ (system/controlDict beside it): the
    # remedy is a grainFoam restart; `grain run --restart` there ran the coupled scene without
    # its fluid over the case's snapshots.
    case = os.path.join(args.work, "foam_case")
    shutil.rmtree(case, ignore_errors=True)
    shutil.copytree(os.path.join(args.work, "damaged"), os.path.join(case, "particles"))
    os.makedirs(os.path.join(case, "system"))
    with open(os.path.join(case, "system", "controlDict"), "w") as f:
        f.write("// a grainFoam case\n")
    with open(os.path.join(case, "particles", "particles.xdmf"), "wb") as f:
        f.write(intact[:len(intact) // 2])
    code, text = script(args, "h5_summary.py", os.path.join("foam_case", "particles"))
    check(code == 0 and "A restart of grainFoam (startFrom latestTime in system/controlDict of "
          in text and "not grain run --restart" in text,
          "damaged index of a grainFoam case: the remedy is a grainFoam restart", text)


def h5_summary_unreadable_snapshot(args):
    """A run's own snapshot that cannot be read (particles_000001.h5 cut to 1000 bytes), a
    gap the restart from the 0.01 s checkpoint reports: h5_summary calls it unreadable (damaged
    or truncated) and a gap in the series, with or without particles.xdmf, not a file "left
    over from other runs" or of "another scene_fingerprint" (it said both)."""
    path = scene(args.work, "gap.yaml", "out")
    grain_run(args, path)
    with open(os.path.join(args.work, "out", "particles_000001.h5"), "r+b") as f:
        f.truncate(1000)
    checkpoint = sorted(c for c in os.listdir(os.path.join(args.work, "out"))
                        if c.startswith("checkpoint_"))[0]
    restart = grain_restart(args, path, "out", checkpoint)
    check("particles_000001.h5 (unreadable) is a gap" in restart,
          "the restart reports particles_000001.h5 as a gap", restart)
    expected = ("1 particles_*.h5 file(s) in out cannot be read (damaged or truncated), not "
                "summarised: particles_000001.h5 (1 of them inside the numbers of the series "
                "summarised: a gap in it)")
    for label in ("with particles.xdmf", "without particles.xdmf"):
        code, text = script(args, "h5_summary.py", "out")
        check(code == 0 and expected in text and "left over" not in text.split("out/checkpoint")[0]
              and "another scene_fingerprint" not in text,
              f"{label}: particles_000001.h5 is unreadable, a gap, not another run's", text)
        check(summarised(text, "out") == [f"particles_00000{i}.h5" for i in (0, 2, 3, 4)],
              f"{label}: snapshots 0, 2, 3, 4 are summarised", text)
        os.remove(os.path.join(args.work, "out", "particles.xdmf")) if label.startswith("with ") \
            else None


def plot_log_bad_inputs(args):
    """Each bad input is a one-line error naming it, exit 1, no traceback."""
    grain_run(args, scene(args.work, "plot.yaml", "plot"))
    cases = [
        (["nosuch.csv", "-o", "p.png"], "nosuch.csv: no such file"),
        (["plot", "-o", "p.png"], "plot is a folder, not a log table"),
        (["plot/particles_000000.h5", "-o", "p.png"], "is a binary file"),
        (["plot.yaml", "-o", "p.png"], "is not a grainflow log header"),
        (["plot/log.csv", "-o", "nodir/p.png"], "-o nodir/p.png: no folder"),
        (["plot/log.csv", "-o", "plot"], "-o plot is a folder"),
        (["plot/log.csv", "-c", "ke_total", "-o", "p.png"], "no column ke_total; valid columns"),
        (["plot/log.csv", "-o", "g.xyz"], "-o g.xyz: matplotlib cannot write .xyz files; "
                                          "give a name ending in"),
        (["plot/log.csv", "-o", "g.txt"], ".png"),
        (["plot/log.csv", "-o", "plot/log.csv"], "-o plot/log.csv is the log table itself"),
    ]
    for argv, expected in cases:
        code, text = script(args, "plot_log.py", *argv)
        check(code == 1 and "Traceback" not in text and expected in text
              and len(text.strip().splitlines()) == 1,
              f"plot_log {' '.join(argv)}: exit 1, one line with '{expected}'", text)
    code, text = script(args, "plot_log.py", "plot/log.csv", "-o", "ok.png")
    check(code == 0 and re.search(r"wrote ok.png \(\d+ rows\)\n", text) is not None
          and "skipped" not in text, "an intact log plots, nothing skipped", text)
    with open(os.path.join(args.work, "plot", "log.csv"), encoding="utf-8") as f:
        lines = f.read().splitlines()
    # A byte-order mark before the header (it made the first column '\ufefftime_s').
    with open(os.path.join(args.work, "bom.csv"), "w", encoding="utf-8-sig") as f:
        f.write("\n".join(lines) + "\n")
    code, text = script(args, "plot_log.py", "bom.csv", "-x", "time_s", "-o", "bom.png")
    check(code == 0 and f"wrote bom.png ({len(lines) - 1} rows)\n" in text,
          "a log with a byte-order mark plots all its rows", text)
    # A field longer than csv's default limit of 131072 characters (it raised _csv.Error):
    # a damaged row, skipped and named.
    with open(os.path.join(args.work, "long.csv"), "w") as f:
        f.write("\n".join(lines[:3] + ["1" * 200000] + lines[3:]) + "\n")
    code, text = script(args, "plot_log.py", "long.csv", "-o", "long.png")
    check(code == 0 and "Traceback" not in text and "long.csv:4: damaged row skipped" in text
          and f"wrote long.png ({len(lines) - 1} rows; skipped 1 damaged row(s), line(s) 4)"
          in text, "a 200000-character field: that row skipped and named", text)
    # And in the header: the last column's name 200000 characters long.
    with open(os.path.join(args.work, "longhead.csv"), "w") as f:
        f.write("\n".join([lines[0] + "x" * 200000] + lines[1:]) + "\n")
    code, text = script(args, "plot_log.py", "longhead.csv", "-o", "longhead.png")
    check(code == 0 and f"wrote longhead.png ({len(lines) - 1} rows)\n" in text,
          "a 200000-character header field: the log plots", text)
    # -o without an extension: matplotlib writes <name>.png, and the script names that file.
    code, text = script(args, "plot_log.py", "bom.csv", "-o", "noext")
    check(code == 0 and "wrote noext.png (" in text
          and os.path.isfile(os.path.join(args.work, "noext.png")), "-o noext writes and names "
          "noext.png", text)


def plot_log_damaged_row(args):
    """A damaged row in the middle of a log (a ';' for a ',') and a last row cut short: both
    left out and reported with their line numbers; the other rows are plotted."""
    grain_run(args, scene(args.work, "plot.yaml", "plot"))
    with open(os.path.join(args.work, "plot", "log.csv")) as f:
        lines = f.read().splitlines()
    rows = len(lines) - 1
    lines[50] = lines[50].replace(",", ";", 1)  # line 51
    with open(os.path.join(args.work, "damaged.csv"), "w") as f:
        f.write("\n".join(lines) + "\n")
    code, text = script(args, "plot_log.py", "damaged.csv", "-o", "damaged.png")
    check(code == 0 and "Traceback" not in text, "plot_log on a damaged log exits 0", text)
    check("damaged.csv:51: damaged row skipped: 9 fields, not 10 numbers" in text,
          "the damaged row is named by its line, 51", text)
    check(f"wrote damaged.png ({rows - 1} rows; skipped 1 damaged row(s), line(s) 51)" in text,
          f"{rows - 1} of {rows} rows plotted, the skipped one counted", text)
    # And the last row cut short, as by a killed run (no newline at its end).
    with open(os.path.join(args.work, "cut.csv"), "w") as f:
        f.write("\n".join(lines) + "\n" + lines[-1][:25])
    code, text = script(args, "plot_log.py", "cut.csv", "-o", "cut.png")
    check(code == 0 and f"cut.csv:{rows + 2}: damaged row skipped: cut short" in text
          and f"skipped 2 damaged row(s), line(s) 51, {rows + 2}" in text,
          "a last row cut short is reported too", text)


CASES = {f.__name__: f for f in (h5_summary_folder, h5_summary_coarse_grain,
                                 h5_summary_no_index, h5_summary_unreadable_snapshot,
                                 plot_log_bad_inputs, plot_log_damaged_row)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", choices=sorted(CASES))
    ap.add_argument("--grain", required=True, help="the grain executable")
    ap.add_argument("--work", required=True, help="a folder for the runs (emptied first)")
    args = ap.parse_args()
    args.grain = os.path.abspath(args.grain)
    args.work = os.path.abspath(args.work)
    shutil.rmtree(args.work, ignore_errors=True)
    os.makedirs(args.work)
    CASES[args.case](args)
    print(f"{args.case}: {len(failures)} check(s) failed" if failures else f"{args.case}: ok")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
