#!/usr/bin/env python3
"""Two equal spheres settling side by side in a quiescent liquid, in Stokes flow, coarse cells:
the pair falls faster than one sphere alone, by the mutual mobility of two spheres moving
perpendicular to their line of centres.

Reference (Happel & Brenner 1965, Low Reynolds number hydrodynamics, sec. 6.3, method of
reflections; the exact bipolar solution: Goldman, Cox & Brenner 1966, Chem. Eng. Sci. 21:1151):
each sphere of a pair at centre distance l, moving perpendicular to the line of centres, has
the drag 6 pi mu a U lambda with lambda = 1 - (3/4) k + (9/16) k^2 - (59/64) k^3 + O(k^4),
k = a / l; under the same weight the pair settles at U_pair / U_single = 1 / lambda =
1 + (3/4) k + (1/2) k^3 + O(k^4) (the (3/4) k is the other sphere's Stokeslet, the k^3 its
Faxen term).

The spheres are those of settling_cells.py (d = 2 mm, rho_p = 2500, rho_f = 1000, viscosity
for the terminal Reynolds number Re_t, Schiller-Naumann, model B, divided footprint, cell
sampling), placed at the same offset inside their cells. Both runs, the single sphere and
the pair, use the same box; the ratio of their mean settling speeds over the second half of
the fall is compared with 1 / lambda.

Usage: settling_pair.py [--re 0.05] [--cells 1.5] [--spacing 3] [--width 16] [--fall 20]
                        [--correction oseenBrinkman] [--check POINTS] [--work DIR] [--build DIR]
With --check, exit 1 unless |(U_pair/U_single - 1) - (1/lambda - 1)| <= POINTS / 100, the
pair faster than the single sphere, and every run's exchange balanced to 1e-12.
"""
import argparse
import glob
import os
import subprocess
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import settling_cells as sc  # noqa: E402


def mean_speed(case, info, n):
    t, w = [], []
    for f in sorted(glob.glob(os.path.join(case, "particles", "particles_*.h5"))):
        with h5py.File(f, "r") as h5:
            v = h5["velocity"][:]
            if len(v) != n:
                sys.exit(f"settling_pair: {f} holds {len(v)} particles, expected {n}")
            t.append(h5.attrs["time"])
            w.append(-v[:, 2].mean())
    t, w = np.array(t), np.array(w)
    start = info["transient"] / info["u_t"]
    late = t > start + 0.5 * (info["end"] - start)
    return w[late].mean()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--re", type=float, default=0.05)
    ap.add_argument("--cells", type=float, default=1.5, help="cell size in diameters")
    ap.add_argument("--spacing", type=float, default=3.0, help="centre distance l in diameters")
    ap.add_argument("--width", type=int, default=16)
    ap.add_argument("--fall", type=float, default=20)
    ap.add_argument("--courant", type=float, default=0.05)
    ap.add_argument("--correction", default="oseenBrinkman")
    ap.add_argument("--check", type=float, default=None)
    ap.add_argument("--work", default="/tmp/settling_pair")
    ap.add_argument("--build", default=os.path.join(sc.ROOT, "build"))
    a = ap.parse_args()
    correction = None if a.correction == "off" else a.correction
    k = 0.5 / a.spacing
    expected = 1 / (1 - 0.75 * k + 9 / 16 * k**2 - 59 / 64 * k**3)
    speeds, worst = {}, 0.0
    for n in (1, 2):
        case = os.path.join(a.work, f"re{a.re:g}_n{a.cells:g}_l{a.spacing:g}_{a.correction}_{n}")
        subprocess.call(["rm", "-rf", case])
        info = sc.make_case(case, a.cells, a.re, a.width, a.fall, "divided", "cell", correction,
                            a.courant)
        h = info["h"]
        # settling_cells puts the single sphere a quarter cell off the box's centre line; the
        # pair sits at +-l/2 about that point along x, each at the same place in its cell when
        # l/2 is a whole number of cells.
        with open(os.path.join(case, "particle.csv")) as f:
            _, row = f.read().split("\n")[:2]
        x0, y0, z0, r = (float(v) for v in row.split(","))
        xs = [x0] if n == 1 else [x0 - 0.5 * a.spacing * sc.D, x0 + 0.5 * a.spacing * sc.D]
        with open(os.path.join(case, "particle.csv"), "w") as f:
            f.write("x,y,z,radius\n")
            for x in xs:
                f.write(f"{x:.12g},{y0:.12g},{z0:.12g},{r}\n")
        if n == 2:  # two particles need contact properties (they never touch: l > d)
            with open(os.path.join(case, "particles.yaml"), "a") as f:
                f.write("contact: {normal: hertz}\n"
                        "interaction_defaults: {restitution: 0.5, friction: 0.5}\n")
        cpu, imbalance = sc.run(case, a.build)
        worst = max(worst, imbalance)
        speeds[n] = mean_speed(case, info, n)
        print(f"settling_pair: {n} sphere(s), Re_t {a.re:g}, cells {a.cells:g} d, "
              f"correction {a.correction}: settling speed {speeds[n] / info['u_t']:.4f} u_t, "
              f"{cpu:.0f} s, exchange imbalance {imbalance:.1e}", flush=True)
    ratio = speeds[2] / speeds[1]
    print(f"settling_pair: l = {a.spacing:g} d: U_pair / U_single = {ratio:.4f}, "
          f"Happel & Brenner 1 / lambda = {expected:.4f} (difference "
          f"{100 * (ratio - expected):+.2f} points)")
    if a.check is not None:
        ok = abs(ratio - expected) <= a.check / 100 and ratio > 1 and worst <= 1e-12
        print(f"settling_pair: within {a.check:g} points, faster than one sphere, exchange "
              f"balanced to 1e-12: {'ok' if ok else 'FAILED'}")
        sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
