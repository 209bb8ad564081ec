#!/usr/bin/env python3
"""Coarse-grained parcels discharging from a flat-bottomed bin (issue 23, validation 3).

A DEM-only check of the energy-conserving parcel scaling (Bierwisch et al. 2009) against
Beverloo's correlation and against the real particles. The same real material (glass beads,
radius uniform 0.9-1.1 mm, mean d = 2.0 mm, Young's modulus lowered to 10 MPa as in the
`tutorials/dem/hopper` case) and the same real mass (N_REAL = 19 656 beads = 2457 x 2^3 =
728 x 3^3) fill a cylindrical bin of diameter 72 mm (a `cylinder` wall, steel) with a flat
floor (a triangle-mesh annulus written by this script) and a central circular orifice of
D0 = 36 mm = 18 d: 9 parcel diameters at k = 2 and 6 at k = 3, above the orifice of about
5 sphere diameters below which a 3D silo jams by arching (Zuriguel et al. 2005, Phys. Rev. E
71:051303). Two stages per k:

1. fill: the parcels (count N_REAL / k^3, radius k r) are placed at random in 2-102 mm and
   settle for FILL_END s on a plane (the gate) that closes the orifice;
2. discharge: a new scene continues from the settled snapshot without the gate for
   DISCHARGE_END s; parcels falling below z = -20 mm leave the domain.

The rate W is the slope of the real mass above the orifice (z > 0) against time, fitted while
that mass falls from FIT_FROM to FIT_TO of the initial mass (flow established, the bed not
yet drained to the orifice). Reference: Beverloo, Leniger & van de Velde (1961, Chem. Eng.
Sci. 15:260), W = C rho_b sqrt(g) (D0 - k_B d)^(5/2), C = 0.58, k_B = 1.5 (Nedderman 1992,
Statics and Kinematics of Granular Materials, sec. 10.2), with the REAL mean diameter d and
the bulk density rho_b measured in the core of the settled k = 1 bed (RHO_B_K1; the script
also prints each k's own core value). Beverloo with the PARCEL diameter k d is printed too:
the empty annulus k_B d is a particle-scale effect, and the parcels do flow at about that
rate. The corrected rate W x Bev(d) / Bev(k d) puts the annulus back to the real size.

The bin is a compromise for the budget (k = 1 under 20 000 beads): D_bin = 2 D0 (Mankoc et
al. 2007, Granular Matter 9:407, ask for > 2.5 D0 and > D0 + 30 d for a rate independent of
the bin) and a bed about D0 deep (da Silva et al. 2025, arXiv:2512.03698, find Beverloo's
constant rate above h = 2 D0), so the beads themselves flow below Beverloo's rate and the rate
falls as the bed drains.

With --seeds N each k is filled N times (fill seeds 1..N) and W is the mean of the N rates:
one fill's rate is a sample, not the rate (at k = 3, six fills gave 244-337 g/s, a standard
deviation of 10 %; at k = 2, 347-368 g/s, 2.3 %), since a few hundred parcels through an
orifice of 6 parcel diameters flow in bursts.

Checks with --check TOL (the CTest short form, --ks 2,3 --seeds 3): each k's corrected rate within TOL
of the beads' rate (W_K1, measured by this script at k = 1; with k = 1 in --ks, that run's);
real mass conserved: every parcel's snapshot coarse_grain = k, real_count = k^3 and mass =
k^3 rho pi (2 r/k)^3 / 6 (to 1e-12), the real mass in the domain + that of the parcels
removed (identified by id between snapshots) = the settled bed's real mass at every snapshot
(to 1e-12), the number removed = the log's `removed` column, and parcels x k^3 = N_REAL.

usage: hopper.py [--ks 1,2,3] [--work DIR] [--grain PATH] [--check TOL [--check-k 2]]
                 [--analyse-only]
Prints one row per k (rate, error against Beverloo with d and with k d, against k = 1, the
corrected rate, process CPU seconds of each stage) and appends them to <work>/hopper.csv.
"""
import argparse
import csv
import glob
import math
import os
import resource
import subprocess
import sys
import time

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
N_REAL = 19656
R_MIN, R_MAX = 0.9e-3, 1.1e-3
D_MEAN = R_MIN + R_MAX
RHO_P = 2500.0
D0 = 0.036
R_BIN = 0.036
FILL_END = 0.35
DISCHARGE_END = 0.3
SNAP = 0.01
FIT_FROM, FIT_TO = 0.85, 0.5
C_BEV, K_BEV, G = 0.58, 1.5, 9.81
# Bulk density of the settled real (k = 1) bed: solid volume of the centres in the core
# cylinder r < CORE_R, CORE_Z over its volume, times rho_p (measured by this script, k = 1).
CORE_R, CORE_Z = 0.024, (0.006, 0.026)
RHO_B_K1 = 1500.0  # solid fraction 0.600
# The real beads' (k = 1) rate measured by this script (seed 1), for the "vs k = 1" columns of a
# run without k = 1.
W_K1 = 0.4824
SEGMENTS = 72


def write_floor(path):
    """A flat annulus at z = 0 from the orifice (radius D0/2) to beyond the bin wall."""
    r0, r1 = D0 / 2, R_BIN + 0.002

    def p(r, j):
        a = 2 * math.pi * (j % SEGMENTS) / SEGMENTS
        return (r * math.cos(a), r * math.sin(a), 0.0)

    with open(path, "w") as f:
        f.write("solid floor\n")
        for j in range(SEGMENTS):
            a, b, c, d = p(r0, j), p(r0, j + 1), p(r1, j + 1), p(r1, j)
            for tri in ((a, b, c), (a, c, d)):
                f.write("  facet normal 0 0 1\n    outer loop\n")
                for v in tri:
                    f.write("      vertex %.17g %.17g %.17g\n" % v)
                f.write("    endloop\n  endfacet\n")
        f.write("endsolid floor\n")


def common(k, end):
    return f"""domain:
  min: [-0.04, -0.04, -0.02]
  max: [0.04, 0.04, 0.11]
gravity: [0, 0, -9.81]
time:
  rayleigh_fraction: 0.2
  end: {end}
  expected_max_speed: 1.5
materials:
  - {{name: glass, youngs_modulus: 1e7, poisson_ratio: 0.25, density: {RHO_P}}}
  - {{name: steel, youngs_modulus: 4e7, poisson_ratio: 0.3, density: 7800}}
interactions:
  - {{materials: [glass, glass], restitution: 0.5, friction: 0.5}}
  - {{materials: [glass, steel], restitution: 0.6, friction: 0.3}}
  - {{materials: [steel, steel], restitution: 0.6, friction: 0.3}}
contact:
  normal: hertz
  tangential: history
"""


def fill_scene(k, seed=1):
    cg = f"\n    coarse_grain: {k}" if k != 1 else ""
    return common(k, FILL_END) + f"""walls:
  - {{type: cylinder, name: bin, axis_point: [0, 0, 0], axis: [0, 0, 1], radius: {R_BIN}, material: steel}}
  - {{type: mesh, name: floor, file: floor.stl, material: steel}}
  - {{type: plane, name: gate, point: [0, 0, 0], normal: [0, 0, 1], material: steel}}
insert:
  - type: fill
    region: {{cylinder: {{base: [0, 0, 0.002], axis: [0, 0, 1], radius: {R_BIN - k * R_MAX - 2e-4:.6g}, height: 0.1}}}}
    count: {N_REAL // k**3}
    material: glass
    radius: {{distribution: uniform, min: {R_MIN}, max: {R_MAX}}}
    seed: {seed}{cg}
output:
  directory: fill
  snapshot_interval: {FILL_END}
  log_interval: 0.01
"""


def discharge_scene(k):
    # The settled snapshot carries its parcel class glass[k=k] (root attributes
    # material_coarse_grain, material_real): the discharge scene gets the same class from it.
    return common(k, DISCHARGE_END) + f"""walls:
  - {{type: cylinder, name: bin, axis_point: [0, 0, 0], axis: [0, 0, 1], radius: {R_BIN}, material: steel}}
  - {{type: mesh, name: floor, file: floor.stl, material: steel}}
insert:
  - {{type: snapshot, file: settled.h5}}
output:
  directory: discharge
  snapshot_interval: {SNAP}
  log_interval: {SNAP}
"""


def run(grain, case, scene):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    wall = time.time()
    with open(os.path.join(case, scene.replace(".yaml", ".log")), "w") as log:
        rc = subprocess.call([grain, "run", scene], cwd=case, stdout=log, stderr=subprocess.STDOUT)
    if rc != 0:
        sys.exit(f"hopper: {grain} run {scene} failed in {case} (exit {rc}); see its .log")
    with open(os.path.join(case, scene.replace(".yaml", ".log"))) as log:
        if not any(line.startswith("done: ") for line in log):
            sys.exit(f"hopper: {grain} run {scene} in {case} did not reach its end "
                     f"(a SIGTERM or SIGINT stops it with exit 0 after a checkpoint: 'stopped:'); see its .log")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, time.time() - wall


def real_mass(f, k):
    """Checks each parcel's k, k^3 and mass; returns (position, mass, ids)."""
    r = f["radius"][:]
    m = f["mass"][:]
    if k == 1 and "coarse_grain" not in f:  # a scene without parcels writes neither field
        cg, cnt = np.ones_like(r), np.ones_like(r)
    else:
        cg, cnt = f["coarse_grain"][:], f["real_count"][:]
    if len(r) and (np.max(np.abs(cg - k)) > 0 or np.max(np.abs(cnt - k**3)) > 0):
        sys.exit(f"hopper: k = {k}: a parcel's coarse_grain/real_count is not {k}/{k**3}")
    expect = k**3 * RHO_P * math.pi / 6 * (2 * r / k) ** 3
    if len(r) and np.max(np.abs(m / expect - 1)) > 1e-12:
        sys.exit(f"hopper: k = {k}: a parcel's mass is not k^3 real masses")
    return f["position"][:], m, f["id"][:]


def particle_steps(logcsv):
    """Steps x particles summed over the log's intervals: the cost, independent of the load."""
    with open(logcsv) as f:
        rows = list(csv.DictReader(f))
    return sum((int(b["step"]) - int(a["step"])) * int(a["particles"]) for a, b in zip(rows, rows[1:]))


def removed_column(logcsv):
    with open(logcsv) as f:
        rows = list(csv.DictReader(f))
    return int(float(rows[-1]["removed"]))


def analyse(case, k):
    files = sorted(glob.glob(os.path.join(case, "discharge", "particles_*.h5")))
    t, above, problems = [], [], []
    with h5py.File(os.path.join(case, "settled.h5"), "r") as f:
        x, m0, _ = real_mass(f, k)
        r = f["radius"][:]
    total = float(m0.sum())
    parcels = len(m0)
    if parcels * k**3 != N_REAL:
        problems.append(f"parcels x k^3 = {parcels * k**3} != {N_REAL}")
    inside = (np.hypot(x[:, 0], x[:, 1]) < CORE_R) & (x[:, 2] > CORE_Z[0]) & (x[:, 2] < CORE_Z[1])
    phi = float((4 / 3 * math.pi * r[inside] ** 3).sum() / (math.pi * CORE_R**2 * (CORE_Z[1] - CORE_Z[0])))
    top = float(np.percentile(x[:, 2], 99))
    mass_of, gone_mass, worst = {}, 0.0, 0.0
    for name in files:
        with h5py.File(name, "r") as f:
            pos, m, ids = real_mass(f, k)
            tt = float(f.attrs["time"])
        present = dict(zip(ids.tolist(), m.tolist()))
        for i in list(mass_of):
            if i not in present:
                gone_mass += mass_of.pop(i)
        mass_of.update(present)
        t.append(tt)
        above.append(float(m[pos[:, 2] > 0].sum()))
        worst = max(worst, abs(sum(present.values()) + gone_mass - total) / total)
    removed_ids = N_REAL // k**3 - len(mass_of)
    removed_log = removed_column(os.path.join(case, "discharge", "log.csv"))
    if removed_ids != removed_log:
        problems.append(f"{removed_ids} parcels gone from the snapshots, log.csv says {removed_log}")
    if worst > 1e-12:
        problems.append(f"real mass not conserved: worst relative defect {worst:.2e}")
    t, above = np.array(t), np.array(above)
    first = above[0]
    win = (above <= FIT_FROM * first) & (above >= FIT_TO * first)
    if win.sum() < 4:
        problems.append(f"only {win.sum()} snapshots in the fit window")
        w = float("nan")
    else:
        w = -np.polyfit(t[win], above[win], 1)[0]
    work = sum(particle_steps(os.path.join(case, stage, "log.csv")) for stage in ("fill", "discharge"))
    return dict(k=k, parcels=parcels, particle_steps=work, t=t, above=above, real_mass=total, phi=phi, rho_b=phi * RHO_P,
                top=top, w=w,
                t_from=float(t[win].min()) if win.any() else float("nan"),
                t_to=float(t[win].max()) if win.any() else float("nan"),
                mass_defect=worst, removed=removed_log, problems=problems)


def beverloo(rho_b, d):
    return C_BEV * rho_b * math.sqrt(G) * (D0 - K_BEV * d) ** 2.5


def plot(rows, rho_b, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for i, r in enumerate(rows):
        k = r["k"]
        ax.plot(r["t"], 1e3 * r["above"], "o-", ms=3, color=f"C{i}",
                label=f"k = {k} ({r['parcels']} parcels): W = {1e3 * r['w']:.0f} g/s")
        t0 = r["t_from"]
        m0 = float(np.interp(t0, r["t"], r["above"]))
        span = np.array([t0, t0 + 0.2])
        if k != 1:
            ax.plot(span, 1e3 * (m0 - beverloo(rho_b, k * D_MEAN) * (span - t0)), ":", color=f"C{i}", lw=1.2,
                    label=f"Beverloo with the parcel size {1e3 * k * D_MEAN:.0f} mm")
        if i == 0:
            ax.plot(span, 1e3 * (m0 - beverloo(rho_b, D_MEAN) * (span - t0)), "k--", lw=1,
                    label=f"Beverloo with the real size {1e3 * D_MEAN:.0f} mm")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("real mass above the orifice [g]")
    ax.set_title(f"Flat-bottomed bin, D0 = {1e3 * D0:.0f} mm, real d = {1e3 * D_MEAN:.0f} mm")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"{path} written")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ks", default="1,2,3")
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "benchmarks", "coarse_grain_hopper"))
    build = os.environ.get("GRAINFLOW_BUILD_DIR", os.path.join(ROOT, "build"))
    ap.add_argument("--grain", default=os.path.join(build, "bin", "grain"))
    ap.add_argument("--check", type=float, default=None,
                    help="fail unless the rate of each k in --check-k, corrected for Beverloo's annulus "
                         "(x Bev(d)/Bev(k d)), is within this fraction of the k = 1 rate")
    ap.add_argument("--check-beverloo", type=float, default=None,
                    help="fail unless each k's rate is within this fraction of Beverloo's correlation "
                         "evaluated with the parcel diameter k d and that run's own measured bulk density")
    ap.add_argument("--check-k", default=None, help="the ks whose rate --check tests (default: all)")
    ap.add_argument("--analyse-only", action="store_true", help="analyse the runs already in --work")
    ap.add_argument("--plot", default=None, help="write the real mass above the orifice against time to this PNG")
    ap.add_argument("--seeds", type=int, default=1,
                    help="fills per k (fill seeds 1..N): W is their mean, and the checks test the mean")
    a = ap.parse_args()
    a.grain = os.path.abspath(a.grain)  # the runs' working directory is each case
    ks = [int(s) for s in a.ks.split(",")]
    os.makedirs(a.work, exist_ok=True)
    rows = []
    for k in ks:
        seeds = []
        for seed in range(1, a.seeds + 1):
            case = os.path.abspath(os.path.join(a.work, f"k{k}" + (f"_s{seed}" if seed > 1 else "")))
            cpu_fill = cpu_dis = wall = 0.0
            if not a.analyse_only:
                os.makedirs(case, exist_ok=True)
                for old in glob.glob(os.path.join(case, "*", "particles_*.h5")):
                    os.remove(old)
                write_floor(os.path.join(case, "floor.stl"))
                open(os.path.join(case, "fill.yaml"), "w").write(fill_scene(k, seed))
                open(os.path.join(case, "discharge.yaml"), "w").write(discharge_scene(k))
                cpu_fill, w1 = run(a.grain, case, "fill.yaml")
                last = sorted(glob.glob(os.path.join(case, "fill", "particles_*.h5")))[-1]
                os.replace(last, os.path.join(case, "settled.h5"))
                cpu_dis, w2 = run(a.grain, case, "discharge.yaml")
                wall = w1 + w2
            one = analyse(case, k)
            one.update(cpu_fill=cpu_fill, cpu_discharge=cpu_dis, wall=wall)
            seeds.append(one)
        # The first fill's run stands for the k (its curve, bulk density, top); the rate is the
        # mean over the fills, the costs their sums, the problems every fill's.
        row = dict(seeds[0])
        ws = [r["w"] for r in seeds]
        row["w"] = float(np.mean(ws))
        row["w_seeds"] = ws
        row["problems"] = [p for r in seeds for p in r["problems"]]
        for key in ("cpu_fill", "cpu_discharge", "wall", "particle_steps"):
            row[key] = sum(r[key] for r in seeds)
        rows.append(row)
    rho_b = RHO_B_K1
    w1 = next((r["w"] for r in rows if r["k"] == 1), W_K1)
    print(f"Beverloo: C = {C_BEV}, k_B = {K_BEV}, D0 = {1e3 * D0:.0f} mm, rho_b = {rho_b:.0f} kg/m3 "
          f"(k = 1 core), real d = {1e3 * D_MEAN:.1f} mm: W = {1e3 * beverloo(rho_b, D_MEAN):.1f} g/s")
    print("k parcels real_mass[g] rho_b_core top[mm] W[g/s] vs_Bev(d) Bev(kd)[g/s] vs_Bev(kd) vs_k1 "
          "W_corr[g/s] corr_vs_k1 fit[s] particle_steps cpu_fill[s] cpu_discharge[s] wall[s]")
    failed = []
    with open(os.path.join(a.work, "hopper.csv"), "a", newline="") as out:
        wr = csv.writer(out)
        for r in rows:
            k = r["k"]
            bev, bev_k = beverloo(rho_b, D_MEAN), beverloo(rho_b, k * D_MEAN)
            err, err_k = r["w"] / bev - 1, r["w"] / bev_k - 1
            corrected = r["w"] * bev / bev_k  # Beverloo's annulus put back to the real d
            vs1 = f"{100 * (r['w'] / w1 - 1):+.1f}%" if w1 else "-"
            cvs1 = f"{100 * (corrected / w1 - 1):+.1f}%" if w1 else "-"
            print(f"{k} {r['parcels']} {1e3 * r['real_mass']:.2f} {r['rho_b']:.0f} {1e3 * r['top']:.1f} "
                  f"{1e3 * r['w']:.1f} {100 * err:+.1f}% {1e3 * bev_k:.1f} {100 * err_k:+.1f}% {vs1} "
                  f"{1e3 * corrected:.1f} {cvs1} "
                  f"{r['t_from']:.2f}-{r['t_to']:.2f} {r['particle_steps']:.3g} "
                  f"{r['cpu_fill']:.1f} {r['cpu_discharge']:.1f} {r['wall']:.0f}")
            print(f"  k = {k}: real mass conserved to {r['mass_defect']:.1e}, {r['removed']} parcels removed "
                  f"({r['removed'] * k**3} real beads)")
            if len(r["w_seeds"]) > 1:
                spread = float(np.std(r["w_seeds"], ddof=1))
                print(f"  k = {k}: W of the {len(r['w_seeds'])} fills "
                      f"{', '.join(f'{1e3 * w:.1f}' for w in r['w_seeds'])} g/s: mean {1e3 * r['w']:.1f}, "
                      f"standard deviation {1e3 * spread:.1f} g/s ({100 * spread / r['w']:.1f} %)")
            if not a.analyse_only:
                wr.writerow([time.strftime("%Y-%m-%dT%H:%M:%S"), k, r["parcels"], r["real_mass"], r["rho_b"],
                             r["w"], err, err_k, corrected, r["particle_steps"], r["cpu_fill"],
                             r["cpu_discharge"], r["wall"]])
            failed += [f"k = {k}: {p}" for p in r["problems"]]
            rate_checked = a.check_k is None or k in [int(x) for x in a.check_k.split(",")]
            if a.check is not None and rate_checked and not abs(corrected / w1 - 1) <= a.check:
                failed.append(f"k = {k}: W {1e3 * r['w']:.1f} g/s, corrected {1e3 * corrected:.1f} g/s, is "
                              f"{100 * (corrected / w1 - 1):+.1f}% from the beads' {1e3 * w1:.1f} g/s "
                              f"(tolerance {100 * a.check:.0f}%)")
            if a.check_beverloo is not None:
                own = beverloo(r["rho_b"], k * D_MEAN)  # independent of every other run
                print(f"  k = {k}: W / Beverloo(k d, own rho_b {r['rho_b']:.0f} kg/m3 = {1e3 * own:.1f} g/s) "
                      f"- 1 = {100 * (r['w'] / own - 1):+.1f}%")
                if not abs(r["w"] / own - 1) <= a.check_beverloo:
                    failed.append(f"k = {k}: W {1e3 * r['w']:.1f} g/s is {100 * (r['w'] / own - 1):+.1f}% from "
                                  f"Beverloo with the parcel size ({1e3 * own:.1f} g/s; tolerance "
                                  f"{100 * a.check_beverloo:.0f}%)")
    if a.plot:
        plot(rows, rho_b, a.plot)
    for f in failed:
        print("FAIL:", f)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
