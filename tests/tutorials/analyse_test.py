#!/usr/bin/env python3
"""Checks of the tutorials' analyse.py (and tutorials/run_index.py) on the output of stopped,
restarted and damaged runs, built by hand so that every number is known by construction.

    analyse_test.py CASE --work DIR

CASE is one of the functions in CASES below; each writes a few small files (snapshots with
h5py, log tables, OpenFOAM postProcessing series) into DIR, runs the tutorial's analyse.py on
them from the source tree and checks what it prints against the construction. Each takes a
second or two. Exit 0 when every check passes; each failed check is printed. Run by CTest
(tests/tutorials/tests.cmake).
"""
import argparse
import math
import os
import re
import shutil
import subprocess
import sys

import h5py
import numpy as np

SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TUTORIALS = os.path.join(SOURCE, "tutorials")
ERGUN = os.path.join(TUTORIALS, "cfd-dem", "ergunPackedBed", "analyse.py")  # run in its case

failures = []


def check(ok, what, output=""):
    print(("ok:     " if ok else "FAILED: ") + what)
    if not ok:
        failures.append(what)
        if output:
            print("  output was:\n    " + "\n    ".join(output.splitlines()[-20:]))


def run(args, script, *argv):
    """(exit code, stdout + stderr) of a tutorial script run by this Python in the work folder."""
    r = subprocess.run([sys.executable, os.path.join(TUTORIALS, script), *argv], cwd=args.work,
                       capture_output=True, text=True, timeout=120)
    return r.returncode, r.stdout + r.stderr


def number(pattern, text):
    m = re.search(pattern, text)
    return float(m.group(1)) if m else float("nan")


def snapshot(path, time, step, position, radius, density=2500.0, fingerprint="scene-A", **extra):
    """A particle snapshot as grain writes one (the datasets and attributes the scripts read)."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    n = len(radius)
    with h5py.File(path, "w") as f:
        f.attrs["time"] = time
        f.attrs["step"] = step
        f.attrs["count"] = n
        f.attrs["scene_fingerprint"] = fingerprint
        f["id"] = np.arange(n, dtype=np.int64)
        f["position"] = np.asarray(position, float).reshape(n, 3)
        f["radius"] = np.asarray(radius, float)
        f["mass"] = density * 4 / 3 * math.pi * np.asarray(radius, float) ** 3
        f["velocity"] = np.zeros((n, 3))
        for name, value in extra.items():
            f[name] = value


def index(folder, names):
    """particles.xdmf listing `names` (the stems of the snapshot files), as grain's run index."""
    grids = "".join(f'      <Grid Name="{n}" GridType="Uniform"><Time Value="{i}"/></Grid>\n'
                    for i, n in enumerate(names))
    with open(os.path.join(folder, "particles.xdmf"), "w") as f:
        f.write('<?xml version="1.0"?>\n<Xdmf Version="2.0">\n  <Domain>\n'
                '    <Grid Name="particles" GridType="Collection" CollectionType="Temporal">\n'
                f"{grids}    </Grid>\n  </Domain>\n</Xdmf>\n")


LOG_HEADER = ("time_s,step,particles,ke_trans_J,ke_rot_J,max_overlap_ratio,contacts,rebuilds,"
              "removed,wall_s")


def hopper_restarted_folder(args):
    """A discharge whose series in `restart/` starts at t = 0.32 s (a run restarted into
    another folder). Construction: 147 beads of radius 1 mm on a 2 mm cubic lattice fill the
    bulk-density cylinder at t = 0 (solid fraction 147 (4/3 pi r^3) / (pi 5^2 15 mm^3) =
    0.5227); from t > 0 every other one sits lower (z = 5 mm, out of the cylinder: a bed that
    has moved), and 10 reservoir beads drop below the orifice per 0.02 s snapshot: the mass
    falls at exactly 10 m / 0.02 s = 5.236 g/s. On restart/ alone analyse.py took the moved bed
    for the one at t = 0 (solid fraction 0.26) and labelled the fit 0.2-1.0 s; now it says that
    the series starts at 0.32 s and stops, and with --bed it gives the t = 0 numbers."""
    r, rho_p = 1e-3, 2500.0
    grid = [(x, y) for x in range(-4, 5, 2) for y in range(-4, 5, 2) if math.hypot(x, y) < 5]
    cyl = np.array([(x * 1e-3, y * 1e-3, z * 1e-3) for x, y in grid for z in range(11, 24, 2)])
    n_cyl, n_res = len(cyl), 700
    phi = n_cyl * 4 / 3 * math.pi * r**3 / (math.pi * 0.005**2 * 0.015)
    m = rho_p * 4 / 3 * math.pi * r**3
    w = 10 * m / 0.02
    times = [0.02 * i for i in range(61)]

    def bed(i):
        c = cyl.copy()
        if i > 0:
            c[1::2, 2] = 0.005
        res = np.array([(0.02, 0.0, 0.001 * (k + 1)) for k in range(n_res)])
        res[: 10 * i, 2] = -0.01  # below the orifice
        return np.vstack([c, res])

    for folder, first in (("first", 0), ("restart", 16)):
        names = []
        for j, i in enumerate(range(first, len(times))):
            name = f"particles_{j:06d}"
            snapshot(os.path.join(args.work, folder, name + ".h5"), times[i], 1000 * i, bed(i),
                     np.full(n_cyl + n_res, r), rho_p)
            names.append(name)
        index(os.path.join(args.work, folder), names)
    beverloo = 0.58 * phi * rho_p * math.sqrt(9.81) * (0.012 - 1.5 * 2 * r) ** 2.5
    print(f"reference: solid fraction {phi:.4f}, bulk density {phi * rho_p:.1f} kg/m3, rate "
          f"{1e3 * w:.3f} g/s, Beverloo {1e3 * beverloo:.3f} g/s")

    def numbers(text):
        return (number(r"bulk solid fraction (\S+),", text),
                number(r"measured discharge rate (\S+) g/s", text),
                number(r"Beverloo \(C = 0.58, k = 1.5\) (\S+) g/s", text))

    code, text = run(args, "dem/hopper/analyse.py", "first")
    got = numbers(text)
    # Printed to 3 and 2 decimals: half a unit of the last digit.
    check(code == 0 and abs(got[0] - phi) <= 5e-4 and abs(got[1] - 1e3 * w) <= 5e-3
          and abs(got[2] - 1e3 * beverloo) <= 5e-3 and "(fit over 0.20-1.00 s)" in text,
          f"the series from t = 0: solid fraction {phi:.3f}, {1e3 * w:.2f} g/s, Beverloo "
          f"{1e3 * beverloo:.2f} g/s, fit over 0.20-1.00 s", text)
    code, text = run(args, "dem/hopper/analyse.py", "restart")
    check(code == 1 and "starts at t = 0.32 s" in text and "restart/particles_000000.h5" in text
          and "--bed" in text and "bulk solid fraction" not in text,
          "the series from t = 0.32 s alone: says so, names the file and --bed, no numbers", text)
    code, text = run(args, "dem/hopper/analyse.py", "restart", "--bed",
                     "first/particles_000000.h5")
    got = numbers(text)
    check(code == 0 and abs(got[0] - phi) <= 5e-4 and abs(got[1] - 1e3 * w) <= 5e-3
          and abs(got[2] - 1e3 * beverloo) <= 5e-3
          and "(fit over 0.32-1.00 s; the series starts at 0.32 s)" in text,
          f"--bed: the t = 0 solid fraction {phi:.3f} and Beverloo {1e3 * beverloo:.2f} g/s, the "
          "fit labelled 0.32-1.00 s", text)
    # A part-emptied bed given as the bed (the restarted series' own last snapshot): refused.
    last = sorted(n for n in os.listdir(os.path.join(args.work, "restart"))
                  if n.endswith(".h5"))[-1]
    code, text = run(args, "dem/hopper/analyse.py", "restart", "--bed", f"restart/{last}")
    check(code == 1 and "it is not the settled bed the discharge started from" in text
          and "bulk solid fraction" not in text,
          "--bed with a part-emptied bed: refused, no numbers", text)


def pour_settle_cut_log(args):
    """A log.csv whose last row was cut inside its ke_rot_J field, before the exponent
    ('5.6424819663758342' of 5.64e-05), without a newline (a killed run), and a row at line 6
    with a ';' for a ','. Kinetic energy of the complete rows by construction: 1e-3 (k + 1) +
    1e-5 at t = 0.01 k, k = 0..9 but 4 (line 6 is k = 4): final 1.001e-02 J at t = 0.09 s, the
    peak too. It printed 5.651e+00 J, the cut field read as 5.64 J."""
    out = os.path.join(args.work, "out")
    os.makedirs(out)
    rows = [f"{0.01 * k:.2f},{100 * k},8,{1e-3 * (k + 1):.6e},1.0e-05,0,0,0,0,0.1"
            for k in range(10)]
    rows[4] = rows[4].replace(",", ";", 1)
    with open(os.path.join(out, "log.csv"), "w") as f:
        f.write(LOG_HEADER + "\n" + "\n".join(rows) + "\n0.10,1000,8,2.0e-03,5.6424819663758342")
    x = [(0.01 + 0.005 * i, 0.02, 0.002) for i in range(8)]
    snapshot(os.path.join(out, "particles_000000.h5"), 0.1, 1000, x, np.full(8, 1e-3))
    index(out, ["particles_000000"])
    code, text = run(args, "dem/pour_settle/analyse.py", "out")
    check(code == 0 and "final kinetic energy 1.001e-02 J at t = 0.09 s (peak 1.001e-02 J)"
          in text, "the final and peak kinetic energy of the complete rows, 1.001e-02 J at "
          "0.09 s", text)
    check("out/log.csv:12: row left out: cut short" in text
          and "out/log.csv:6: row left out: 9 fields, not 10 numbers" in text,
          "the cut last row (line 12) and the damaged row (line 6) are named", text)


def run_index_damaged_index(args):
    """particles.xdmf cut short (a power loss) in a folder holding two runs of one scene (the
    same scene_fingerprint): the last run wrote particles_000000-2 (5 beads, steps 0-200, its
    log.csv ends at step 200) over a longer run's 0-4 (7 beads), plus a snapshot of another
    scene and one cut to 100 bytes. tutorials/run_index.py (and pour_settle/analyse.py on it)
    stopped with "cannot read"; now: the last run's three, the damaged index named with its
    remedy, the others named and not used."""
    out = os.path.join(args.work, "out")
    for i in range(5):  # the longer run: 7 beads
        snapshot(os.path.join(out, f"particles_{i:06d}.h5"), 0.01 * i, 100 * i,
                 [(0.01, 0.01, 0.002 + 0.002 * k) for k in range(7)], np.full(7, 1e-3))
    for i in range(3):  # the last run, over the first three: 5 beads
        snapshot(os.path.join(out, f"particles_{i:06d}.h5"), 0.01 * i, 100 * i,
                 [(0.01, 0.01, 0.002 + 0.002 * k) for k in range(5)], np.full(5, 1e-3))
        os.utime(os.path.join(out, f"particles_{i:06d}.h5"), (2e9 + i, 2e9 + i))
    snapshot(os.path.join(out, "particles_000006.h5"), 0.5, 5000, [(0, 0, 0)], [1e-3],
             fingerprint="scene-B")
    with open(os.path.join(out, "particles_000007.h5"), "wb") as f:
        f.write(b"\x89HDF\r\n\x1a\n" + bytes(92))
    with open(os.path.join(out, "log.csv"), "w") as f:
        f.write(LOG_HEADER + "\n" + "".join(f"{0.01 * k:.2f},{100 * k},5,1e-3,1e-5,0,0,0,0,0.1\n"
                                            for k in range(3)))
    index(out, [f"particles_{i:06d}" for i in range(3)])
    with open(os.path.join(out, "particles.xdmf"), "r+") as f:
        f.truncate(180)
    code, text = run(args, "run_index.py", "out")
    listed = [line for line in text.splitlines() if line.startswith("out/")]
    check(code == 0 and listed == [f"out/particles_00000{i}.h5" for i in range(3)],
          "the last run's particles_000000-2", text)
    check("out/particles.xdmf cannot be read (" in text and "A restart (grain run --restart) "
          "from one of the folder's checkpoints before the run's end rewrites the index" in text,
          "the damaged index is named, with its remedy", text)
    check("cannot tell whether 2 snapshot(s) past the end of out/log.csv (step 200" in text
          and "particles_000003.h5, particles_000004.h5" in text,
          "the longer run's 3 and 4, past the end of log.csv, named as not told apart", text)
    check("are left over from other runs (another scene_fingerprint" in text
          and "particles_000006.h5" in text, "the other scene's snapshot is named", text)
    check("cannot be read (damaged or truncated), left out: particles_000007.h5" in text,
          "the truncated snapshot is named as unreadable", text)
    code, text = run(args, "dem/pour_settle/analyse.py", "out")
    check(code == 0 and "settled bed: 5 particles" in text,
          "pour_settle/analyse.py: the last run's last snapshot (5 beads, not 7)", text)


# heatedBed: the well-mixed bed by construction. Beads C_p = 0.05 J/K at 300 K; from t = 0.1 s
# air at T_in = 400 K flows in at Q = 1e-4 m^3/s (rho c_p Q = 0.12 W/K) and leaves at the
# beads' temperature, T_k = (T_{k-1} + dt a T_in) / (1 + dt a), a = rho c_p Q / C_p (the
# implicit Euler step analyse.py integrates its lower bound with); the air's energy stays 15 J.
# E_p + E_f then grows by exactly the enthalpy carried in minus out, step by step.
HEAT_DT, HEAT_END, HEAT_RESTART = 0.001, 0.69, 0.36
ENERGY_LINE = ("grainFoam thermal energy: particles {:.10g} J (m c 0.05 J/K), fluid 15 J "
               "(eps rho c_p V 0.05 J/K), sum {:.10g} J\n")


def heated_bed_case(case):
    rho, cp, q_on, t_in, c_p = 1.2, 1000.0, 1e-4, 400.0, 0.05
    steps = int(round(HEAT_END / HEAT_DT))
    t = HEAT_DT * np.arange(1, steps + 1)
    q = np.where(t > 0.1 + 1e-9, q_on, 0.0)
    temp = np.empty(steps)
    prev = 300.0
    for k in range(steps):
        a = rho * cp * q[k] / c_p
        prev = (prev + HEAT_DT * a * t_in) / (1 + HEAT_DT * a)
        temp[k] = prev
    for name, value in (("inletFlow", -q), ("heatIn", -q * t_in), ("heatOut", q * temp)):
        for start, sel in (("0", t <= HEAT_RESTART + 1e-9), ("0.36", t > HEAT_RESTART + 1e-9)):
            folder = os.path.join(case, "postProcessing", name, start)
            os.makedirs(folder)
            with open(os.path.join(folder, "surfaceFieldValue.dat"), "w") as f:
                f.write("# Area          : 5.40000000e-04\n# Time          \tsum(phi)\n")
                f.writelines(f"{ti:.6g}\t{v:.12e}\n" for ti, v in zip(t[sel], value[sel]))
    os.makedirs(os.path.join(case, "constant"))
    with open(os.path.join(case, "constant", "transportProperties"), "w") as f:
        f.write(f"rho     {rho};\nCp      {cp};\n")
    with open(os.path.join(case, "particles.yaml"), "w") as f:
        f.write("domain: {min: [0, 0, 0], max: [0.06, 0.009, 0.12]}\n")
    snapshot(os.path.join(case, "particles", "particles_000000.h5"), HEAT_END, steps,
             [(0.03, 0.004, 0.01)] * 4, np.full(4, 6e-4), temperature=np.full(4, temp[-1]))
    index(os.path.join(case, "particles"), ["particles_000000"])
    # The logs: energies after the first step and at every write time (0.03 s).
    writes = {0} | {k for k in range(steps) if (k + 1) % 30 == 0}
    restart_k = int(round(HEAT_RESTART / HEAT_DT))  # the restart's first step is restart_k
    first = ["Create time\n", "Starting time loop\n"]
    second = [f"grainFoam coupling: restart at time {HEAT_RESTART} (time index {restart_k}) "
              "from the DEM checkpoint \"particles/checkpoint.h5\"\n", "Starting time loop\n"]
    for k in range(steps):
        lines = [f"Time = {t[k]:.6g}\n", "\n"]
        if k in writes or k == restart_k:
            lines.append(ENERGY_LINE.format(c_p * temp[k], c_p * temp[k] + 15))
        (first if k < restart_k else second).extend(lines)
    with open(os.path.join(case, "log.grainFoam.first"), "w") as f:
        f.writelines(first)
    with open(os.path.join(case, "log.grainFoam"), "w") as f:
        f.writelines(second)
    return temp[-1], c_p * (temp[-1] - 300.0)


def heatedBed_restart_log(args):
    """A coupled run restarted at t = 0.36 s: log.grainFoam is the restart's, the first run's
    log is kept as log.grainFoam.first, postProcessing/ holds 0/ and 0.36/. analyse.py took the
    restart's first energy line as the state at t = 0 and reported FAILED (a 33 % gap); now it
    says that log.grainFoam starts at t = 0.36 s and what to pass, and with --log it checks
    the whole run: the final bead temperature and the energy gained are the construction's,
    the beads sit on the well-mixed bound, and both checks pass."""
    case = os.path.join(args.work, "heat")
    final, gained = heated_bed_case(case)
    print(f"reference: bead temperature {final:.2f} K at {HEAT_END} s, energy gained "
          f"{gained:.4f} J")
    code, text = run(args, "cfd-dem/heatedBed/analyse.py", "--short", case)
    check(code == 1 and "log.grainFoam starts at t = 0.36 s, the log of a restart" in text
          and "--log" in text and "log.grainFoam.first" in text and "FAILED" not in text,
          "the restart's log alone: says it starts at 0.36 s, names --log and the logs", text)
    code, text = run(args, "cfd-dem/heatedBed/analyse.py", "--short", case, "--log",
                     "log.grainFoam.first", "log.grainFoam")
    # Printed to 2 and 4 decimals; the beads are the lower bound itself (0.00 % below it).
    check(code == 0 and abs(number(r"mean bead temperature (\S+) K", text) - final) <= 5e-3
          and abs(number(r"beads and air gained (\S+) J", text) - gained) <= 5e-5
          and "below the lower bound by at most 0.00 %" in text and "FAILED" not in text,
          f"--log both pieces: {final:.2f} K, {gained:.4f} J gained, both checks ok", text)
    code, text = run(args, "cfd-dem/heatedBed/analyse.py", "--short", case, "--log",
                     "log.grainFoam", "log.grainFoam.first")
    check(code == 1 and "starts at t = 0.36 s" in text,
          "--log in the wrong order: the first is the restart's, refused", text)


def ergun_restart_folders(args):
    """A packed-bed run restarted at t = 0.3 s: postProcessing/inletPressure/0/ (to 0.3 s)
    and 0.3/ (to 0.45 s). Construction: 2880 beads of 1 mm on a cubic lattice (12 x 12 x 20 in
    the 12 mm column; bed void fraction 1 - pi/6); kinematic pressure 80/1.2 on the inlet from
    0.15 s and weight/area / 1.2 from 0.25 s: the stages measure 80 Pa and the weight/area,
    N (pi/6) d^3 (2500 - 1.2) 9.81 / (12 mm)^2 = 256.70 Pa, exactly. analyse.py read only
    one folder: nan, FAILED."""
    case = os.path.join(args.work, "ergun")
    d, n_side, layers = 1e-3, 12, 20
    pos = [((i + 0.5) * d, (j + 0.5) * d, (k + 0.5) * d)
           for i in range(n_side) for j in range(n_side) for k in range(layers)]
    snapshot(os.path.join(case, "particles", "particles_000000.h5"), 0.15, 15000, pos,
             np.full(len(pos), d / 2))
    index(os.path.join(case, "particles"), ["particles_000000"])
    weight = len(pos) * math.pi / 6 * d**3 * (2500 - 1.2) * 9.81 / 0.012**2
    t = 0.001 * np.arange(1, 451)
    p = np.where(t > 0.25 + 1e-9, weight, np.where(t > 0.15 + 1e-9, 80.0, 0.0)) / 1.2
    for start, sel in (("0", t <= 0.3 + 1e-9), ("0.3", t > 0.3 + 1e-9)):
        folder = os.path.join(case, "postProcessing", "inletPressure", start)
        os.makedirs(folder)
        with open(os.path.join(folder, "surfaceFieldValue.dat"), "w") as f:
            f.write("# Area            : 1.4400000000e-04\n# Time            \tareaAverage(p)\n")
            f.writelines(f"{ti:.6g}\t{v:.10e}\n" for ti, v in zip(t[sel], p[sel]))
    r = subprocess.run([sys.executable, ERGUN, "--short"], cwd=case, capture_output=True,
                       text=True, timeout=120)
    text = r.stdout + r.stderr
    check("nan" not in text and abs(number(r"U = 0.30 m/s: dp = +(\S+) Pa", text) - 80) <= 5e-3
          and abs(number(r"U = 0.60 m/s: dp = +(\S+) Pa", text) - weight) <= 5e-3,
          f"both folders: the stages measure 80.00 Pa and {weight:.2f} Pa", text)
    check(abs(number(r"weight/area = (\S+) Pa", text) - weight) <= 5e-3
          and "U = 0.60 m/s" in text and re.search(r"U = 0.60 m/s:.*: ok", text) is not None,
          f"the fluidised stage is its weight/area, {weight:.2f} Pa: ok", text)
    # Without the restart's folder the second stage has no data: said, not nan.
    shutil.rmtree(os.path.join(case, "postProcessing", "inletPressure", "0.3"))
    r = subprocess.run([sys.executable, ERGUN, "--short"], cwd=case, capture_output=True,
                       text=True, timeout=120)
    text = r.stdout + r.stderr
    check(r.returncode == 1 and "nan" not in text and "Traceback" not in text
          and "holds no time in 0.33-0.45 s" in text and "to 0.3 s" in text,
          "the restart's folder missing: the empty stage window is named, no nan", text)


CASES = {f.__name__: f for f in (hopper_restarted_folder, pour_settle_cut_log,
                                 run_index_damaged_index, heatedBed_restart_log,
                                 ergun_restart_folders)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", choices=sorted(CASES))
    ap.add_argument("--work", required=True, help="a folder for the files (emptied first)")
    args = ap.parse_args()
    args.work = os.path.abspath(args.work)
    shutil.rmtree(args.work, ignore_errors=True)
    os.makedirs(args.work)
    CASES[args.case](args)
    print(f"{args.case}: {len(failures)} check(s) failed" if failures else f"{args.case}: ok")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
