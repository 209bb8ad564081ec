#!/usr/bin/python3
"""Reads the DPMFoam and grainFoam runs of run.sh, checks that both simulated the same thing
and prints the table of docs/performance.md ("grainFoam against DPMFoam (Goldschmidt)").

    compare.py OUTPUT_DIR            (OUTPUT_DIR holds cases/setup.json and runs/<code>_<round>)

Exit status 0 when the case `grainfoam` (the coupling matched to DPMFoam's) passes every check.

Cost: OpenFOAM's ExecutionTime (process CPU time) and ClockTime (wall time) of the fluid step
at `startup` and at `end_time`: the time per simulated second after start-up; /usr/bin/time's
user + system CPU time and peak memory of the whole run. Medians over the rounds.

Same thing (each round's grainFoam run against the same round's DPMFoam run):
- the change of the particles' mean height from t = 0 to end_time, within 5 %;
- the particles' mean vertical velocity at end_time, within 5 %;
- the bed pressure drop rho_f (p_bottom - p_top), hydrostatics removed, averaged over
  [startup, end_time], within 10 % (the drag laws' split between drag and pressure-gradient
  force differs: docs/performance.md).
DPMFoam's mean velocity is its logged linear momentum over its mass (every step); its mean
height is the initial one plus the time integral of that velocity. grainFoam's come from its
particle snapshots (particles/particles_*.h5).
"""
import glob
import json
import re
import statistics
import sys
from pathlib import Path

import h5py
import numpy as np


def steps(log):
    """(time, ExecutionTime, ClockTime) of every fluid step in an OpenFOAM log."""
    out, t = [], None
    for line in log.splitlines():
        if line.startswith("Time = "):
            t = float(line.split()[2])
        elif line.startswith("ExecutionTime = ") and t is not None:
            w = line.split()
            out.append((t, float(w[2]), float(w[6])))
    return out


def at(series, t):
    """The entry of series whose time is closest to t."""
    return min(series, key=lambda s: abs(s[0] - t))


def cost(log, setup):
    s = steps(log)
    if not s or abs(s[-1][0] - setup["end_time"]) > 1e-9:
        raise RuntimeError("the run did not reach end_time")
    a, b = at(s, setup["startup"]), s[-1]
    span = b[0] - a[0]
    return (b[1] - a[1]) / span, (b[2] - a[2]) / span


def gnu_time(path):
    user, system, wall, rss = Path(path).read_text().split()[-4:]
    return float(user) + float(system), float(wall), float(rss) / 1024


def bed_pressure(case, setup, hydrostatic):
    dat = glob.glob(f"{case}/postProcessing/pBottom/0/surfaceFieldValue.dat")
    rows = np.loadtxt(dat[0], comments="#")
    g = abs(setup["g"][2])
    height = setup["domain"][1][2] - setup["domain"][0][2]
    dp = setup["rho_f"] * (rows[:, 1] - (g * height if hydrostatic else 0.0))
    keep = rows[:, 0] >= setup["startup"] - 1e-12
    return float(np.mean(dp[keep]))


def dpm_motion(log, setup, z0):
    t, vz = [0.0], [0.0]
    time = None
    for line in log.splitlines():
        if line.startswith("Time = "):
            time = float(line.split()[2])
        elif "Current mass in system" in line:
            mass = float(line.split("=")[1])
        elif line.strip().startswith("Linear momentum") and time is not None:
            pz = float(line.split("(")[1].split(")")[0].split()[2])
            t.append(time)
            vz.append(pz / mass)
    t, vz = np.array(t), np.array(vz)
    z = z0 + np.concatenate(([0.0], np.cumsum(0.5 * (vz[1:] + vz[:-1]) * np.diff(t))))
    return t, z, vz


def grain_motion(case):
    rows = []
    for s in glob.glob(f"{case}/particles/particles_*.h5"):
        with h5py.File(s, "r") as f:
            m = f["mass"][:]
            rows.append((float(f.attrs["time"]), np.average(f["position"][:, 2], weights=m),
                         np.average(f["velocity"][:, 2], weights=m), len(m)))
    return sorted(rows)


def time_split(log):
    """The cumulative 'grainFoam time split' lines: (time, DEM, coupling, fluid, particle
    output) seconds. The particle output (snapshots, checkpoints) is logged apart since
    commit "time split: particle output apart"; older logs counted it in the coupling and
    give 0 here."""
    out, t = [], None
    pat = re.compile(r"grainFoam time split: DEM ([\d.e+-]+) s .*coupling ([\d.e+-]+) s .*"
                     r"fluid ([\d.e+-]+) s[^;]*(?:; particle output ([\d.e+-]+) s)?")
    for line in log.splitlines():
        if line.startswith("Time = "):
            t = float(line.split()[2])
        m = pat.search(line)
        if m:
            out.append((t, *(float(g) if g is not None else 0.0 for g in m.groups())))
    return out


def main():
    root = Path(sys.argv[1])
    setup = json.loads((root / "cases/setup.json").read_text())
    codes = setup["codes"]  # dpmfoam first, then the grainFoam cases
    positions = np.loadtxt(root / "cases/grainfoam/particles.csv", delimiter=",", skiprows=2)
    z0 = float(np.mean(positions[:, 2]))
    rounds = sorted({int(p.name.rsplit("_", 1)[1]) for p in (root / "runs").glob("*_*")})
    cols = {(c, k): [] for c in codes
            for k in ("cpu", "wall", "total", "rss", "dem", "coupling", "fluid",
                      "coupling_output")}
    ok = {c: True for c in codes[1:]}
    for r in rounds:
        runs = {c: root / f"runs/{c}_{r}" for c in codes}
        logs = {c: d / ("log.DPMFoam" if c == "dpmfoam" else "log.grainFoam")
                for c, d in runs.items()}
        if not all(log.exists() and (runs[c] / "time.txt").exists() for c, log in logs.items()):
            print(f"round {r}: incomplete, skipped")
            continue
        text = {c: log.read_text() for c, log in logs.items()}
        for c in codes:
            cpu, wall = cost(text[c], setup)
            total, _, rss = gnu_time(runs[c] / "time.txt")
            for k, v in (("cpu", cpu), ("wall", wall), ("total", total), ("rss", rss)):
                cols[(c, k)].append(v)
            if c == "dpmfoam":
                continue
            split = time_split(text[c])
            first = next(s for s in split if s[0] >= setup["startup"] - 1e-12)
            diff = [b - a for a, b in zip(first[1:], split[-1][1:])]
            for k, v in zip(("dem", "coupling", "fluid"), diff[:3]):
                cols[(c, k)].append(100 * v / sum(diff[:3]))
            # The share the coupling would have with the particle output counted in it.
            cols[(c, "coupling_output")].append(100 * (diff[1] + diff[3]) / sum(diff))

        t, z, vz = dpm_motion(text["dpmfoam"], setup, z0)
        dp_d = bed_pressure(runs["dpmfoam"], setup, True)
        for c in codes[1:]:
            snaps = grain_motion(runs[c])
            end = snaps[-1]
            if abs(end[0] - setup["end_time"]) > 1e-9 or end[3] != setup["particles"]:
                raise RuntimeError(f"{runs[c]}: last snapshot at {end[0]} with {end[3]} particles")
            print(f"round {r}, {c}: mean height at t = 0 {1e3 * z0:.3f} mm\n"
                  "    t [s]    change of the mean height [mm]  mean v_z [mm/s]\n"
                  "             DPMFoam   grainFoam             DPMFoam  grainFoam")
            for ts, zg, vg, _ in snaps:
                i = int(np.argmin(abs(t - ts)))
                print(f"    {ts:.4f}   {1e3 * (z[i] - z0):8.4f}  {1e3 * (zg - z0):8.4f}"
                      f"           {1e3 * vz[i]:9.3f}  {1e3 * vg:9.3f}")
            i = int(np.argmin(abs(t - end[0])))
            dp_g = bed_pressure(runs[c], setup, False)
            checks = [("change of the mean height [m]", z[i] - z0, end[1] - z0, 0.05),
                      ("mean v_z at the end [m/s]", vz[i], end[2], 0.05),
                      ("bed pressure drop, mean after start-up [Pa]", dp_d, dp_g, 0.10)]
            for name, a, b, tol in checks:
                rel = (b - a) / abs(a)
                good = abs(rel) <= tol
                ok[c] &= good
                print(f"    {name}: DPMFoam {a:.5g}, grainFoam {b:.5g}, difference "
                      f"{100 * rel:+.1f} % (tolerance {100 * tol:.0f} %: {'ok' if good else 'FAIL'})")

    med = {key: statistics.median(v) for key, v in cols.items() if v}
    n = len(cols[("dpmfoam", "cpu")])
    if n == 0:
        sys.exit("compare.py: no complete round")
    print(f"\n{setup['particles']} spheres, fluid step {setup['dt_fluid']:g} s, grainFoam DEM step "
          f"{setup['dt_dem']:.3g} s; window {setup['startup']}-{setup['end_time']} s; "
          f"medians of {n} interleaved round(s)\n")
    print("| run | CPU s per simulated s | wall s per simulated s | DPMFoam / this (CPU) | "
          "CPU s, whole run | peak memory | time split DEM / coupling / fluid |")
    print("|---|---:|---:|---:|---:|---:|---|")
    ref = med[("dpmfoam", "cpu")]
    for c in codes:
        split = "" if c == "dpmfoam" else (
            f"{med[(c, 'dem')]:.0f} % / {med[(c, 'coupling')]:.0f} % / {med[(c, 'fluid')]:.0f} %")
        print(f"| {c} | {med[(c, 'cpu')]:.0f} | {med[(c, 'wall')]:.0f} | "
              f"{ref / med[(c, 'cpu')]:.1f}x | {med[(c, 'total')]:.1f} | "
              f"{med[(c, 'rss')]:.0f} MB | {split} |")
    print("\nper round, CPU s per simulated s: " + "; ".join(
        f"{c} " + ", ".join(f"{v:.0f}" for v in cols[(c, 'cpu')]) for c in codes))
    print("per round, coupling share (wall clock, after start-up): " + "; ".join(
        f"{c} " + ", ".join(f"{v:.1f} %" for v in cols[(c, 'coupling')]) for c in codes[1:]))
    print("per round, coupling share with the particle output (snapshots, checkpoints) counted "
          "as coupling: " + "; ".join(
              f"{c} " + ", ".join(f"{v:.1f} %" for v in cols[(c, 'coupling_output')])
              for c in codes[1:]))
    print("same simulation as DPMFoam (every check of every round within tolerance): " + ", ".join(
        f"{c} {'yes' if good else 'NO'}" for c, good in ok.items()))
    return 0 if ok["grainfoam"] else 1


if __name__ == "__main__":
    sys.exit(main())
