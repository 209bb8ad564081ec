#!/usr/bin/env python3
"""Random hard scenes for `grain run`, each checked against invariants (docs/stability.md).

    hard_scenes.py --grain build/bin/grain [--mpiexec mpiexec] --seeds 0:40
    hard_scenes.py --grain build/bin/grain --seed 17          # one scene, reproducibly
    hard_scenes.py --grain build/bin/grain --seeds 0:16,608   # ranges and single seeds
    hard_scenes.py --grain build/bin/grain --first 1000 --count 400 --budget 1200
    hard_scenes.py --grain build/bin/grain --seeds 0:24 --jobs 2  # seeds side by side, 2 cores

Each seed draws one valid scene (numbers from Python's seeded `random.Random(seed)`, so a
seed is the same scene on every machine): sizes over a ratio up to 100 and densities up to
1000 within a scene, Young's modulus over 1e5..1e11 Pa (Hooke stiffness 1e1..1e7 N/m), all 24
contact-slot combinations (normal x tangential x rolling x cohesion; seeds 0..23 hold each once),
planes, cylinders inside and outside, STL meshes written next to the scene, moving walls,
periodic axes, 1 or 2 ranks, one-way fluid with every drag law and force term, streams, CSV
particles placed at the limits (touching, on a cylinder's axis, on a wall). The family of a
scene is seed % 8 (see FAMILIES); `--family thermal` draws heat transfer with coarse-grained
parcels for every seed instead (Draw.thermal, its invariants in check_heat).

A scene passes when either
  * `grain run` exits 0 and the run's output holds the invariants: finite state in every
    snapshot; every particle on the allowed side of every wall it cannot pass (planes,
    cylinders, mesh plates that span the domain, at the snapshot's time for moving walls);
    no resting particle in the path of a moving rod left untouched; particles at the end +
    removed = particles at the start + streamed; in an isolated system (no gravity, fluid,
    cohesion or moving wall) the energy, kinetic + elastic, does not rise; in a fully
    periodic box without walls, gravity or fluid the momentum is conserved; restarted from
    the checkpoint the run wrote (grain run --restart, as many ranks), it ends bit for bit
    as the run (--no-restarts leaves this out);
  * or it exits 1 with a message of the form "error: <cause>" that names a key or a remedy;
    a step the message proposes ("a step of at most X s", "use dt <= X s") must be smaller
    than the step that ran, and the scene rerun with it must get further (finish, or stop
    later in simulated time); when the overlap guard finds no step that prevents a stop,
    each remedy it lists, applied alone, must be accepted and get past that contact
    (--no-advice leaves this out); a CSV row that is valid input (touching spheres written with
    17 digits) must not be refused; the NaN guard of a scene with fluid forces must name
    each enabled force term (issue 17, item 4). Exit 2 (input refused) is judged as exit 1.
A signal, std::bad_alloc, an abort, exit codes other than 0 and 1, or a run longer than
--timeout fail the scene. A failing scene's YAML is printed and kept under --work.

Needs numpy, h5py and yaml: run under another python3, it re-runs itself through
scripts/python.sh, which finds a Python that has them or says how to install them.
"""
import argparse
import json
import math
import os
import random
import re
import resource
import shutil
import signal
import subprocess
import sys
import threading
import time

try:
    import h5py
    import numpy as np
    import yaml
except ImportError:  # this python3 lacks them: scripts/python.sh finds one that has them
    if os.environ.get("GRAINFLOW_PYTHON_CHOSEN"):
        raise
    _helper = os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "..", "..",
                           "scripts", "python.sh")
    os.execv(_helper, [_helper, os.path.abspath(__file__), *sys.argv[1:]])

sys.path.insert(0, os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "..",
                                "support"))
from seeds import parse_seeds  # noqa: E402  (tests/support/seeds.py)

FAMILIES = ["pour", "drum", "rod", "mesh", "periodic_gas", "closed_gas", "fluid", "limits"]
# Families outside the seed % 8 cycle (so that a seed's scene above never changes): chosen
# with --family, they draw a scene of their own for every seed.
EXTRA_FAMILIES = ["thermal"]
NORMAL = ["hertz", "hooke"]
TANGENTIAL = ["none", "history"]
ROLLING = ["none", "cdt", "epsd"]
COHESION = ["none", "sjkr"]
DRAG_LAWS = ["schiller_naumann", "di_felice", "rong", "wen_yu", "ergun", "gidaspow",
             "koch_hill", "beetstra", "tenneti_garg_subramaniam"]
OPTIONAL_FORCES = ["virtual_mass", "saffman_mei", "magnus", "rotational_drag"]
MAX_OVERLAP_DEFAULT = 0.25
# A child may not take more address space than this (per rank): an unbounded grid must end
# in a clear error or std::bad_alloc here, never in the kernel's OOM killer on a shared box.
MEMORY_LIMIT = 3 << 30


def logu(rng, lo, hi):
    return math.exp(rng.uniform(math.log(lo), math.log(hi)))


def combo_of(seed):
    # 7 is prime to 24: seeds 0..23 hold every combination once; the s // 24 term shifts the
    # cycle so that every family (seed % 8) meets every combination over 192 seeds.
    i = (7 * seed + seed // 24) % 24
    return (NORMAL[i // 12], TANGENTIAL[(i // 6) % 2], ROLLING[(i // 2) % 3], COHESION[i % 2])


def rayleigh_time(r, rho, y, nu):
    g = y / (2 * (1 + nu))
    return math.pi * r * math.sqrt(rho / g) / (0.1631 * nu + 0.8766)


# ---------------------------------------------------------------------------------------
# Drawing a scene
# ---------------------------------------------------------------------------------------
class Draw:
    """One scene: the YAML dict plus what the checks need to know about it."""

    def __init__(self, seed, family=None):
        self.seed = seed
        self.rng = random.Random(seed)
        self.family = family or FAMILIES[seed % len(FAMILIES)]
        self.ranks = 2 if seed % 3 == 2 else 1
        self.files = {}  # extra files: name -> text
        self.meta = {"moving_walls": False, "gravity": False, "fluid": False, "cohesion": False,
                     "streams": False, "expected_start": None, "plates": [], "rods": [],
                     "isolated": False, "momentum": False, "heat": None}

    # -- pieces shared by the families ------------------------------------------------------
    def materials(self, n, y_max=1e11):
        rng = self.rng
        mats = []
        rho0 = logu(rng, 100, 20000)
        for k in range(n):
            rho = rho0 if k == 0 else rho0 * logu(rng, 1e-3, 1) if rng.random() < 0.5 else \
                min(rho0 * logu(rng, 1, 1000), 1e6)
            mats.append({"name": f"m{k}", "youngs_modulus": float(f"{logu(rng, 1e5, y_max):.4g}"),
                         "poisson_ratio": round(rng.uniform(-0.2, 0.49), 3),
                         "density": float(f"{rho:.4g}")})
        return mats

    def contact(self, scene):
        rng = self.rng
        normal, tangential, rolling, cohesion = combo_of(self.seed)
        c = {"normal": normal, "tangential": tangential, "rolling": rolling, "cohesion": cohesion}
        if normal == "hooke":
            if rng.random() < 0.5:
                c["hooke"] = {"characteristic_velocity": float(f"{logu(rng, 0.01, 20):.3g}")}
            else:
                kn = logu(rng, 1e1, 1e7)
                c["hooke"] = {"stiffness": {"normal": float(f"{kn:.4g}")}}
                if rng.random() < 0.5:
                    c["hooke"]["stiffness"]["tangential"] = float(f"{kn * rng.uniform(0.2, 1):.4g}")
        if rolling == "epsd" and rng.random() < 0.5:
            c["epsd"] = {"damping_ratio": round(rng.uniform(0, 1), 3)}
        scene["contact"] = c
        self.meta["cohesion"] = cohesion == "sjkr"
        d = {"restitution": round(rng.uniform(0.05, 1.0), 3),
             "friction": round(rng.choice([0, rng.uniform(0, 1.2)]), 3)}
        if rolling != "none":
            d["rolling_friction"] = round(rng.uniform(0, 0.3), 3)
        if cohesion == "sjkr":
            d["cohesion_energy_density"] = float(f"{logu(rng, 1e2, 1e6):.3g}")
        scene["interaction_defaults"] = d
        names = [m["name"] for m in scene["materials"]]
        if len(names) > 1 and rng.random() < 0.5:
            e = {"materials": [names[0], names[-1]], "restitution": round(rng.uniform(0.1, 1), 3)}
            scene["interactions"] = [e]

    def radii(self, r0, ratio):
        rng = self.rng
        kind = rng.choice(["constant", "uniform", "normal", "discrete"]) if ratio > 1.01 else \
            "constant"
        if kind == "constant":
            return {"distribution": "constant", "value": r0}
        if kind == "uniform":
            return {"distribution": "uniform", "min": r0, "max": r0 * ratio}
        if kind == "normal":
            mean = r0 * math.sqrt(ratio)
            return {"distribution": "normal", "mean": mean, "stddev": mean * rng.uniform(0.05, 0.3),
                    "min": max(r0, mean / 10), "max": r0 * ratio}
        return {"distribution": "discrete", "values": [r0, r0 * ratio],
                "weights": [round(logu(rng, 1, 100), 2), 1]}

    def time(self, scene, r_min, steps):
        """Time step from the smallest particle's Rayleigh time, as the code computes it."""
        rng = self.rng
        tr = min(rayleigh_time(r_min, m["density"], m["youngs_modulus"], m["poisson_ratio"])
                 for m in scene["materials"])
        u = rng.random()
        t = {}
        if u < 0.7:
            frac = logu(rng, 0.02, 0.5)
            t["rayleigh_fraction"] = float(f"{frac:.3g}")
            dt = frac * tr
        else:  # a given step, sometimes beyond what the contacts resolve
            dt = tr * logu(rng, 0.02, 3)
            t["step"] = float(f"{dt:.4g}")
        t["end"] = float(f"{dt * steps:.4g}")
        if rng.random() < 0.3:
            t["expected_max_speed"] = float(f"{logu(rng, 0.1, 50):.3g}")
        if rng.random() < 0.2:
            t["max_overlap"] = round(rng.uniform(0.05, 0.6), 3)
        scene["time"] = t
        self.dt_estimate = dt
        return dt

    def output(self, scene):
        end = scene["time"]["end"]
        scene["output"] = {"directory": "out", "snapshot_interval": end / 8, "progress": False,
                           # One checkpoint between the third and the ninth snapshot: the
                           # restart from it must end bit for bit as this run (check_restart).
                           "checkpoint_interval": float(f"{end * self.rng.uniform(0.3, 0.9):.6g}"),
                           "checkpoint_keep": 1}

    def parallel(self, scene, axis_choices):
        if self.ranks == 2 and self.rng.random() < 0.5:
            a = self.rng.choice(axis_choices)
            grid = [1, 1, 1]
            grid[a] = 2
            scene["parallel"] = {"grid": grid}
            if self.rng.random() < 0.5:
                scene["parallel"]["balance"] = True

    def count_fill(self, region_volume, r_mean, fraction):
        return max(1, int(fraction * region_volume / (4 / 3 * math.pi * r_mean ** 3)))

    def velocity(self, scale):
        rng = self.rng
        return [round(rng.gauss(0, scale), 6) for _ in range(3)]

    # -- families ----------------------------------------------------------------------------
    def base(self, nmat=None, y_max=1e11):
        rng = self.rng
        scene = {"materials": self.materials(nmat or rng.choice([1, 2, 2, 3]), y_max)}
        self.contact(scene)
        return scene

    def pour(self):
        rng = self.rng
        scene = self.base()
        r0 = logu(rng, 5e-5, 3e-3)
        ratio = logu(rng, 1, 100) if rng.random() < 0.7 else 1
        r_max = r0 * ratio
        per = [rng.random() < 0.4, rng.random() < 0.4, False]
        lx, ly = (r_max * rng.uniform(6, 16) for _ in range(2))
        lz = r_max * rng.uniform(10, 30)
        scene["domain"] = {"min": [0, 0, 0], "max": [lx, ly, lz], "periodic": per}
        g = -logu(rng, 0.5, 50)
        scene["gravity"] = [0, 0, round(g, 4)]
        self.meta["gravity"] = True
        mats = [m["name"] for m in scene["materials"]]
        walls = [{"type": "plane", "name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1],
                  "material": rng.choice(mats)}]
        for a, (lo, hi) in enumerate([(0, lx), (0, ly)]):
            if not per[a] and rng.random() < 0.7:
                n = [0, 0, 0]
                n[a] = 1
                walls.append({"type": "plane", "name": f"side{a}lo", "point": [0, 0, 0],
                              "normal": list(n), "material": rng.choice(mats)})
                n[a] = -1
                p = [0, 0, 0]
                p[a] = hi
                walls.append({"type": "plane", "name": f"side{a}hi", "point": p, "normal": n,
                              "material": rng.choice(mats)})
        fill_top = lz * 0.6
        if rng.random() < 0.3:  # a piston coming down, sometimes fast
            v = -logu(rng, 0.01, 200)
            walls.append({"type": "plane", "name": "piston", "point": [0, 0, lz * 0.95],
                          "normal": [0, 0, -1], "material": rng.choice(mats),
                          "motion": {"velocity": [0, 0, round(v, 5)]}})
            self.meta["moving_walls"] = True
            fill_top = lz * 0.6
        elif not per[0] and rng.random() < 0.2:  # a tilting floor (rotation about y)
            walls[0]["motion"] = {"angular_velocity": round(rng.uniform(-20, 20), 3),
                                  "axis": [0, 1, 0], "axis_point": [lx / 2, 0, 0]}
            walls[0]["point"] = [lx / 2, 0, 0]
            self.meta["moving_walls"] = True
        scene["walls"] = walls
        fill = {"type": "fill",
                "region": {"box": {"min": [0, 0, lz * 0.05], "max": [lx, ly, fill_top]}},
                "material": rng.choice(mats), "radius": self.radii(r0, ratio),
                "seed": rng.randrange(1 << 32)}
        vol = lx * ly * (fill_top - lz * 0.05)
        r_mean = r0 * (1 + ratio) / 2 if ratio > 1 else r0
        n = min(300, self.count_fill(vol, r_mean, rng.uniform(0.02, 0.2)))
        fill["count"] = n
        if rng.random() < 0.3:
            fill["velocity"] = self.velocity(logu(rng, 0.01, 5))
        scene["insert"] = [fill]
        self.meta["expected_start"] = n
        if rng.random() < 0.3:
            rs = r_max * 0.5
            scene["insert"].append({
                "type": "stream", "material": rng.choice(mats),
                "face": {"rectangle": {"centre": [lx / 2, ly / 2, lz * 0.9], "normal": [0, 0, -1],
                                       "u": [1, 0, 0], "size": [lx * 0.6, ly * 0.6]}},
                "count_rate": 1.0, "radius": {"distribution": "constant", "value": rs},
                "velocity": [0, 0, round(-logu(rng, 0.01, 3), 4)], "seed": rng.randrange(1000)})
            self.meta["streams"] = True
        self.time(scene, r0, rng.randint(300, 1500))
        # A stream delivers a few particles in the run.
        for ins in scene["insert"]:
            if ins["type"] == "stream":
                ins["count_rate"] = float(f"{rng.randint(3, 30) / scene['time']['end']:.4g}")
        self.parallel(scene, [0, 1, 2])
        self.leaver(scene, walls, per, (lx, ly, lz), fill_top, r_max, mats)
        return scene

    def leaver(self, scene, walls, per, size, fill_top, r_max, mats):
        """Three pour scenes in five with an open side: the largest particle of the scene, thrown
        out through that side within a few steps, long before the checkpoint. It set the
        interaction range at the start, which a restart must keep (the restart check; found:
        restarts took the range from the particles left). From its own stream, so that the
        other draws stay as they were."""
        rng = random.Random(1000003 * self.seed + 41)
        sides = {w["name"][4] for w in walls if w["name"].startswith("side")}
        open_axes = [a for a in (0, 1) if not per[a] and str(a) not in sides]
        if rng.random() >= 0.6 or not open_axes:
            return
        a = rng.choice(open_axes)
        r_t = 1.2 * r_max
        top = size[2] * 0.88
        if top - fill_top < 2.05 * r_t:
            return
        lo, hi = [0, 0, fill_top], [size[0], size[1], top]
        lo[a] = size[a] - 2.05 * r_t  # against the open side at the upper end
        v = [0.0, 0.0, 0.0]
        # Outwards at 0.3 radii per step, at most 20 m/s: it leaves when its centre has moved
        # about one radius.
        v[a] = float(f"{min(0.3 * r_t / self.dt_estimate, 20.0):.4g}")
        scene["insert"].append({"type": "fill", "region": {"box": {"min": lo, "max": hi}},
                                "count": 1, "material": rng.choice(mats),
                                "radius": {"distribution": "constant",
                                           "value": float(f"{r_t:.6g}")},
                                "velocity": v, "seed": rng.randrange(1000)})
        self.meta["expected_start"] += 1

    def drum(self):
        rng = self.rng
        scene = self.base()
        r0 = logu(rng, 1e-4, 2e-3)
        ratio = logu(rng, 1, 20)
        r_max = r0 * ratio
        R = r_max * rng.uniform(6, 15)
        L = r_max * rng.uniform(6, 12)
        m = R * 1.05
        periodic_x = rng.random() < 0.6
        scene["domain"] = {"min": [0, -m, -m], "max": [L, m, m],
                           "periodic": [periodic_x, False, False]}
        g = rng.choice([0, -9.81, -logu(rng, 0.1, 100)])
        scene["gravity"] = [0, 0, round(g, 4)]
        self.meta["gravity"] = g != 0
        mats = [x["name"] for x in scene["materials"]]
        drum = {"type": "cylinder", "name": "drum", "axis_point": [0, 0, 0], "axis": [1, 0, 0],
                "radius": R, "side": "inside", "material": rng.choice(mats)}
        u = rng.random()
        if u < 0.35:
            drum["angular_velocity"] = round(rng.uniform(-50, 50), 3)
            self.meta["moving_walls"] = True
        elif u < 0.7:
            drum["motion"] = {"angular_velocity": round(logu(rng, 0.1, 3000) *
                                                        rng.choice([-1, 1]), 3),
                              "axis": [1, 0, 0], "axis_point": [0, 0, 0]}
            self.meta["moving_walls"] = True
        walls = [drum]
        if not periodic_x:
            walls.append({"type": "plane", "name": "cap0", "point": [0, 0, 0], "normal": [1, 0, 0],
                          "material": rng.choice(mats)})
            walls.append({"type": "plane", "name": "cap1", "point": [L, 0, 0],
                          "normal": [-1, 0, 0], "material": rng.choice(mats)})
        scene["walls"] = walls
        n = min(250, self.count_fill(math.pi * R * R * L, r0 * (1 + ratio) / 2,
                                     rng.uniform(0.02, 0.25)))
        scene["insert"] = [{"type": "fill",
                            "region": {"cylinder": {"base": [0, 0, 0], "axis": [1, 0, 0],
                                                    "radius": R * 0.98, "height": L}},
                            "count": n, "material": rng.choice(mats),
                            "radius": self.radii(r0, ratio), "seed": rng.randrange(1 << 32)}]
        self.meta["expected_start"] = n
        self.time(scene, r0, rng.randint(300, 1500))
        self.parallel(scene, [0, 1, 2])
        return scene

    def rod(self):
        rng = self.rng
        scene = self.base()
        r0 = logu(rng, 2e-4, 2e-3)
        ratio = logu(rng, 1, 10)
        r_max = r0 * ratio
        R = logu(rng, 0.2, 5) * r0
        L = r_max * rng.uniform(8, 16)
        periodic_x = rng.random() < 0.5
        scene["domain"] = {"min": [0, -L / 2, -L / 2], "max": [L, L / 2, L / 2],
                           "periodic": [periodic_x, False, False]}
        gravity = rng.random() < 0.4
        scene["gravity"] = [0, 0, -9.81] if gravity else [0, 0, 0]
        self.meta["gravity"] = gravity
        mats = [x["name"] for x in scene["materials"]]
        rod = {"type": "cylinder", "name": "rod", "axis_point": [0, 0, -L / 4], "axis": [1, 0, 0],
               "radius": R, "side": "outside", "material": rng.choice(mats)}
        speed = 0.0
        if rng.random() < 0.7:  # the rod sweeps up through the particles
            speed = logu(rng, 0.01, 5) if rng.random() < 0.5 else logu(rng, 5, 300)
            rod["motion"] = {"velocity": [0, 0, round(speed, 5)]}
            self.meta["moving_walls"] = True
        elif rng.random() < 0.5:
            rod["angular_velocity"] = round(rng.uniform(-100, 100), 3)
            self.meta["moving_walls"] = True
        scene["walls"] = [rod]
        vol = L * L * L / 2
        n = min(250, self.count_fill(vol, r0 * (1 + ratio) / 2, rng.uniform(0.02, 0.15)))
        scene["insert"] = [{"type": "fill",
                            "region": {"box": {"min": [0, -L / 2, -L / 8],
                                               "max": [L, L / 2, L / 2 * 0.95]}},
                            "count": n, "material": rng.choice(mats),
                            "radius": self.radii(r0, ratio), "seed": rng.randrange(1 << 32)}]
        self.meta["expected_start"] = n
        dt = self.time(scene, r0, rng.randint(300, 1500))
        if speed > 0:
            # Long enough for the rod to cross the particles when it is fast; capped in steps.
            end = min(max(scene["time"]["end"], 0.6 * L / speed), dt * 4000)
            scene["time"]["end"] = float(f"{end:.4g}")
        self.meta["rods"].append({"name": "rod", "point": [0, 0, -L / 4], "axis": [1, 0, 0],
                                  "radius": R, "velocity": [0, 0, speed]})
        self.parallel(scene, [0, 1, 2])
        return scene

    def stl_plate(self, name, x0, x1, y0, y1, n):
        lines = [f"solid {name}"]
        xs = np.linspace(x0, x1, n + 1)
        ys = np.linspace(y0, y1, n + 1)
        for i in range(n):
            for j in range(n):
                a = (xs[i], ys[j], 0.0)
                b = (xs[i + 1], ys[j], 0.0)
                c = (xs[i + 1], ys[j + 1], 0.0)
                d = (xs[i], ys[j + 1], 0.0)
                for tri in ((a, b, c), (a, c, d)):
                    lines.append("  facet normal 0 0 1\n    outer loop")
                    for v in tri:
                        lines.append(f"      vertex {v[0]!r} {v[1]!r} {v[2]!r}")
                    lines.append("    endloop\n  endfacet")
        lines.append(f"endsolid {name}")
        self.files[f"{name}.stl"] = "\n".join(lines) + "\n"

    def mesh(self):
        rng = self.rng
        scene = self.base()
        r0 = logu(rng, 1e-4, 3e-3)
        ratio = logu(rng, 1, 30) if rng.random() < 0.6 else 1
        r_max = r0 * ratio
        lx, ly = (r_max * rng.uniform(6, 14) for _ in range(2))
        lz = r_max * rng.uniform(10, 25)
        per = [rng.random() < 0.5, rng.random() < 0.5, False]
        scene["domain"] = {"min": [0, 0, 0], "max": [lx, ly, lz], "periodic": per}
        gravity = rng.random() < 0.7
        scene["gravity"] = [0, 0, round(-logu(rng, 1, 30), 4)] if gravity else [0, 0, 0]
        self.meta["gravity"] = gravity
        mats = [x["name"] for x in scene["materials"]]
        # A plate that spans the domain's cross-section (and beyond), so nothing goes round it.
        n = rng.randint(1, 5)
        self.stl_plate("plate", -0.25 * lx, 1.25 * lx, -0.25 * ly, 1.25 * ly, n)
        zp = lz * rng.uniform(0.05, 0.3)
        plate = {"type": "mesh", "name": "plate", "file": "plate.stl", "translate": [0, 0, zp],
                 "material": rng.choice(mats)}
        if rng.random() < 0.3:  # an in-plane turn about z keeps the plane and the cover
            plate["rotate"] = {"axis": [0, 0, 1], "angle": round(rng.uniform(-10, 10), 3)}
            plate["translate"] = [0, 0, zp]
        velocity = [0, 0, 0]
        u = rng.random()
        if u < 0.3:
            # Rises into the particles; half the time fast (issue 17: 120 m/s crossed a sphere).
            speed = logu(rng, 0.01, 5) if rng.random() < 0.5 else logu(rng, 5, 300)
            velocity = [0, 0, round(speed, 5)]
            plate["motion"] = {"velocity": velocity}
            self.meta["moving_walls"] = True
        elif u < 0.5:
            plate["surface_velocity"] = [round(rng.uniform(-2, 2), 4), 0, 0]
            self.meta["moving_walls"] = True
        scene["walls"] = [plate]
        top = lz * 0.9
        bottom = zp + r_max * 0.5
        n_p = min(250, self.count_fill(lx * ly * (top - bottom), r0 * (1 + ratio) / 2,
                                       rng.uniform(0.02, 0.15)))
        fill = {"type": "fill", "region": {"box": {"min": [0, 0, bottom], "max": [lx, ly, top]}},
                "count": n_p, "material": rng.choice(mats), "radius": self.radii(r0, ratio),
                "seed": rng.randrange(1 << 32)}
        if rng.random() < 0.4:
            fill["velocity"] = [0, 0, round(-logu(rng, 0.01, 30), 4)]
        scene["insert"] = [fill]
        self.meta["expected_start"] = n_p
        dt = self.time(scene, r0, rng.randint(300, 1500))
        if velocity[2] > 0:
            end = min(max(scene["time"]["end"], 0.8 * (top - zp) / velocity[2]), dt * 4000)
            scene["time"]["end"] = float(f"{end:.4g}")
        self.meta["plates"].append({"name": "plate", "point": [0, 0, zp], "normal": [0, 0, 1],
                                    "velocity": velocity, "side": 1})
        self.parallel(scene, [0, 1, 2])
        return scene

    def gas(self, periodic):
        rng = self.rng
        scene = self.base()
        r0 = logu(rng, 1e-4, 3e-3)
        ratio = logu(rng, 1, 100) if rng.random() < 0.6 else 1
        r_max = r0 * ratio
        L = [r_max * rng.uniform(5, 12) for _ in range(3)]
        scene["domain"] = {"min": [0, 0, 0], "max": L, "periodic": [periodic] * 3}
        scene["gravity"] = [0, 0, 0]
        mats = [x["name"] for x in scene["materials"]]
        if not periodic:
            walls = []
            for a in range(3):
                for side in (0, 1):
                    nvec = [0, 0, 0]
                    nvec[a] = 1 if side == 0 else -1
                    p = [0, 0, 0]
                    p[a] = 0 if side == 0 else L[a]
                    walls.append({"type": "plane", "name": f"box{a}{side}", "point": p,
                                  "normal": nvec, "material": rng.choice(mats)})
            if rng.random() < 0.4:  # a static rod through the box
                R = r_max * rng.uniform(0.3, 1.5)
                walls.append({"type": "cylinder", "name": "post", "side": "outside",
                              "axis_point": [L[0] / 2, L[1] / 2, 0], "axis": [0, 0, 1],
                              "radius": R, "material": rng.choice(mats)})
                self.meta["rods"].append({"name": "post", "point": [L[0] / 2, L[1] / 2, 0],
                                          "axis": [0, 0, 1], "radius": R,
                                          "velocity": [0, 0, 0]})
            scene["walls"] = walls
        vol = L[0] * L[1] * L[2]
        n = min(300, self.count_fill(vol, r0 * (1 + ratio) / 2, rng.uniform(0.02, 0.2)))
        speed = logu(rng, 0.01, 10)
        if rng.random() < 0.5:
            # Groups of particles, each with its own velocity (a fill gives one to all).
            scene["insert"] = []
            groups = rng.randint(2, 4)
            for k in range(groups):
                scene["insert"].append({
                    "type": "fill", "region": {"box": {"min": [0, 0, 0], "max": L}},
                    "count": max(1, n // groups), "material": mats[k % len(mats)],
                    "radius": self.radii(r0, ratio), "velocity": self.velocity(speed),
                    "seed": rng.randrange(1 << 32)})
            self.meta["expected_start"] = sum(i["count"] for i in scene["insert"])
        else:
            # A gas with a random velocity per particle, from a CSV file (non-overlapping by
            # rejection; centres kept a radius inside the walls).
            rows = []
            placed = []
            for _ in range(20 * n):
                if len(rows) >= n:
                    break
                q = r0 if rng.random() < 0.7 else r0 * ratio
                c = np.array([rng.uniform(q, L[a] - q) for a in range(3)])
                span = np.asarray(L) * (1.0 if periodic else 0.0)
                if any(np.linalg.norm(c - c2 - span * np.round((c - c2) / np.asarray(L))) <
                       q + q2 for c2, q2 in placed):
                    continue
                if any(np.linalg.norm((c - rod["point"])[:2]) < rod["radius"] + q
                       for rod in self.meta["rods"]):  # the post stands along z
                    continue
                placed.append((c, q))
                v = self.velocity(speed)
                rows.append((*c, q, *v, rng.choice(mats)))
            text = "x,y,z,radius,vx,vy,vz,material\n"
            for row in rows:
                text += ",".join(f"{v:.17g}" for v in row[:7]) + f",{row[7]}\n"
            self.files["gas.csv"] = text
            scene["insert"] = [{"type": "csv", "file": "gas.csv", "material": mats[0]}]
            self.meta["expected_start"] = len(rows)
            self.meta["csv_valid_lines"] = set(range(2, len(rows) + 2))
        self.meta["isolated"] = not self.meta["cohesion"]
        self.meta["momentum"] = periodic
        self.time(scene, r0, rng.randint(300, 1500))
        self.parallel(scene, [0, 1, 2])
        return scene

    def fluid(self):
        rng = self.rng
        # Soft materials: steps long against the fluid's time scales (drag, spin relaxation).
        small = rng.random() < 0.4
        scene = self.base(y_max=1e7 if small else 1e8)
        r0 = logu(rng, 5e-6, 5e-5) if small else logu(rng, 1e-4, 2e-3)
        ratio = logu(rng, 1, 10)
        r_max = r0 * ratio
        L = [r_max * rng.uniform(8, 20) for _ in range(3)]
        per = [rng.random() < 0.5, rng.random() < 0.5, rng.random() < 0.3]
        big = rng.random() < 0.08  # a large domain with a fine void-fraction grid
        if big:
            L = [logu(rng, 0.5, 3)] * 3
        scene["domain"] = {"min": [0, 0, 0], "max": L, "periodic": per}
        gravity = rng.random() < 0.7
        scene["gravity"] = [0, 0, -9.81] if gravity else [0, 0, 0]
        mats = [x["name"] for x in scene["materials"]]
        walls = []
        if not per[2]:
            walls.append({"type": "plane", "name": "floor", "point": [0, 0, 0],
                          "normal": [0, 0, 1], "material": rng.choice(mats)})
        scene["walls"] = walls
        hydro = rng.random() < 0.5
        forces = ["drag", "pressure_gradient", "viscous"]
        # Small beads mostly get a shear and rotational drag with a viscous fluid: their spin
        # relaxation time rho_p d^2 / (60 mu) is then far below the contact step (issue 17).
        forces += [f for f in OPTIONAL_FORCES
                   if rng.random() < (0.8 if small and f == "rotational_drag" else 0.5)]
        if gravity and not hydro:
            forces.append("buoyancy")
        rng.shuffle(forces)
        fl = {"density": float(f"{logu(rng, 1, 2000):.4g}"),
              "viscosity": float(f"{logu(rng, 1e-2 if small else 1e-5, 1):.3g}"),
              "velocity": [round(rng.uniform(-2, 2), 4) for _ in range(3)],
              "drag": rng.choice(DRAG_LAWS), "model": rng.choice(["A", "B"]), "forces": forces,
              "pressure": {"hydrostatic": hydro}}
        # A shear varies along a bounded axis (across a periodic one it is refused).
        gradient = next(([0, a == 1, a == 2] for a in (2, 1) if not per[a]), None)
        if rng.random() < (0.8 if small else 0.5) and gradient is not None:
            fl["shear"] = {"rate": round(logu(rng, 0.1, 1e4), 4), "flow_direction": [1, 0, 0],
                           "gradient_direction": [int(g) for g in gradient],
                           "origin": [0, 0, 0]}
        if rng.random() < 0.3:
            fl["pressure"]["gradient"] = [round(rng.uniform(-1e3, 1e3), 3), 0, 0]
        if "virtual_mass" in forces and rng.random() < 0.5:
            fl["virtual_mass_coefficient"] = round(rng.uniform(0, 1), 3)
        if big or rng.random() < 0.4:
            cell = L[0] / logu(rng, 50, 3000) if big else r_max * logu(rng, 1.5, 8)
            fl["void_fraction"] = {"cell_size": float(f"{cell:.4g}"),
                                   "minimum": round(rng.uniform(0.2, 0.6), 3)}
        else:
            fl["void_fraction"] = round(rng.uniform(0.2, 1), 3)
        scene["fluid"] = fl
        self.meta["fluid"] = True
        self.meta["gravity"] = gravity
        box_max = [L[0], L[1], L[2] * 0.8] if not big else [r_max * 20] * 3
        vol = box_max[0] * box_max[1] * box_max[2]
        n = min(200, self.count_fill(vol, r0 * (1 + ratio) / 2, rng.uniform(0.01, 0.15)))
        scene["insert"] = [{"type": "fill",
                            "region": {"box": {"min": [0, 0, 0], "max": box_max}},
                            "count": n, "material": rng.choice(mats),
                            "radius": self.radii(r0, ratio), "seed": rng.randrange(1 << 32)}]
        self.meta["expected_start"] = n
        self.time(scene, r0, rng.randint(200, 1000))
        self.parallel(scene, [0, 1, 2])
        return scene

    def limits(self):
        """CSV particles at the limits of insertion: touching (17 digits), on walls, on axes."""
        rng = self.rng
        scene = self.base()
        r = logu(rng, 1e-4, 3e-3)
        L = r * rng.uniform(12, 30)
        scene["domain"] = {"min": [0, 0, 0], "max": [L, L, L], "periodic": [False] * 3}
        gravity = rng.random() < 0.6
        scene["gravity"] = [0, 0, -9.81] if gravity else [0, 0, 0]
        self.meta["gravity"] = gravity
        mats = [x["name"] for x in scene["materials"]]
        walls = [{"type": "plane", "name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1],
                  "material": rng.choice(mats)}]
        rows = []
        valid = []  # per row: True when the row is valid input and must be accepted
        # Half the scenes test touching and overlapping pairs; the other half walls, so that
        # a refusal of the first kind does not hide what the second would show.
        touching = rng.random() < 0.5
        # A chain of touching spheres along a random direction: centres r1 + r2 apart, written
        # with 17 significant digits.
        d = np.array([rng.gauss(0, 1) for _ in range(3)])
        d /= np.linalg.norm(d)
        x = np.array([L / 2, L / 2, L / 2])
        k = rng.randint(2, 6) if touching else 0
        radii = [r * logu(rng, 0.3, 1) for _ in range(k)]
        span = sum(2 * q for q in radii)
        x = x - d * span / 2
        pos = []
        for i, q in enumerate(radii):
            if i == 0:
                c = x + d * q
            else:
                c = pos[-1][0] + d * (radii[i - 1] + q)
            pos.append((c, q))
        for c, q in pos:
            rows.append((c[0], c[1], c[2], q))
            valid.append(True)
        # A sphere resting exactly on the floor (centre r above it).
        q = r * rng.uniform(0.5, 1)
        rows.append((L * 0.2, L * 0.2, q, q))
        valid.append(True)
        u = rng.random() if not touching else 1
        if u < 0.55:  # a rod with a sphere exactly on (or just off) its axis
            R = r * logu(rng, 0.2, 2)
            off = rng.choice([0.0, 0.0, 0.3 * R])
            yz = float(f"{L * 0.8:.12g}")  # as the YAML holds it: the centre exactly on the axis
            walls.append({"type": "cylinder", "name": "rod", "side": "outside",
                          "axis_point": [0, yz, yz], "axis": [1, 0, 0], "radius": R,
                          "material": rng.choice(mats)})
            self.meta["rods"].append({"name": "rod", "point": [0, yz, yz],
                                      "axis": [1, 0, 0], "radius": R, "velocity": [0, 0, 0]})
            rows.append((L * 0.5, yz + off, yz, r * 0.5))
            valid.append(False)  # inside the rod: must be refused with the rod's name
        elif u < 1:  # a wall crossing a sphere by a given fraction of its radius
            frac = rng.choice([0.01, 0.1, 0.24, 0.26, 0.5, 0.99])
            q = r * 0.8
            walls.append({"type": "plane", "name": "shelf", "point": [0, 0, L * 0.85],
                          "normal": [0, 0, -1], "material": rng.choice(mats)})
            rows.append((L * 0.7, L * 0.7, L * 0.85 - q * (1 - frac), q))
            valid.append(None)  # accepted or refused, depending on the overlap limit
        # A touching, slightly overlapping or slightly separated pair.
        gap = (rng.choice([-1e-3, -1e-9, 0.0, 1e-12]) if touching else 1e-6) * r
        a = np.array([L * 0.25, L * 0.75, L * 0.3])
        rows.append((a[0], a[1], a[2], r))
        rows.append((a[0] + 2 * r + gap, a[1], a[2], r))
        valid += [True, gap >= 0]
        # An unequal pair: a large sphere resting on a small one (ratio up to 20).
        ratio = logu(rng, 1, 20)
        small = r / ratio
        b = np.array([L * 0.75, L * 0.25, small])
        rows.append((b[0], b[1], b[2], small))
        rows.append((b[0], b[1], b[2] + small + r * 1.0000001, r))
        valid += [True, True]
        text = "x,y,z,radius,vx,vy,vz\n"
        for row in rows:
            text += ",".join(f"{v:.17g}" for v in row) + ",0,0,0\n"
        self.files["particles.csv"] = text
        scene["walls"] = walls
        scene["insert"] = [{"type": "csv", "file": "particles.csv", "material": rng.choice(mats)}]
        self.meta["expected_start"] = len(rows)
        # Line numbers in the file (the header is line 1) of rows that must be accepted.
        self.meta["csv_valid_lines"] = {k + 2 for k, ok in enumerate(valid) if ok}
        self.time(scene, min(row[3] for row in rows), rng.randint(300, 1500))
        self.parallel(scene, [0, 1, 2])
        return scene

    def thermal(self):
        """Heat transfer with coarse-grained parcels (`--family thermal`; not in the seed % 8
        cycle): a box under gravity, beads and parcels of k in [1.2, 3] side by side, walls
        adiabatic, at a fixed temperature or (rarely) under a fixed flux, a heat source now and
        then, and sometimes a prescribed fluid that exchanges heat by convection."""
        rng = self.rng
        scene = self.base(y_max=1e9)
        for m in scene["materials"]:
            m["heat_capacity"] = float(f"{logu(rng, 100, 5000):.4g}")
            m["conductivity"] = float(f"{logu(rng, 0.01, 400):.4g}")  # reset below if used
        heat = {}
        c = scene["contact"]
        if c["normal"] == "hertz" and rng.random() < 0.3:
            heat["contact_radius"] = rng.choice(["morris_static", "morris_collision"])
            for m in scene["materials"]:
                m["real_youngs_modulus"] = float(f"{m['youngs_modulus'] * logu(rng, 1, 1e4):.4g}")
        if rng.random() < 0.1:
            heat["conduction"] = "none"
        scene["heat"] = heat
        if rng.random() < 0.2:
            m = rng.choice(scene["materials"])
            m["heat_source"] = float(f"{rng.choice([-1, 1]) * logu(rng, 1e-2, 1e5):.4g}")
        mats = [x["name"] for x in scene["materials"]]
        r0 = logu(rng, 2e-4, 3e-3)
        ratio = logu(rng, 1, 4) if rng.random() < 0.6 else 1
        # One or two insertions (a fill, sometimes a stream), each beads or parcels.
        ks = [1.0 if rng.random() < 0.3 else round(rng.uniform(1.2, 3), 3)
              for _ in range(rng.choice([1, 2]))]
        if any(k != 1 for k in ks) and "stiffness" in c.get("hooke", {}) and rng.random() < 0.9:
            # A fixed Hooke stiffness is refused with parcels; keep a few to check the message.
            c["hooke"] = {"characteristic_velocity": float(f"{logu(rng, 0.01, 20):.3g}")}
        r_big = r0 * ratio * max(ks)
        lx, ly = (r_big * rng.uniform(6, 14) for _ in range(2))
        lz = r_big * rng.uniform(12, 30)
        per = [rng.random() < 0.3, rng.random() < 0.3, False]
        scene["domain"] = {"min": [0, 0, 0], "max": [lx, ly, lz], "periodic": per}
        scene["gravity"] = [0, 0, -9.81]
        self.meta["gravity"] = True
        temps = [round(rng.uniform(250, 500), 3) for _ in ks]
        bounds = list(temps)
        flux = False
        # A third of the scenes are closed and adiabatic (no wall temperature or flux, no
        # fluid, no stream): the particles' m c T then changes only by their heat sources.
        adiabatic = rng.random() < 0.35

        def thermal(w):
            nonlocal flux
            u = 1 if adiabatic else rng.random()
            if u < 0.35:
                w["temperature"] = round(rng.uniform(250, 500), 3)
                bounds.append(w["temperature"])
            elif u < 0.45:
                w["heat_flux"] = float(f"{rng.choice([-1, 1]) * logu(rng, 1, 1e5):.4g}")
                flux = True
            return w

        walls = [thermal({"type": "plane", "name": "floor", "point": [0, 0, 0],
                          "normal": [0, 0, 1], "material": rng.choice(mats)})]
        for a, hi in enumerate([lx, ly]):
            if per[a]:
                continue
            n = [0, 0, 0]
            n[a] = 1
            walls.append(thermal({"type": "plane", "name": f"side{a}lo", "point": [0, 0, 0],
                                  "normal": list(n), "material": rng.choice(mats)}))
            n[a] = -1
            p = [0, 0, 0]
            p[a] = hi
            walls.append(thermal({"type": "plane", "name": f"side{a}hi", "point": p,
                                  "normal": n, "material": rng.choice(mats)}))
        # A lid keeps everything in (no removal), so that the energy balance is exact.
        walls.append(thermal({"type": "plane", "name": "lid", "point": [0, 0, lz],
                              "normal": [0, 0, -1], "material": rng.choice(mats)}))
        scene["walls"] = walls
        inserts = []
        expected = 0
        base = lz * 0.02
        block = None
        if rng.random() < 0.6:
            # A block of beads on the floor in a simple cubic lattice, each touching its
            # neighbours and the floor (written with 17 digits), each at its own temperature:
            # under gravity the contacts close at once and heat flows from the first step.
            rc = r0 * logu(rng, 1, ratio) if ratio > 1 else r0
            nx, ny = max(1, int(lx / (2 * rc))), max(1, int(ly / (2 * rc)))
            nz = max(1, min(rng.randint(1, 3), 150 // (nx * ny)))
            rows = []
            for i in range(nx):
                for j in range(ny):
                    for kz in range(nz):
                        if len(rows) < 150:
                            t = rng.uniform(250, 500)
                            bounds.append(t)
                            rows.append((rc + 2 * rc * i, rc + 2 * rc * j, rc + 2 * rc * kz, rc, t))
            text = "x,y,z,radius,T\n" + "".join(",".join(f"{v:.17g}" for v in row) + "\n"
                                                 for row in rows)
            self.files["block.csv"] = text
            block = {"type": "csv", "file": "block.csv", "material": rng.choice(mats)}
            inserts.append(block)
            expected += len(rows)
            self.meta["csv_valid_lines"] = set(range(2, len(rows) + 2))
            base = 2 * rc * nz + 0.02 * lz
        top = lz * 0.7
        for i, (k, t) in enumerate(zip(ks, temps)):
            ins = {"type": "fill",
                   "region": {"box": {"min": [0, 0, base + i * (top - base) / len(ks)],
                                      "max": [lx, ly, base + (i + 1) * (top - base) / len(ks)]}},
                   "material": rng.choice(mats), "radius": self.radii(r0, ratio),
                   "temperature": t, "seed": rng.randrange(1 << 32)}
            if k != 1 or rng.random() < 0.2:
                ins["coarse_grain"] = k
            vol = lx * ly * (top - base) / len(ks)
            r_mean = k * r0 * ((1 + ratio) / 2 if ratio > 1 else 1)
            n = min(150, self.count_fill(vol, r_mean, rng.uniform(0.1, 0.28)))
            ins["count"] = n
            if rng.random() < 0.4:
                ins["velocity"] = self.velocity(logu(rng, 0.01, 0.5))
            expected += n
            inserts.append(ins)
        scene["insert"] = inserts
        self.meta["expected_start"] = expected
        fluid = not adiabatic and rng.random() < 0.5
        if fluid:
            fl = {"density": float(f"{logu(rng, 1, 1000):.4g}"),
                  "viscosity": float(f"{logu(rng, 1e-5, 1e-2):.3g}"),
                  "velocity": [0, 0, round(rng.uniform(0, 1), 4)],
                  "drag": rng.choice(DRAG_LAWS), "model": "B",
                  "forces": ["drag", "pressure_gradient", "viscous"],
                  "pressure": {"hydrostatic": True},
                  "temperature": round(rng.uniform(250, 500), 3),
                  "heat_capacity": float(f"{logu(rng, 500, 5000):.4g}"),
                  "conductivity": float(f"{logu(rng, 0.02, 1):.3g}"),
                  "convection": rng.choice(["ranz_marshall", "gunn"])}
            if rng.random() < 0.5:
                fl["void_fraction"] = {"cell_size": float(f"{r_big * logu(rng, 2, 6):.4g}"),
                                       "minimum": round(rng.uniform(0.35, 0.5), 3)}
            else:
                fl["void_fraction"] = round(rng.uniform(0.4, 1), 3)
            scene["fluid"] = fl
            self.meta["fluid"] = True
            bounds.append(fl["temperature"])
        sources = any("heat_source" in m for m in scene["materials"])
        self.meta["heat"] = {
            "bounds": None if flux or sources else (min(bounds), max(bounds)),
            # A closed box without a fixed wall temperature, flux or fluid exchanges no heat:
            # the particles' m c T changes only by their sources.
            "closed": adiabatic,
            "ks": sorted({float(k) for k in ks})}
        # Long enough for the particles to meet and settle, so that heat passes.
        dt = self.time(scene, r0, rng.randint(2000, 20000))
        # Each inserted material's conductivity puts its conduction time scale m c / (2 k a)
        # (a at the default overlap limit 0.25 r: sqrt(r/2 0.25 r) = 0.354 r; the start-up's
        # estimate) at 12 dt times 0.5 to 100: near the stability limit of dt <= tau / 12,
        # and beyond it now and then, where the start-up refuses and its advice is rerun.
        by_name = {m["name"]: m for m in scene["materials"]}
        r_of = {}
        fills = [ins for ins in inserts if ins["type"] == "fill"]
        for ins, k in zip(fills, ks):
            r_of[ins["material"]] = min(r_of.get(ins["material"], 1e9), k * r0)
        if block:
            r_of[block["material"]] = min(r_of.get(block["material"], 1e9), r0)
        for name, r in r_of.items():
            m = by_name[name]
            tau = 12 * dt * logu(rng, 0.5, 100)
            cond = m["density"] * 4 / 3 * math.pi * r ** 2 * m["heat_capacity"] / (0.707 * tau)
            m["conductivity"] = float(f"{cond:.4g}")
        # A stream of parcels or beads delivers a few more (then not closed).
        if not adiabatic and rng.random() < 0.3:
            k = rng.choice(ks)
            st = {"type": "stream", "material": rng.choice(mats),
                  "face": {"rectangle": {"centre": [lx / 2, ly / 2, lz * 0.9],
                                         "normal": [0, 0, -1], "u": [1, 0, 0],
                                         "size": [lx * 0.5, ly * 0.5]}},
                  "count_rate": float(f"{rng.randint(3, 20) / scene['time']['end']:.4g}"),
                  "radius": {"distribution": "constant", "value": r0},
                  "velocity": [0, 0, -0.1], "temperature": temps[0],
                  "seed": rng.randrange(1000)}
            if k != 1:
                st["coarse_grain"] = k
            scene["insert"].append(st)
            self.meta["streams"] = True
            self.meta["heat"]["closed"] = False
        # One scene in ten: a heat sink (negative heat_source) that would take the first
        # fill's particles below 0 K in 1/30 to 1/3 of the run. The temperature guard must stop
        # it naming the key, and its advice, a weaker sink, must get further. From its own
        # stream, so that the other draws stay as they were.
        sink = random.Random(1000003 * self.seed + 29)
        if sink.random() < 0.1 and fills:
            m = by_name[fills[0]["material"]]
            rate = m["heat_capacity"] * max(temps) / scene["time"]["end"] * sink.uniform(3, 30)
            m["heat_source"] = -float(f"{rate:.4g}")
            self.meta["heat"]["bounds"] = None
        self.parallel(scene, [0, 1])
        return scene

    def scene(self):
        f = self.family
        s = {"pour": self.pour, "drum": self.drum, "rod": self.rod, "mesh": self.mesh,
             "periodic_gas": lambda: self.gas(True), "closed_gas": lambda: self.gas(False),
             "fluid": self.fluid, "limits": self.limits, "thermal": self.thermal}[f]()
        self.output(s)
        order = ["domain", "gravity", "time", "materials", "interactions", "interaction_defaults",
                 "contact", "heat", "walls", "insert", "fluid", "parallel", "output"]
        return {k: s[k] for k in order if k in s}


def draw(seed, family=None):
    d = Draw(seed, family)
    s = d.scene()
    return d, clean(s)


def clean(x):
    """Plain Python numbers (no numpy scalars) with 12 significant digits for YAML."""
    if isinstance(x, dict):
        return {k: clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [clean(v) for v in x]
    if isinstance(x, bool):
        return x
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return float(f"{float(x):.12g}")
    return x


def scene_yaml(seed, scene, draw_obj):
    head = (f"# hard_scenes.py seed {seed}: family {draw_obj.family}, {draw_obj.ranks} rank(s), "
            f"contact {'+'.join(combo_of(seed))}\n")
    return head + yaml.safe_dump(scene, default_flow_style=None, sort_keys=False, width=100)


# ---------------------------------------------------------------------------------------
# Running and checking
# ---------------------------------------------------------------------------------------
def limit_memory():
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))


def run_grain(args, ranks, scene_path, cwd, timeout, extra=(), output="out"):
    cmd = [args.grain, "run", scene_path, "--output", output, "--no-progress", *extra]
    if ranks > 1:
        # mpiexec binds the ranks to cores 0, 1, ...: when --jobs leaves room for another
        # multi-rank run beside this one, both would be bound to the same cores. Otherwise
        # binding stays (a bound 2-rank run is ~15 % faster here).
        bind = ("--bind-to", "none") if getattr(args, "jobs", 1) - ranks >= 2 else ()
        cmd = [args.mpiexec, "-np", str(ranks), "--oversubscribe", *bind, *cmd]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    start = time.monotonic()
    try:
        p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=timeout,
                           env=env, preexec_fn=limit_memory, start_new_session=True)
        return p.returncode, p.stdout + p.stderr, time.monotonic() - start
    except subprocess.TimeoutExpired as e:
        out = (e.stdout or b"").decode(errors="replace") if isinstance(e.stdout, bytes) else \
            (e.stdout or "")
        return None, out, time.monotonic() - start


FATAL_PATTERNS = [
    (r"bad_alloc", "std::bad_alloc"),
    (r"Segmentation fault|SIGSEGV|signal 11\b", "segmentation fault"),
    (r"SIGABRT|signal 6\b|Aborted \(core|terminate called", "abort"),
    (r"exited on signal \d+|SIGBUS|SIGFPE|SIGKILL|Floating point exception", "signal"),
    (r"MPI_ABORT was invoked", "MPI_Abort"),
]

STEP_PROPOSAL = re.compile(
    r"(?:[Ss]tep of at most|dt\s*<=|dt\s*≤|step of|time step of)\s*([0-9]+(?:\.[0-9]*)?"
    r"(?:[eE][-+]?[0-9]+)?)\s*s\b")
FAIL_TIME = re.compile(r"\bt = ([0-9.eE+-]+) s")
ADVICE_WORDS = re.compile(
    r"key |lower |raise |reduce |increase |decrease |use |set |give |add |remove |check |"
    r"enlarge |make |move |choose |at most|at least|should|must|would|instead|;", re.I)


class Failure(Exception):
    def __init__(self, cls, detail):
        super().__init__(f"{cls}: {detail}")
        self.cls = cls
        self.detail = detail


def error_line(out):
    # A step refused at start-up by several limits: the final line's advice is the one that
    # must satisfy them all (each earlier error proposes its own limit's step).
    for line in out.splitlines():
        if "error: refusing to run with this time step" in line:
            return line.strip()
    for line in out.splitlines():
        if re.search(r"\berror: ", line):
            return line.strip()
    lines = [ln for ln in out.splitlines() if ln.strip()]
    return lines[-1].strip() if lines else ""


def read_snapshots(outdir):
    snaps = []
    for name in sorted(os.listdir(outdir)):
        if name.startswith("particles_") and name.endswith(".h5"):
            with h5py.File(os.path.join(outdir, name), "r") as f:
                d = {k: f[k][...] for k in ("id", "position", "velocity", "angular_velocity",
                                            "radius", "mass", "material", "temperature",
                                            "coarse_grain", "real_count") if k in f}
                for a in ("material_coarse_grain", "material_real"):
                    if a in f.attrs:
                        d[a] = np.asarray(f.attrs[a])
                d["time"] = float(f.attrs["time"])
                d["count"] = int(f.attrs["count"])
                snaps.append(d)
    return snaps


def rotation(axis, angle):
    a = np.asarray(axis, float)
    a /= np.linalg.norm(a)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)


def moved(w, t, point, direction):
    """A wall's point and unit direction at time t (DESIGN motion: P + V t + R (x0 - P))."""
    p = np.asarray(point, float)
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    m = w.get("motion", {})
    v = np.asarray(m.get("velocity", [0, 0, 0]), float)
    om = m.get("angular_velocity", 0)
    if om:
        P = np.asarray(m.get("axis_point", [0, 0, 0]), float)
        R = rotation(m["axis"], om * t)
        p = P + R @ (p - P)
        d = R @ d
    return p + v * t, d


def plane_at(w, t):
    """Point and unit normal of a plane wall at time t."""
    return moved(w, t, w["point"], w["normal"])


def cylinder_at(w, t):
    """Axis point and unit axis of a cylinder wall at time t."""
    return moved(w, t, w["axis_point"], w["axis"])


def wall_speed(w, extent):
    m = w.get("motion", {})
    v = np.linalg.norm(np.asarray(m.get("velocity", [0, 0, 0]), float))
    return v + abs(m.get("angular_velocity", 0)) * extent


def material_table(scene):
    return {i: m for i, m in enumerate(scene["materials"])}, \
        {m["name"]: i for i, m in enumerate(scene["materials"])}


def y_star(ma, mb):
    return 1 / ((1 - ma["poisson_ratio"] ** 2) / ma["youngs_modulus"] +
                (1 - mb["poisson_ratio"] ** 2) / mb["youngs_modulus"])


def elastic_energy(scene, s):
    """Normal elastic energy of every pair and plane contact, by brute force (DESIGN.md §3):
    Hertz (8/15) Y* sqrt(R*) d^(5/2); Hooke k_n d^2 / 2."""
    mats, index = material_table(scene)
    c = scene["contact"]
    hooke = c["normal"] == "hooke"
    x, r, m, mat = s["position"], s["radius"], s["mass"], s["material"]
    n = len(r)
    if n == 0:
        return 0.0
    lo = np.asarray(scene["domain"]["min"], float)
    L = np.asarray(scene["domain"]["max"], float) - lo
    per = scene["domain"].get("periodic", [False] * 3)

    def law(delta, ys, rs, ms):
        if not hooke:
            return (8 / 15) * ys * np.sqrt(rs) * delta ** 2.5
        h = c["hooke"]
        if "stiffness" in h:
            kn = h["stiffness"]["normal"]
        else:
            v = h["characteristic_velocity"]
            kn = (16 / 15) * np.sqrt(rs) * ys * (15 * ms * v * v / (16 * np.sqrt(rs) * ys)) ** 0.2
        return 0.5 * kn * delta ** 2

    e = 0.0
    for i in range(n - 1):
        d = x[i + 1:] - x[i]
        for a in range(3):
            if per[a]:
                d[:, a] -= L[a] * np.round(d[:, a] / L[a])
        dist = np.linalg.norm(d, axis=1)
        rr = r[i] + r[i + 1:]
        ov = rr - dist
        k = np.nonzero(ov > 0)[0]
        for j in k:
            jj = i + 1 + j
            ys = y_star(mats[int(mat[i])], mats[int(mat[jj])])
            rs = r[i] * r[jj] / (r[i] + r[jj])
            ms = m[i] * m[jj] / (m[i] + m[jj])
            e += law(ov[j], ys, rs, ms)
    for w in scene.get("walls", []):
        wm = mats[index[w["material"]]]
        if w["type"] == "plane":
            p, nn = plane_at(w, s["time"])
            dist = (x - p) @ nn
        elif w["type"] == "cylinder":
            p, a = cylinder_at(w, s["time"])
            rel = x - p
            rho = np.linalg.norm(rel - np.outer(rel @ a, a), axis=1)
            dist = w["radius"] - rho if w.get("side", "inside") == "inside" else rho - w["radius"]
        else:  # the plates of these scenes are flat at z = translate[2]
            dist = np.abs(x[:, 2] - w["translate"][2])
        ov = r - dist
        for i in np.nonzero(ov > 0)[0]:
            e += law(ov[i], y_star(mats[int(mat[i])], wm), r[i], m[i])
    return float(e)


def kinetic_energy(s):
    m, r = s["mass"], s["radius"]
    return float(0.5 * np.sum(m * np.sum(s["velocity"] ** 2, axis=1)) +
                 0.5 * np.sum(0.4 * m * r * r * np.sum(s["angular_velocity"] ** 2, axis=1)))


def check_output(d, scene, cwd, out):
    """Invariants of a run that ended with exit 0."""
    outdir = os.path.join(cwd, "out")
    snaps = read_snapshots(outdir)
    if not snaps:
        raise Failure("no output", "exit 0 but no snapshot in out/")
    m = re.search(r"done: (\d+) steps, (\d+) particles \((\d+) removed\)", out)
    if not m:
        raise Failure("no summary", "exit 0 without the 'done: ... particles (... removed)' line")
    n_end, removed = int(m.group(2)), int(m.group(3))
    streamed = sum(int(k) for k in re.findall(r"^stream .*?: (\d+) particles", out, re.M))
    first = snaps[0]
    if d.meta["expected_start"] is not None and first["count"] != d.meta["expected_start"]:
        raise Failure("particle count", f"{first['count']} particles at t = 0, "
                      f"{d.meta['expected_start']} asked for")
    if n_end + removed != first["count"] + streamed:
        raise Failure("particle lost", f"start {first['count']} + streamed {streamed} != end "
                      f"{n_end} + removed {removed}")
    if snaps[-1]["count"] != n_end:
        raise Failure("particle lost", f"last snapshot holds {snaps[-1]['count']}, summary {n_end}")
    max_ov = scene["time"].get("max_overlap", MAX_OVERLAP_DEFAULT)
    dt = d.dt_run
    for s in snaps:
        for k in ("position", "velocity", "angular_velocity"):
            if s["count"] and not np.all(np.isfinite(s[k])):
                raise Failure("non-finite state", f"{k} not finite at t = {s['time']}")
        if len(s["id"]) != len(set(s["id"].tolist())):
            raise Failure("duplicate ids", f"at t = {s['time']}")
        x, r = s["position"], s["radius"]
        if len(r) == 0:
            continue
        # Slack: the guard allows max_overlap of the radius; a moving wall may advance one
        # step's travel between the guard's check and the snapshot; 1e-9 r for round-off.
        for w in scene.get("walls", []):
            if w["type"] == "plane":
                p, n = plane_at(w, s["time"])
                dist = (x - p) @ n
                slack = wall_speed(w, np.max(np.abs(x - p))) * dt + 1e-9 * r
                bad = np.nonzero(dist < r * (1 - max_ov) - slack)[0]
            elif w["type"] == "cylinder":
                p, a = cylinder_at(w, s["time"])
                rel = x - p
                rho = np.linalg.norm(rel - np.outer(rel @ a, a), axis=1)
                slack = wall_speed(w, w["radius"]) * dt + 1e-9 * r
                if w.get("side", "inside") == "inside":
                    bad = np.nonzero(w["radius"] - rho < r * (1 - max_ov) - slack)[0]
                else:
                    bad = np.nonzero(rho - w["radius"] < r * (1 - max_ov) - slack)[0]
            else:
                bad = []
                for pl in d.meta["plates"]:
                    if pl["name"] != w["name"]:
                        continue
                    pz = pl["point"][2] + pl["velocity"][2] * s["time"]
                    slack = abs(pl["velocity"][2]) * dt + 1e-9 * r
                    bad = np.nonzero((x[:, 2] - pz) * pl["side"] < r * (1 - max_ov) - slack)[0]
            if len(bad):
                i = bad[0]
                raise Failure(
                    "particle inside a wall",
                    f"wall '{w.get('name')}' ({w['type']}): {len(bad)} particle(s) at t = "
                    f"{s['time']:.6g} s, e.g. id {int(s['id'][i])} at "
                    f"({x[i][0]:.6g}, {x[i][1]:.6g}, {x[i][2]:.6g}) m, r = {r[i]:.4g} m "
                    f"(overlap limit {max_ov})")
    # A moving rod must touch every resting particle in its path (no gravity, no fluid).
    last = snaps[-1]
    if not d.meta["gravity"] and not d.meta["fluid"]:
        for rod in d.meta["rods"]:
            v = np.asarray(rod["velocity"], float)
            if not np.any(v):
                continue
            T = last["time"]
            p0 = np.asarray(rod["point"], float)
            ids_end = {int(i): k for k, i in enumerate(last["id"])}
            for k, pid in enumerate(first["id"]):
                pid = int(pid)
                if pid not in ids_end or np.any(first["velocity"][k] != 0):
                    continue
                rel = first["position"][k] - p0
                ahead = rel @ v / np.linalg.norm(v)
                lateral = abs(rel[1])  # the rods sweep along z with axis x: y is lateral
                travel = np.linalg.norm(v) * T
                rr = first["radius"][k]
                # The rod's surface passes through the centre's column in the run.
                if lateral < rod["radius"] and ahead > rod["radius"] + rr and \
                        ahead < travel - rod["radius"] - rr:
                    j = ids_end[pid]
                    if np.array_equal(last["position"][j], first["position"][k]):
                        raise Failure(
                            "wall passed through a particle",
                            f"rod '{rod['name']}' at {np.linalg.norm(v):.4g} m/s swept over "
                            f"particle {pid} (r = {rr:.4g} m, {lateral:.3g} m off its path) "
                            f"without touching it (dt = {dt:.4g} s: "
                            f"{np.linalg.norm(v) * dt / rr:.3g} radii per step)")
    if d.meta["isolated"] and not d.meta["moving_walls"]:
        e = [kinetic_energy(s) + elastic_energy(scene, s) for s in snaps]
        e0 = e[0]
        # Tangential and rolling springs store energy that is not counted here, and velocity
        # Verlet's energy error within a contact at >= 5 steps per contact is a few per cent:
        # a rise above 5 % of E0 over the lowest earlier value is a gain, not noise (an
        # under-resolved impact multiplies the energy, docs/stability.md).
        lowest = e0
        for s, ek in zip(snaps[1:], e[1:]):
            if ek > lowest + 0.05 * e0 + 1e-300:
                raise Failure("energy rises", f"E = {ek:.6g} J at t = {s['time']:.6g} s, above "
                              f"the earlier lowest {lowest:.6g} J by {100 * (ek - lowest) / e0:.3g}"
                              f" % of E0 = {e0:.6g} J (isolated, dissipative)")
            lowest = min(lowest, ek)
    if d.meta["heat"]:
        check_heat(d, scene, snaps)
    if d.meta["momentum"] and removed == 0:
        p = [np.sum(s["mass"][:, None] * s["velocity"], axis=0) for s in snaps]
        scale = max(float(np.sum(snaps[0]["mass"] * np.linalg.norm(snaps[0]["velocity"],
                                                                   axis=1))), 1e-300)
        for s, pk in zip(snaps[1:], p[1:]):
            # Pair forces are equal and opposite: only round-off of the sums, ~1e-15 per step.
            if np.max(np.abs(pk - p[0])) > 1e-9 * scale:
                raise Failure("momentum not conserved",
                              f"|P - P0| = {np.max(np.abs(pk - p[0])):.3g} kg m/s at t = "
                              f"{s['time']:.6g} s, sum m|v| = {scale:.3g} (fully periodic, no "
                              "walls, gravity or fluid)")


def check_heat(d, scene, snaps):
    """Invariants of heat transfer and parcels (the thermal family)."""
    h = d.meta["heat"]
    mats = scene["materials"]
    for s in snaps:
        if not s["count"]:
            continue
        t = s.get("temperature")
        if t is None:
            raise Failure("no temperature", f"heat is on, but the snapshot at t = {s['time']} "
                          "holds no dataset 'temperature'")
        if not np.all(np.isfinite(t)) or np.any(t <= 0):
            i = int(np.argmin(np.where(np.isfinite(t), t, -np.inf)))
            raise Failure("temperature not finite and positive",
                          f"T = {t[i]} K (id {int(s['id'][i])}) at t = {s['time']:.6g} s")
        if h["bounds"]:
            lo, hi = h["bounds"]
            tol = 1e-9 * hi
            if t.min() < lo - tol or t.max() > hi + tol:
                raise Failure("temperature outside its bounds",
                              f"T in [{t.min():.12g}, {t.max():.12g}] K at t = {s['time']:.6g} "
                              f"s, outside [{lo}, {hi}] K, the initial, wall and fluid "
                              "temperatures (no source, no flux: a maximum principle)")
        # Each particle's k is one that an insertion asked for, and its class's.
        cg = s.get("coarse_grain")
        if cg is not None:
            allowed = set(h["ks"]) | {1.0}
            if not set(np.unique(cg).tolist()) <= allowed:
                raise Failure("coarse_grain", f"k values {sorted(set(cg.tolist()))} at t = "
                              f"{s['time']:.6g} s, asked {sorted(allowed)}")
            if "real_count" in s and np.max(np.abs(s["real_count"] - cg ** 3)) > 1e-9 * \
                    np.max(cg ** 3):
                raise Failure("real_count", f"real_count != k^3 at t = {s['time']:.6g} s")
            mk = s.get("material_coarse_grain")
            if mk is not None and np.any(mk[s["material"]] != cg):
                raise Failure("coarse_grain", f"a particle's k is not its class's at t = "
                              f"{s['time']:.6g} s")
    if not h["closed"] or not snaps[0]["count"]:
        return
    # Closed and adiabatic: sum m c T moves only by the sources, sum m q t.
    real = snaps[0].get("material_real")

    def listed(idx):
        return mats[int(real[idx]) if real is not None else int(idx)]

    first = snaps[0]
    mc = np.array([listed(i)["heat_capacity"] for i in first["material"]]) * first["mass"]
    q = np.array([listed(i).get("heat_source", 0.0) for i in first["material"]]) * first["mass"]
    e0 = float(np.sum(mc * first["temperature"]))
    order0 = np.argsort(first["id"])
    for s in snaps[1:]:
        if s["count"] != first["count"]:
            return  # a particle left (then the balance has a term this check does not see)
        order = np.argsort(s["id"])
        if not np.array_equal(s["id"][order], first["id"][order0]):
            return
        e = float(np.sum(mc[order0] * s["temperature"][order]))
        expected = e0 + float(np.sum(q)) * (s["time"] - first["time"])
        if abs(e - expected) > 1e-10 * abs(e0):
            raise Failure("heat not conserved",
                          f"sum m c T = {e:.15g} J at t = {s['time']:.6g} s, expected "
                          f"{expected:.15g} J (closed, adiabatic; sources {np.sum(q):.6g} W): "
                          f"off by {abs(e - expected) / e0:.3g} of it")


OVERLOAD_REMEDIES = [
    (re.compile(r"scale the Young's modulus by at least ([0-9.eE+-]+)"), "youngs_modulus"),
    (re.compile(r"set contact\.hooke\.stiffness\.normal to at least ([0-9.eE+-]+) N/m"),
     "hooke_stiffness"),
    (re.compile(r"raise contact\.hooke\.characteristic_velocity to at least ([0-9.eE+-]+) m/s"),
     "hooke_velocity"),
    (re.compile(r"lower cohesion_energy_density to at most ([0-9.eE+-]+) J/m\^3"), "cohesion"),
    (re.compile(r"set time\.max_overlap to at least ([0-9.eE+-]+)"), "max_overlap"),
]
OVERLOADED_PAIR = re.compile(r"(particles? \d+ and (?:\d+|a wall)) overlap by")


def apply_remedy(scene, kind, value):
    """The scene with one remedy of the overlap guard's message applied, as a user would."""
    s = json.loads(json.dumps(scene))
    if kind == "youngs_modulus":  # "..., and the partner's alike": every material
        for m in s["materials"]:
            m["youngs_modulus"] = float(f"{m['youngs_modulus'] * value:.6g}")
    elif kind == "hooke_stiffness":
        h = s["contact"].setdefault("hooke", {})
        h.pop("characteristic_velocity", None)
        h.setdefault("stiffness", {})["normal"] = value
    elif kind == "hooke_velocity":
        s["contact"]["hooke"]["characteristic_velocity"] = value
    elif kind == "cohesion":
        s["interaction_defaults"]["cohesion_energy_density"] = value
        for e in s.get("interactions", []):
            if "cohesion_energy_density" in e:
                e["cohesion_energy_density"] = value
    else:
        s["time"]["max_overlap"] = value
    return s


def touch_energy(msg, scene, workdir):
    """The energy an overloaded contact had at first touch, from the guard's message (the
    figures at the limit) and the pair's smaller radius (the run's last snapshot): approach
    energy + elastic energy at the limit (Hertz 2/5 F delta, Hooke 1/2 F delta) - (load +
    cohesion pull) delta. None when a figure is missing."""
    def num(pattern):
        m = re.search(pattern, msg)
        return float(m.group(1)) if m else 0.0
    pair = re.search(r"particles? (\d+) and (\d+|a wall) overlap by ([0-9.eE+-]+) %", msg)
    spring = re.search(r"the spring carries ([0-9.eE+-]+) N at the limit", msg)
    limit = re.search(r"limit ([0-9.eE+-]+) %, key time\.max_overlap", msg)
    if not (pair and spring and limit):
        return None
    ids = [int(pair.group(1))] + ([int(pair.group(2))] if pair.group(2) != "a wall" else [])
    try:
        last = read_snapshots(os.path.join(workdir, "out"))[-1]
    except (OSError, IndexError):
        return None
    index = {int(i): k for k, i in enumerate(last["id"])}
    if any(i not in index for i in ids):
        return None
    delta = float(limit.group(1)) / 100 * min(float(last["radius"][index[i]]) for i in ids)
    elastic = (0.4 if scene["contact"]["normal"] == "hertz" else 0.5) * float(spring.group(1))
    return (num(r"the approach brings ([0-9.eE+-]+) J") + elastic * delta -
            (num(r"press it with ([0-9.eE+-]+) N") + num(r"pulls it in with ([0-9.eE+-]+) N")) *
            delta)


def rerun_draw(d, dt_estimate):
    """The draw of an advice's rerun: the same files, checks, ranks and family as `d`."""
    d2 = Draw(d.seed, d.family)
    d2.files, d2.meta, d2.ranks, d2.family = d.files, d.meta, d.ranks, d.family
    d2.dt_estimate = dt_estimate
    return d2


def check_sink_advice(args, seed, d, scene, workdir, msg, seconds):
    """The temperature guard stopped the run: a particle is no longer above 0 K. The message
    names the keys that draw heat out at a fixed rate (a wall's negative heat_flux, a
    material's negative heat_source) and says to lower them. Each such value a tenth as
    strong must carry the run further: no stop by the temperature guard until after the
    first one (the other heat flows only bring temperatures towards the positive bounds)."""
    if "`heat_source`" not in msg or "`heat_flux`" not in msg:
        raise Failure("temperature guard without its keys", msg)
    m = FAIL_TIME.search(msg)
    t_fail = float(m.group(1)) if m else 0.0
    dt = d.dt_run or d.dt_estimate
    end = min(scene["time"]["end"], 2 * t_fail + 50 * dt)
    re_scene = json.loads(json.dumps(scene))
    for item in re_scene["materials"]:
        if item.get("heat_source", 0) < 0:
            item["heat_source"] = float(f"{item['heat_source'] / 10:.4g}")
    for wall in re_scene.get("walls", []):
        if wall.get("heat_flux", 0) < 0:
            wall["heat_flux"] = float(f"{wall['heat_flux'] / 10:.4g}")
    re_scene["time"]["end"] = float(f"{end:.6g}")
    re_scene["output"]["snapshot_interval"] = end / 8
    re_scene["output"].pop("checkpoint_interval", None)
    sub = os.path.join(workdir, "advice_sink")
    d2 = rerun_draw(d, dt)
    try:
        how, s2 = check_scene(args, seed, d2, re_scene, sub, 1)
    except Failure as f:
        raise Failure("rerun with a tenth of the heat sinks: " + f.cls, f.detail + f" [after: {msg}]")
    if how.startswith("stopped"):
        msg2 = error_line(open(os.path.join(sub, "grain.out")).read())
        m2 = FAIL_TIME.search(msg2)
        t2 = float(m2.group(1)) if m2 else 0.0
        if "not above 0 K" in msg2 and t2 <= t_fail:
            raise Failure("weaker sink does not get further",
                          f"stopped at t = {t2:.6g} s, the full sink at t = {t_fail:.6g} s: {msg}")
    return f"stopped by the temperature guard, a tenth of the sink {how}", seconds + s2


def check_overload_advice(args, seed, d, scene, workdir, msg, seconds):
    """The overlap guard stopped the run and found no step that prevents it; it lists what
    changes it. Each remedy it names, applied alone, must carry the run past that contact:
    the rerun ends, or stops later, or stops elsewhere (another pair, another cause)."""
    m = FAIL_TIME.search(msg)
    t_fail = float(m.group(1)) if m else 0.0
    pair = OVERLOADED_PAIR.search(msg)
    pair = pair.group(1) if pair else None
    dt = d.dt_run or d.dt_estimate
    end = min(scene["time"]["end"], 1.5 * t_fail + 50 * dt)
    tried = []
    for pattern, kind in OVERLOAD_REMEDIES:
        hit = pattern.search(msg)
        if not hit:
            continue
        value = float(hit.group(1))
        re_scene = apply_remedy(scene, kind, value)
        re_scene["time"]["end"] = float(f"{end:.6g}")
        re_scene["output"]["snapshot_interval"] = end / 8
        re_scene["output"].pop("checkpoint_interval", None)
        if kind == "youngs_modulus" and "step" not in re_scene["time"] and \
                end / (dt / math.sqrt(value)) > 2e5:
            continue  # too many steps to rerun here
        sub = os.path.join(workdir, f"advice_{kind}")
        d2 = rerun_draw(d, dt)
        try:
            how, s2 = check_scene(args, seed, d2, re_scene, sub, 1)
        except Failure as f:
            raise Failure(f"rerun with the advice ({kind} {value:g}): " + f.cls,
                          f.detail + f" [after: {msg}]")
        seconds += s2
        tried.append(kind)
        if how == "refused":
            raise Failure("advice refused", f"{kind} {value:g}, as the message says, is refused: "
                          f"{getattr(d2, 'message', '')} [after: {msg}]")
        if how.startswith("stopped"):
            msg2 = error_line(open(os.path.join(sub, "grain.out")).read())
            m2 = FAIL_TIME.search(msg2)
            t2 = float(m2.group(1)) if m2 else 0.0
            p2 = OVERLOADED_PAIR.search(msg2)
            same = p2 is not None and pair is not None and p2.group(1) == pair
            # In a bed the rerun's history differs, and the same pair may meet again in
            # another, harder event: the remedy was computed for the first one. Compare the
            # energy each event had at first touch (approach + elastic energy at the limit -
            # the work of the load and of the cohesion on the way in).
            e1, e2 = touch_energy(msg, scene, workdir), touch_energy(msg2, re_scene, sub)
            harder = e1 is not None and e2 is not None and e2 > 1.05 * e1
            if same and t2 <= t_fail * (1 + 1e-9) and not harder:
                raise Failure("advice does not get further",
                              f"with {kind} {value:g} the same contact ({pair}) stops again at "
                              f"t = {t2:.6g} s (first at {t_fail:.6g} s): {msg2} [after: {msg}]")
    return ("stopped, advice ran: " + "+".join(tried)) if tried else "stopped", seconds


RESTART_FIELDS = ("position", "velocity", "angular_velocity", "radius", "mass", "material",
                  "temperature", "coarse_grain")


def check_restart(args, d, workdir):
    """A run that ended: restarted from its checkpoint on as many ranks, it must end with
    the same particles bit for bit (docs/reliability.md, "Bit-identical on the same rank
    count"). Returns the restart's seconds (None: no checkpoint to restart from)."""
    outdir = os.path.join(workdir, "out")
    cps = sorted(n for n in os.listdir(outdir) if n.startswith("checkpoint_") and n.endswith(".h5"))
    if not cps:
        return None  # the run ended before its first checkpoint
    rc, out, seconds = run_grain(args, d.ranks, "scene.yaml", workdir, args.timeout,
                                 extra=("--restart", os.path.join("out", cps[-1])), output="out_restart")
    with open(os.path.join(workdir, "restart.out"), "w") as f:
        f.write(out)
    for pat, cls in FATAL_PATTERNS:
        if re.search(pat, out):
            raise Failure("restart: " + cls, error_line(out))
    if rc != 0:
        raise Failure("restart failed", f"exit {rc} restarting from {cps[-1]}: {error_line(out)}")
    # The summary's totals continue the run's: steps, particles, removed, rebuilds.
    summary = r"done: (\d+) steps, (\d+) particles \((\d+) removed\), (\d+) neighbour rebuilds"
    with open(os.path.join(workdir, "grain.out")) as f:
        ran = re.search(summary, f.read())
    again = re.search(summary, out)
    if ran and (not again or again.groups() != ran.groups()):
        raise Failure("restart differs",
                      f"restart from {cps[-1]}: '{again.group(0) if again else error_line(out)}', "
                      f"the run: '{ran.group(0)}'")
    a = read_snapshots(outdir)[-1]
    snaps = read_snapshots(os.path.join(workdir, "out_restart"))
    if not snaps:
        raise Failure("restart failed", "the restart wrote no snapshot")
    b = snaps[-1]
    if a["time"] != b["time"] or a["count"] != b["count"]:
        raise Failure("restart differs", f"last snapshot t = {b['time']!r} s, {b['count']} "
                      f"particles; the run's t = {a['time']!r} s, {a['count']} particles")
    ia, ib = np.argsort(a["id"]), np.argsort(b["id"])
    if not np.array_equal(a["id"][ia], b["id"][ib]):
        raise Failure("restart differs", f"other particle ids at t = {a['time']:.6g} s")
    for k in RESTART_FIELDS:
        if k not in a:
            continue
        x, y = a[k][ia], b[k][ib]
        if not np.array_equal(x, y):
            bad = np.nonzero(np.any((x != y).reshape(len(x), -1), axis=1))[0]
            i = int(bad[0])
            raise Failure("restart differs",
                          f"'{k}' of {len(bad)} particle(s) at t = {a['time']:.6g} s after a restart "
                          f"from {cps[-1]} on {d.ranks} rank(s), e.g. id {int(a['id'][ia][i])}: "
                          f"{x[i]!r} != {y[i]!r}")
    return seconds


def run_dt(scene):
    """The step a scene runs with: given, or from its line in the start-up report."""
    return scene["time"].get("step")


def startup_dt(out):
    m = re.search(r"\bdt = ([0-9.eE+-]+) s", out)
    return float(m.group(1)) if m else None


def check_scene(args, seed, d, scene, workdir, depth=0):
    """Runs one scene; returns a note on success, raises Failure otherwise."""
    os.makedirs(workdir, exist_ok=True)
    for name, text in d.files.items():
        with open(os.path.join(workdir, name), "w") as f:
            f.write(text)
    path = os.path.join(workdir, "scene.yaml")
    with open(path, "w") as f:
        f.write(scene_yaml(seed, scene, d))
    shutil.rmtree(os.path.join(workdir, "out"), ignore_errors=True)
    rc, out, seconds = run_grain(args, d.ranks, "scene.yaml", workdir, args.timeout)
    with open(os.path.join(workdir, "grain.out"), "w") as f:
        f.write(out)
    d.dt_run = scene["time"].get("step") or startup_dt(out) or d.dt_estimate
    for pat, cls in FATAL_PATTERNS:
        if re.search(pat, out):
            hit = [ln.strip() for ln in out.splitlines() if re.search(pat, ln)]
            raise Failure(cls, hit[0] if hit else out[-300:])
    if rc is None:
        raise Failure("timeout", f"no end after {args.timeout} s; last output: {out[-200:]!r}")
    if rc < 0:
        raise Failure("signal", f"killed by signal {-rc}")
    if rc == 0:
        check_output(d, scene, workdir, out)
        if depth == 0 and not args.no_restarts:
            s2 = check_restart(args, d, workdir)
            if s2 is not None:
                return "ran, restart identical", seconds + s2
        return "ran", seconds
    if rc not in (1, 2):
        raise Failure(f"exit {rc}", error_line(out))
    msg = error_line(out)
    m = re.search(r"particles\.csv:(\d+):", msg)
    if m and int(m.group(1)) in d.meta.get("csv_valid_lines", ()):
        raise Failure("valid CSV row refused", msg)
    if "error" not in msg:
        raise Failure("exit 1 without an error message", out[-300:])
    if not ADVICE_WORDS.search(msg.split("error", 1)[1]):
        raise Failure("message without a remedy", msg)
    d.message = msg
    if "non-finite" in msg and "fluid" in scene:
        # Issue 17: the NaN guard names the enabled force terms (and their dt / limit ratios).
        silent = [f for f in scene["fluid"]["forces"] if f not in msg]
        if silent:
            raise Failure("NaN guard silent on the force terms",
                          f"enabled {', '.join(scene['fluid']['forces'])}, not named: "
                          f"{', '.join(silent)}: {msg}")
    if "not above 0 K" in msg and depth == 0 and not args.no_advice:
        return check_sink_advice(args, seed, d, scene, workdir, msg, seconds)
    proposals = [float(v) for v in STEP_PROPOSAL.findall(msg)]
    if "No time step prevents this" in msg and depth == 0 and not args.no_advice:
        return check_overload_advice(args, seed, d, scene, workdir, msg, seconds)
    if not proposals or depth >= 2:
        return ("refused" if rc == 2 else "stopped"), seconds
    dt_ran = d.dt_run
    step = min(proposals)
    if dt_ran and step >= dt_ran * (1 - 1e-9):
        raise Failure("proposed step not smaller",
                      f"proposes {step:.4g} s after running with dt = {dt_ran:.4g} s: {msg}")
    m = FAIL_TIME.search(msg)
    t_fail = float(m.group(1)) if m else 0.0
    # Rerun with the proposal, far enough to pass the point of failure, at most 2e5 steps.
    end = min(scene["time"]["end"], t_fail + 20 * (dt_ran or step))
    if end / step > 2e5:
        return "stopped (proposal not rerun: over 2e5 steps)", seconds
    re_scene = json.loads(json.dumps(scene))
    re_scene["time"].pop("rayleigh_fraction", None)
    re_scene["time"]["step"] = float(f"{step:.6g}")
    re_scene["time"]["end"] = float(f"{end:.6g}")
    re_scene["output"]["snapshot_interval"] = end / 8
    sub = os.path.join(workdir, f"rerun{depth + 1}")
    d2 = rerun_draw(d, step)
    try:
        how, s2 = check_scene(args, seed, d2, re_scene, sub, depth + 1)
    except Failure as f:
        raise Failure("rerun with the proposed step: " + f.cls, f.detail + f" [after: {msg}]")
    if how.startswith("stopped"):
        msg2 = error_line(open(os.path.join(sub, "grain.out")).read())
        m2 = FAIL_TIME.search(msg2)
        t2 = float(m2.group(1)) if m2 else 0.0
        # The finer step resolved the contact and the rerun names the cause behind it (an
        # overload that no step prevents): the advice did its work even if that stop comes
        # sooner than the coarse run's.
        if t2 <= t_fail and "No time step prevents this" in msg2:
            return "stopped, proposal showed the overload", seconds + s2
        if t2 <= t_fail:
            raise Failure("proposed step does not get further",
                          f"stopped at t = {t2:.6g} s after stopping at t = {t_fail:.6g} s with "
                          f"dt = {dt_ran:.4g} s; proposal {step:.4g} s: {msg}")
    return f"stopped, proposal {how}", seconds + s2


class Cores:
    """The N cores of --jobs N, counted out to the running seeds: a seed of r ranks holds
    min(r, N) of them (one wider than N runs alone), and no two seeds of one key (one work
    folder: a seed listed twice) run at once. One counter under one condition: a seed takes
    all its cores at once or waits, so no two seeds each hold part of what the other needs."""

    def __init__(self, n):
        self.n, self.used, self.keys = n, 0, set()
        self.changed = threading.Condition()

    def take(self, ranks, key, stop=lambda: False):
        """Waits until the cores are free (or stop() holds); returns how many it took."""
        need = min(max(ranks, 1), self.n)
        with self.changed:
            self.changed.wait_for(lambda: stop() or (self.used + need <= self.n and
                                                     key not in self.keys))
            self.used += need
            self.keys.add(key)
        return need

    def give(self, need, key):
        with self.changed:
            self.used -= need
            self.keys.discard(key)
            self.changed.notify_all()


def run_concurrently(jobs, tasks, may_start, ended):
    """Runs tasks side by side on threads (the work is in the `grain` subprocesses): `tasks`
    yields (ranks, key, run) in order; each starts, in that order, once Cores(jobs) has its
    ranks' cores and may_start() holds (False: stop starting, as --budget does). ended(i,
    result) is called as each task ends, one at a time, with the task's index and the value
    run() returned. Returns the number of tasks started. A task that raises stops the
    starting; the first such exception is raised here once the running tasks have ended."""
    cores = Cores(jobs)
    lock = threading.Lock()
    errors, threads = [], []

    def work(i, need, key, run):
        try:
            result = run()
            with lock:
                ended(i, result)
        except BaseException as e:  # raised again by the main thread
            with lock:
                errors.append(e)
        finally:
            cores.give(need, key)

    for i, (ranks, key, run) in enumerate(tasks):
        need = cores.take(ranks, key, stop=lambda: bool(errors))
        if errors or not may_start():
            cores.give(need, key)
            break
        t = threading.Thread(target=work, args=(i, need, key, run), name=f"task {i}")
        t.start()
        threads.append(t)
    for t in threads:
        t.join()
    if errors:
        raise errors[0]
    return len(threads)


STOP_CAUSES = [
    ("key time.min_steps_per_contact", "steps-per-contact guard"),
    ("key time.max_step_travel", "travel guard"),
    ("key time.max_overlap", "overlap guard"),
    ("dt is too large", "start-up step refusal"),
    ("refusing to run with this time step", "start-up step refusal"),
    ("non-finite", "NaN guard"),
    ("not above 0 K", "temperature guard"),
    ("overlaps an earlier particle", "CSV overlap refused"),
    ("wall", "insertion against a wall"),
]


def summarise(path):
    """Counts of a --report file: outcomes, failure classes with seeds, what stopped runs."""
    rows = [json.loads(line) for line in open(path) if line.strip()]
    print(f"{len(rows)} scenes")
    by = {}
    for r in rows:
        key = r["result"] if r["result"] == "FAIL" else r["result"].split(",")[0].split(" (")[0]
        by[key] = by.get(key, 0) + 1
    print("outcomes: " + ", ".join(f"{k} {v}" for k, v in sorted(by.items())))
    fam = {}
    for r in rows:
        f = fam.setdefault(r["family"], [0, 0])
        f[0] += 1
        f[1] += r["result"] == "FAIL"
    print("families (scenes, failed): " + ", ".join(f"{k} {v[0]}/{v[1]}" for k, v in fam.items()))
    stops = {}
    for r in rows:
        msg = r.get("message") or ""
        if r["result"] != "FAIL" and msg:
            cause = next((c for pat, c in STOP_CAUSES if pat in msg), "other")
            stops.setdefault(cause, []).append(r["seed"])
    for c, ss in sorted(stops.items(), key=lambda kv: -len(kv[1])):
        print(f"  stopped by {c}: {len(ss)}")
    classes = {}
    for r in rows:
        if r["result"] == "FAIL":
            classes.setdefault(r["class"], []).append(r)
    for c, rs in sorted(classes.items(), key=lambda kv: -len(kv[1])):
        print(f"  FAIL {len(rs):4d} {c}: seeds {' '.join(str(r['seed']) for r in rs)}")
        print(f"       e.g. seed {rs[0]['seed']}: {rs[0]['detail'][:400]}")


def check_seed(args, seed, d, scene):
    """One drawn seed checked in its own folder under --work, seed_<seed> (removed when it
    passes, unless --keep): (its --report line, its result line, (seed, d, Failure, folder)
    when it failed, else None)."""
    workdir = os.path.abspath(os.path.join(args.work, f"seed_{seed}"))
    shutil.rmtree(workdir, ignore_errors=True)
    t0 = time.monotonic()
    head = f"seed {seed:6d} {d.family:13s} {d.ranks}r {'+'.join(combo_of(seed)):28s} "
    try:
        how, _ = check_scene(args, seed, d, scene, workdir)
    except Failure as f:
        line = {"seed": seed, "family": d.family, "ranks": d.ranks, "result": "FAIL",
                "class": f.cls, "detail": f.detail}
        return line, head + f"{time.monotonic() - t0:6.2f} s  FAIL {f.cls}: {f.detail}", \
            (seed, d, f, workdir)
    msg = getattr(d, "message", "")
    line = {"seed": seed, "family": d.family, "ranks": d.ranks, "result": how, "message": msg}
    text = head + f"{time.monotonic() - t0:6.2f} s  ok ({how})" + \
        (f": {msg[:200]}" if args.verbose and msg else "")
    if not args.keep:
        shutil.rmtree(workdir, ignore_errors=True)
    return line, text, None


def run_seeds_concurrently(args, seeds, extra, report, start):
    """--jobs N > 1: the seeds side by side, the ranks of the running ones summing to at most
    N (run_concurrently). Result lines print as seeds end; the --report lines are written in
    the seeds' order, each once the seeds before it have ended. --budget stops the starting
    of seeds. Returns (scenes done, failures in the seeds' order), as the sequential loop."""
    results = {}
    written = [0]
    budget_used = []

    def tasks():
        for seed in seeds:
            if args.family and not extra and FAMILIES[seed % len(FAMILIES)] != args.family:
                continue
            d, scene = draw(seed, extra)
            if args.ranks != "mixed":
                d.ranks = int(args.ranks)
            yield d.ranks, seed, (lambda seed=seed, d=d, scene=scene:
                                  check_seed(args, seed, d, scene))

    def may_start():
        if args.budget and time.monotonic() - start > args.budget:
            budget_used.append(True)
            return False
        return True

    def ended(i, result):
        results[i] = result
        print(result[1], flush=True)
        while report and written[0] in results:
            report.write(json.dumps(results[written[0]][0]) + "\n")
            report.flush()
            written[0] += 1

    run_concurrently(args.jobs, tasks(), may_start, ended)
    done = len(results)
    if budget_used:
        print(f"time budget of {args.budget:g} s used after {done} scenes")
    return done, [results[i][2] for i in sorted(results) if results[i][2]]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grain")
    ap.add_argument("--summarise", metavar="REPORT", help="summarise a --report file and exit")
    ap.add_argument("--mpiexec", default="mpiexec")
    ap.add_argument("--seed", type=int, help="one scene")
    ap.add_argument("--seeds", type=parse_seeds, help="ranges A:B (B excluded) and seeds, comma-separated: 0:16,608")
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--count", type=int, default=40)
    ap.add_argument("--budget", type=float, default=0, help="stop after this many seconds")
    ap.add_argument("--ranks", choices=["mixed", "1", "2"], default="mixed",
                    help="mixed: every third seed on 2 ranks")
    ap.add_argument("--timeout", type=float, default=60, help="per run [s]")
    ap.add_argument("--work", default="hard_scenes_work")
    ap.add_argument("--keep", action="store_true", help="keep the folders of passing scenes")
    ap.add_argument("--print-scene", action="store_true", help="print the seed's YAML, no run")
    ap.add_argument("--report", help="write a JSON line per scene to this file")
    ap.add_argument("--family", choices=FAMILIES + EXTRA_FAMILIES,
                    help="run only the seeds of this family; an extra family (thermal) draws "
                         "its own scene for every seed")
    ap.add_argument("--verbose", action="store_true", help="print the message of each stop")
    ap.add_argument("--no-advice", action="store_true",
                    help="do not rerun the overlap guard's remedies")
    ap.add_argument("--no-restarts", action="store_true",
                    help="do not restart the runs that ended from their checkpoint")
    ap.add_argument("--jobs", type=int, default=1, metavar="N",
                    help="run seeds side by side on N cores, the running seeds' ranks summing "
                         "to at most N (a seed of more ranks runs alone); result lines print "
                         "as seeds end, the summary and --report as in seed order (default 1)")
    args = ap.parse_args()
    if args.jobs < 1:
        ap.error(f"--jobs: {args.jobs} is not a count of cores >= 1")
    if args.summarise:
        summarise(args.summarise)
        return 0
    if not args.grain:
        ap.error("--grain is required")
    if os.sep in args.grain:
        args.grain = os.path.abspath(args.grain)
    if args.seed is not None:
        seeds = [args.seed]
    elif args.seeds:
        seeds = args.seeds
    else:
        seeds = list(range(args.first, args.first + args.count))
    os.makedirs(args.work, exist_ok=True)
    report = open(args.report, "a") if args.report else None
    start = time.monotonic()
    failures = []
    done = 0
    extra = args.family if args.family in EXTRA_FAMILIES else None
    if args.jobs > 1 and not args.print_scene:
        done, failures = run_seeds_concurrently(args, seeds, extra, report, start)
    else:
        for seed in seeds:
            if args.budget and time.monotonic() - start > args.budget:
                print(f"time budget of {args.budget:g} s used after {done} scenes")
                break
            if args.family and not extra and FAMILIES[seed % len(FAMILIES)] != args.family:
                continue
            d, scene = draw(seed, extra)
            if args.ranks != "mixed":
                d.ranks = int(args.ranks)
            if args.print_scene:
                print(scene_yaml(seed, scene, d))
                continue
            line, text, failure = check_seed(args, seed, d, scene)
            print(text, flush=True)
            if failure:
                failures.append(failure)
            if report:
                report.write(json.dumps(line) + "\n")
                report.flush()
            done += 1
    if args.print_scene:
        return 0
    elapsed = time.monotonic() - start
    print(f"\n{done} scenes in {elapsed:.1f} s, {len(failures)} failed")
    classes = {}
    for seed, d, f, _ in failures:
        classes.setdefault(f.cls, []).append(seed)
    for cls, ss in sorted(classes.items(), key=lambda kv: -len(kv[1])):
        print(f"  {len(ss):4d}  {cls}: seeds {' '.join(map(str, ss))}")
    for seed, d, f, workdir in failures:
        print(f"\n--- seed {seed} failed ({f.cls}); scene {workdir}/scene.yaml; rerun with "
              f"--seed {seed}:")
        with open(os.path.join(workdir, "scene.yaml")) as fh:
            print(fh.read())
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
