#!/usr/bin/env python3
"""A model of how grain's DEM bed and grainFoam's coupled bed scale past this machine.

    benchmarks/scaling_model/model.py --measure [--build DIR]   # counts on 1, 2, 4, 8 ranks
    benchmarks/scaling_model/model.py                           # the model from the last counts
    benchmarks/scaling_model/model.py --fluid [--np 4]          # grainFoam's counts per fluid step

--measure runs bench_strong_scaling (a dense FCC bed of 100 000 spheres) on 1, 2, 4 and 8 ranks
(4 and 8 oversubscribed: the counts do not depend on the cores) with the MPI profiling layer
mpi_count.c preloaded, and stores what every rank owns, holds as ghosts, evaluates as pairs,
sends and reduces per step in DIR/scaling_model/measured.json. The model then

  1. fits the ghost layer's width to the measured ghost counts and checks it on every run;
  2. predicts the messages, bytes and reductions per step on 4 and 8 ranks from the 1- and
     2-rank runs and prints them against the measured ones;
  3. predicts the 1 -> 2 rank speed-up from the 1-rank time per particle-step and compares it
     with docs/parallel-scaling.md's measurement;
  4. extrapolates strong and weak scaling of the DEM bed and of a coupled bed to 64, 256 and
     1024 ranks on the cluster network below, with the part that stops scaling first;
  5. with the counts of --fluid on 2 and 4 ranks, predicts the 4-rank counts from the 2-rank
     ones, and the coupled tutorial's 1 -> 2 rank speed-up, against the measured ones.

--fluid [--np N] counts grainFoam's allreduces and messages per fluid step and rank on N ranks
(default 2), and tells from each call's stack whether the DEM, the coupling or the PIMPLE loop
made it; it stores them in DIR/scaling_model/fluid_npN.json.

The formulas, the network and the limits are explained in docs/scaling-model.md; this script
prints its tables.
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

# ---- measured on this machine, quiet (sources in docs/scaling-model.md) -------------------
T_PS_DENSE = 1 / 2.78e6    # s per particle-step, dense FCC bed, 1 rank (docs/parallel-scaling.md)
SPEEDUP_DENSE_2 = 1.75     # its measured 1 -> 2 rank speed-up (same page)
PAIR_SHARE = 0.75          # share of a step's time that scales with the pairs evaluated
                           # (pair sweep 68 % + walls 7 % of the loop, docs/performance.md)
# The coupled bed, from the fluidisedBed tutorial (12 000 beads, 4 800 cells, 20 DEM steps per
# fluid step): its CPU time split on 1 rank over the first 100 fluid steps (DEM 57.3 %,
# coupling 16.1 %, fluid 26.6 %; on 1 rank no part waits for another rank, so the split is the
# compute alone). The settled-bed rate of docs/performance.md, 1.48e7 particle-steps/s,
# stands for its DEM.
T_PS_BED = 1 / 1.48e7
FB = dict(beads=12000, cells=4800, substeps=20, dem=0.573, coupling=0.161, fluid=0.266)

# ---- the cluster the model assumes ------------------------------------------------------
NET = dict(
    alpha=1.5e-6,          # s, point-to-point latency of a small message between nodes
    alpha_node=0.4e-6,     # s, the same within a node (shared memory)
    node_bw=12.5e9,        # B/s, a node's injection bandwidth (InfiniBand HDR100, 100 Gb/s)
    rank_bw_node=5e9,      # B/s, one rank's copy bandwidth within a node
    ranks_per_node=64,     # 2 sockets x 32 cores
    allreduce_level=1.5e-6,  # s per level of a small allreduce's tree (log2 P levels)
)


def mpirun(np_, args, env):
    base = ["mpirun", "-np", str(np_), "--oversubscribe"]
    for k in env:
        base += ["-x", k]
    e = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", **env)
    return subprocess.run(base + args, env=e, check=True, capture_output=True, text=True).stdout


def build_mpi_count(out_dir):
    """The profiling layer, compiled when its source is newer than the library."""
    lib, src = os.path.join(out_dir, "libmpi_count.so"), os.path.join(HERE, "mpi_count.c")
    if not os.path.exists(lib) or os.path.getmtime(lib) < os.path.getmtime(src):
        subprocess.run(["mpicc", "-O2", "-shared", "-fPIC", "-o", lib, src], check=True)
    return lib


def measure(build, particles, steps):
    out_dir = os.path.join(build, "scaling_model")
    os.makedirs(out_dir, exist_ok=True)
    lib = build_mpi_count(out_dir)
    runs = {}
    for np_ in (1, 2, 4, 8):
        counts = os.path.join(out_dir, f"counts_{np_}.txt")
        if os.path.exists(counts):
            os.remove(counts)
        text = mpirun(np_, [os.path.join(build, "bin", "bench_strong_scaling"), "--particles",
                            str(particles), "--steps", str(steps)],
                      {"LD_PRELOAD": lib, "MPI_COUNT_OUT": counts})
        print(text, end="")
        head = dict(kv.split("=") for kv in text.splitlines()[0].split())
        ranks = [{k: int(v) for k, v in (kv.split("=") for kv in line.split())}
                 for line in text.splitlines() if line.startswith("rank=")]
        traffic = {}
        for line in open(counts):
            d = dict(kv.split("=") for kv in line.split())
            if d["epoch"] != "1":  # the timed loop (between the benchmark's two barriers)
                continue
            r = int(d["rank"])
            traffic.setdefault(r, {})[d["kind"]] = dict(calls=int(d["calls"]) / steps,
                                                         bytes=int(d["bytes"]) / steps)
        for rk in ranks:
            rk["per_step"] = traffic.get(rk["rank"], {})
        runs[np_] = dict(particles=int(head["particles"]), contacts=int(head["contacts"]), ranks=ranks)
    path = os.path.join(out_dir, "measured.json")
    json.dump(dict(steps=steps, runs=runs), open(path, "w"), indent=1)
    print("wrote", path)
    return path


_SYMBOL_TABLES = {}


def symbolise(stack_lines):
    """The function names of the frames in mpi_count's stack lines (MODULE+0xOFFSET), looked up
    in each module's symbol table (nm; the dynamic table where a library has no other)."""
    tables = _SYMBOL_TABLES

    def table(mod):
        if mod not in tables:
            rows = []
            for opt in ([], ["-D"]):
                try:
                    out = subprocess.run(["nm", "-C", "-n", "--defined-only"] + opt + [mod],
                                         capture_output=True, text=True).stdout
                except OSError:
                    out = ""
                for line in out.splitlines():
                    parts = line.split(" ", 2)
                    if len(parts) == 3 and parts[1] in "TtWw":
                        rows.append((int(parts[0], 16), parts[2]))
                if rows:
                    break
            tables[mod] = ([r[0] for r in rows], [r[1] for r in rows])
        return tables[mod]

    import bisect
    names = []
    for frame in stack_lines:
        mod, _, off = frame.rpartition("+0x")
        addrs, syms = table(mod) if mod != "?" else ([], [])
        i = bisect.bisect_right(addrs, int(off, 16) - 1) - 1  # a return address: the call is before it
        names.append(syms[i] if i >= 0 else f"{os.path.basename(mod)}+0x{off}")
    return names


# Who made an MPI call, from its call stack (the first rule that matches a frame, outermost
# rules first): the DEM's steps, the coupling (ParticleCoupling and the DEM link's exchanges
# outside the steps), else the fluid (the PIMPLE loop), split into the pressure solver
# (GAMG), the other linear solvers, and the rest (fvc operators, boundary updates, continuity
# errors, Courant number).
def who(names):
    text = "\n".join(names)
    if "DemLink::advance" in text:
        return "DEM"
    if "ParticleCoupling::" in text or "DemLink::" in text:
        return "coupling"
    if "GAMG" in text:
        return "fluid: GAMG (p)"
    if "Solver::solve" in text or "lduMatrix::solve" in text or "fvMatrix" in text and "::solve" in text:
        return "fluid: other solves"
    return "fluid: rest"


PARTS = ("DEM", "coupling", "fluid: GAMG (p)", "fluid: other solves", "fluid: rest")


def measure_fluid(build, np_=2, ends=("0.009", "0.024")):
    """grainFoam's messages and reductions per fluid step and rank, by who makes them:
    fluidisedBed --short on np_ ranks, run to ends[0] and to ends[1] (by default 0.009 s and
    0.024 s: 30 and 80 fluid steps; no write time in either) with mpi_count preloaded, the two
    runs side by side; the difference of their totals over the fluid steps between."""
    import glob
    import shutil
    import yaml
    out_dir = os.path.join(build, "scaling_model")
    os.makedirs(out_dir, exist_ok=True)
    lib = build_mpi_count(out_dir)
    tut = os.path.join(ROOT, "tutorials", "cfd-dem")
    runs = {}
    for end in ends:
        case = os.path.join(out_dir, f"fluidisedBed_np{np_}_{end}")
        shutil.rmtree(case, ignore_errors=True)
        shutil.copytree(os.path.join(tut, "fluidisedBed"), case)
        # No write time inside either run (the write-time sums and checks are not per step).
        ctl = os.path.join(case, "system", "controlDict")
        text = re.sub(r"^writeInterval .*$", "writeInterval   100000;", open(ctl).read(), flags=re.M)
        open(ctl, "w").write(text)
        # The short scene of Allrun --short: 2000 beads poured from 2-20 mm.
        scene = yaml.safe_load(open(os.path.join(case, "particles.yaml")))
        scene["insert"][0]["count"] = 2000
        scene["insert"][0]["region"]["box"]["max"][2] = 0.02
        yaml.safe_dump(scene, open(os.path.join(case, "particles_short.yaml"), "w"), sort_keys=False)
        open(os.path.join(case, "system", "shortRun.coupling"), "w").write('scene "particles_short.yaml";\n')
        open(os.path.join(case, "system", "shortRun"), "w").write(f"endTime {end};\n")
        counts = os.path.join(out_dir, f"fluid_counts_np{np_}_{end}.txt")
        stacks = os.path.join(out_dir, f"fluid_stacks_np{np_}_{end}")
        for f in [counts] + glob.glob(stacks + ".*"):
            os.remove(f) if os.path.exists(f) else None
        script = f"set -e; cd {case}; source {tut}/run_case.sh; run_case -np {np_}"
        env = dict(os.environ, GRAINFLOW_SOURCE_DIR=ROOT, GRAINFLOW_BUILD_DIR=build,
                   OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                   # A waiting rank yields its core: on a shared or oversubscribed machine the
                   # runs finish sooner, and the counts are the same.
                   OMPI_MCA_mpi_yield_when_idle="1",
                   OMPI_MCA_mca_base_env_list=f"LD_PRELOAD={lib};MPI_COUNT_OUT={counts};MPI_COUNT_STACKS={stacks}")
        runs[end] = (subprocess.Popen(["bash", "-c", script], env=env, stdout=subprocess.DEVNULL), stacks)
    for end, (proc, stacks) in runs.items():
        if proc.wait() != 0:
            sys.exit(f"model.py --fluid: the run to {end} s failed (see its log.grainFoam)")
    return tally_fluid(out_dir, np_, ends)


def tally_fluid(out_dir, np_, ends):
    """The calls per fluid step, rank, kind and part from the stack files of measure_fluid's
    two runs; printed, and stored in fluid_npN.json."""
    import glob
    totals = {}
    for end in ends:
        stacks = os.path.join(out_dir, f"fluid_stacks_np{np_}_{end}")
        t = {}
        for path in glob.glob(stacks + ".*"):
            for line in open(path):
                head, _, stack = line.rstrip("\n").partition(" stack=")
                d = dict(kv.split("=") for kv in head.split())
                if d["kind"] not in ("allreduce", "p2p"):
                    continue
                names = symbolise(stack.split(";"))
                key = (int(d["rank"]), d["kind"], who(names))
                t[key] = t.get(key, 0) + int(d["calls"])
                # The calls of grain's own exchanges (one per direction along a cut axis,
                # MPI_PROC_NULL where a rank has no neighbour), within the coupling's.
                if key[2] == "coupling" and any("grainflow::Exchange::" in n for n in names):
                    k2 = key[:2] + ("coupling: grain exchanges",)
                    t[k2] = t.get(k2, 0) + int(d["calls"])
        totals[end] = t
    steps = round((float(ends[1]) - float(ends[0])) / 3e-4)
    per = {k: (totals[ends[1]].get(k, 0) - totals[ends[0]].get(k, 0)) / steps
           for k in set(totals[ends[0]]) | set(totals[ends[1]])}
    print(f"grainFoam, fluidisedBed --short (2000 beads, 4 800 cells), {np_} ranks: calls per fluid step "
          f"(over fluid steps {round(float(ends[0]) / 3e-4)}-{round(float(ends[1]) / 3e-4)})\n")
    print("| rank | kind | " + " | ".join(PARTS) + " | total |")
    print("|---:|---|" + "---:|" * (len(PARTS) + 1))
    for r in range(np_):
        for kind in ("allreduce", "p2p"):
            row = [per.get((r, kind, w), 0.0) for w in PARTS]
            print(f"| {r} | {kind} | " + " | ".join(f"{x:.1f}" for x in row) + f" | {sum(row):.1f} |")
    # GAMG's cycles for p per fluid step over the same steps, from the longer run's log.
    t, cycles, steps_seen = None, 0, set()
    for line in open(os.path.join(out_dir, f"fluidisedBed_np{np_}_{ends[1]}", "log.grainFoam")):
        m = re.match(r"^Time = (\S+)", line)
        if m:
            t = float(m.group(1))
        m = re.search(r"GAMG:  Solving for p,.*No Iterations (\d+)", line)
        if m and t is not None and t > float(ends[0]) + 1e-9:
            cycles += int(m.group(1))
            steps_seen.add(t)
    per_cycle = cycles / max(len(steps_seen), 1)
    print(f"\nGAMG cycles for p per fluid step: {per_cycle:.2f}; per cycle, rank 0: "
          f"{per.get((0, 'allreduce', PARTS[2]), 0) / per_cycle:.1f} allreduces, "
          f"{per.get((0, 'p2p', PARTS[2]), 0) / per_cycle:.1f} messages")
    out = {f"{r} {k} {w}": v for (r, k, w), v in sorted(per.items())}
    out["gamg_cycles"] = per_cycle
    json.dump(out, open(os.path.join(out_dir, f"fluid_np{np_}.json"), "w"), indent=1)
    return per


# ---- the model ----------------------------------------------------------------------------
R, SKIN = 1e-3, 0.4e-3
PHI_DENSE = math.pi / (3 * math.sqrt(2))        # FCC
RHO_DENSE = PHI_DENSE / (4 / 3 * math.pi * R ** 3)  # spheres per m^3


def ghosts_cube(n, rho, w):
    """Ghosts of a cubic box holding n spheres, a layer w deep on all six sides (3D cut)."""
    L = (n / rho) ** (1 / 3)
    return rho * ((L + 2 * w) ** 3 - L ** 3)


def allreduce_time(p):
    return 0.0 if p == 1 else NET["allreduce_level"] * math.ceil(math.log2(p))


def comm_time(p, ghosts, bytes_per_ghost, messages, reductions):
    """One step's communication of one rank on the cluster (latency + bandwidth + reductions)."""
    if p == 1:
        return 0.0
    rpn = NET["ranks_per_node"]
    # A node holds a cube of ranks; the share of a rank's faces that leave the node:
    side = round(min(p, rpn) ** (1 / 3))
    off = 0.0 if p <= rpn else 1.0 / side
    lat = messages * ((1 - off) * NET["alpha_node"] + off * NET["alpha"])
    b = ghosts * bytes_per_ghost
    bw = (1 - off) * b / NET["rank_bw_node"] + off * b * rpn / NET["node_bw"]
    return lat + bw + reductions * allreduce_time(p)


def report(path):
    m = json.load(open(path))
    runs = {int(k): v for k, v in m["runs"].items()}
    one = runs[1]["ranks"][0]
    N = runs[1]["particles"]
    print(f"## Measured per rank and step (dense FCC bed, {N} spheres; {m['steps']} timed steps)\n")
    print("| ranks | owned | ghosts | ghosts / owned | pairs evaluated / ideal | p2p messages | bytes sent | bytes per ghost | allreduces |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    pairs1 = one["list_pairs"] + one["ghost_pairs"]
    for p, run in sorted(runs.items()):
        for rk in run["ranks"][:1] if p == 1 else run["ranks"]:
            ps = rk["per_step"]
            msg = ps.get("p2p", {}).get("calls", 0)
            byt = ps.get("p2p", {}).get("bytes", 0)
            ar = ps.get("allreduce", {}).get("calls", 0)
            pe = (rk["list_pairs"] + rk["ghost_pairs"]) / (pairs1 / p)
            print(f"| {p} (rank {rk['rank']}) | {rk['local']} | {rk['ghosts']} | {rk['ghosts']/rk['local']:.3f} | "
                  f"{pe:.3f} | {msg:.0f} | {byt/1e6:.3f} MB | {byt/max(rk['ghosts'],1):.0f} | {ar:.0f} |")

    # The ghost layer: fit its depth w to the 1-rank run (x and y periodic: four faces of the bed).
    bed_h = one["local"] / (RHO_DENSE * (16 * math.sqrt(8) * R * 0.999) ** 2)
    side = 16 * math.sqrt(8) * R * 0.999
    w = one["ghosts"] / (RHO_DENSE * 4 * side * bed_h)
    bpg = one["per_step"]["p2p"]["bytes"] / one["ghosts"]
    lam_g = one["ghost_pairs"] / one["ghosts"]
    print(f"\nghost layer depth fitted on 1 rank: w = {w*1e3:.2f} mm = {w/R:.2f} r "
          f"(the list's reach 2 r + skin = {(2*R+SKIN)/R:.1f} r); pairs per ghost {lam_g:.2f}; "
          f"{bpg:.0f} B per ghost and step\n")

    # Check: messages and bytes of 4 and 8 ranks predicted from the geometry of their boxes.
    print("| ranks | ghosts / rank, predicted (mean) | measured (mean) | messages / rank, predicted | measured | allreduces / step, predicted | measured |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    for p in (2, 4, 8):
        run = runs[p]
        rks = run["ranks"]
        mean_g = sum(r["ghosts"] for r in rks) / len(rks)
        # Predicted: the rank's box is the bed cut into p slabs along z (the grid the
        # least-cut-area rule picks for a tall bed), plus the periodic x/y faces.
        h = bed_h / p
        g_pred = RHO_DENSE * w * (4 * side * h) + RHO_DENSE * w * side * side * (2 * (p - 1) / p)
        mean_msg = sum(r["per_step"]["p2p"]["calls"] for r in rks) / len(rks)
        mean_ar = sum(r["per_step"]["allreduce"]["calls"] for r in rks) / len(rks)
        print(f"| {p} | {g_pred:.0f} | {mean_g:.0f} | 6 | {mean_msg:.1f} | 2 | {mean_ar:.1f} |")

    # Check: the 1 -> 2 rank speed-up from the compute model.
    def step_cost(n, pairs_eval, n1, pairs1_, t_ps):
        per_particle = t_ps * (1 - PAIR_SHARE)
        per_pair = t_ps * PAIR_SHARE * n1 / pairs1_
        return per_particle * n + per_pair * pairs_eval
    r2 = max(runs[2]["ranks"], key=lambda r: r["list_pairs"] + r["ghost_pairs"])
    t1 = step_cost(N, pairs1, N, pairs1, T_PS_DENSE)
    t2 = step_cost(r2["local"], r2["list_pairs"] + r2["ghost_pairs"], N, pairs1, T_PS_DENSE)
    print(f"\n1 -> 2 ranks, compute only: predicted speed-up {t1/t2:.2f} (measured {SPEEDUP_DENSE_2}, "
          "docs/parallel-scaling.md)\n")

    # ---- extrapolation: DEM bed ------------------------------------------------------------
    lam = pairs1 / N  # pairs per sphere in the bulk, as the 1-rank list holds them

    def dem_step(n, p, rho=RHO_DENSE, t_ps=T_PS_DENSE):
        g = 0 if p == 1 else ghosts_cube(n, rho, w)
        pairs = lam * n + lam_g * g
        tc = step_cost(n, pairs, 1, lam, t_ps)
        tm = comm_time(p, g, bpg, 6, 2)
        return tc, tm, g

    print("## Strong scaling, dense DEM bed (per step; cluster network of the page)\n")
    print("| spheres | ranks | spheres / rank | ghosts / owned | compute [ms] | communication [ms] | efficiency | limited by |")
    print("|---:|---:|---:|---:|---:|---:|---:|---|")
    for N_ in (10**6, 10**7, 10**8):
        t_1 = step_cost(N_, lam * N_, 1, lam, T_PS_DENSE)
        for p in (1, 2, 64, 256, 1024, 4096):
            n = N_ / p
            tc, tm, g = dem_step(n, p)
            eff = t_1 / (p * (tc + tm))
            lim = "-" if p == 1 else ("ghosts (pairs evaluated twice)" if (tc - t_1 / p) > tm else
                                      "communication (latency, reductions)")
            print(f"| {N_:.0e} | {p} | {n:,.0f} | {g/n:.2f} | {tc*1e3:.3f} | {tm*1e3:.4f} | {eff:.2f} | {lim} |")
    print()
    for N_ in (10**6, 10**7, 10**8):
        t_1 = step_cost(N_, lam * N_, 1, lam, T_PS_DENSE)
        p = 2
        while p < 2 ** 20:
            tc, tm, g = dem_step(N_ / p, p)
            if t_1 / (p * (tc + tm)) < 0.5:
                break
            p *= 2
        print(f"{N_:.0e} spheres: efficiency falls below 50 % at {p} ranks ({N_/p:,.0f} spheres per rank)")
    print("\n## Weak scaling, dense DEM bed, spheres per rank fixed\n")
    print("| spheres / rank | ranks | step [ms] | efficiency |")
    print("|---:|---:|---:|---:|")
    for n in (30000, 3000):
        base = step_cost(n, lam * n, 1, lam, T_PS_DENSE)
        for p in (1, 64, 256, 1024):
            tc, tm, g = dem_step(n, p)
            print(f"| {n} | {p} | {(tc+tm)*1e3:.3f} | {base/(tc+tm):.2f} |")

    # ---- coupled bed -------------------------------------------------------------------------
    t_cell = FB["fluid"] / FB["dem"] * FB["substeps"] * FB["beads"] * T_PS_BED / FB["cells"]
    print(f"\nfluid cost per cell and fluid step (fluidisedBed split against the DEM's rate): {t_cell*1e6:.2f} us")
    check_coupled(runs, t_cell, os.path.dirname(path))
    rho_bed = 0.6 / (4 / 3 * math.pi * R ** 3)
    for Np, C in ((100000, 40000), (10**6, 400000)):
        print(f"\n## Strong scaling, coupled bed ({Np:,} spheres, {C:,} cells, 20 DEM steps per fluid step)\n")
        print("| ranks | spheres / rank | cells / rank | DEM [ms] | fluid + coupling compute [ms] | fluid reductions + halo [ms] | efficiency | limited by |")
        print("|---:|---:|---:|---:|---:|---:|---:|---|")
        t_one = None
        for p in (1, 2, 16, 64, 256, 1024):
            n, c = Np / p, C / p
            tc, tm, g = dem_step(n, p, rho_bed, T_PS_BED)
            t_dem = FB["substeps"] * (tc + tm)
            t_fc = t_cell * c * (1 + FB["coupling"] / FB["fluid"])
            nb = 0 if p == 1 else min(p - 1, 6)  # neighbours of a rank's part of the mesh
            off = 0.0 if p <= NET["ranks_per_node"] else 0.25
            lat = (1 - off) * NET["alpha_node"] + off * NET["alpha"]
            t_fr = 0 if p == 1 else FLUID_REDUCTIONS * allreduce_time(p) + FLUID_HALO * nb * lat
            total = t_dem + t_fc + t_fr
            t_one = t_one or total
            eff = t_one / (p * total)
            lim = max((t_dem, "DEM"), (t_fc, "fluid compute"), (t_fr, "fluid reductions + halo"))[1]
            print(f"| {p} | {n:,.0f} | {c:,.0f} | {t_dem*1e3:.3f} | {t_fc*1e3:.3f} | {t_fr*1e3:.3f} | {eff:.2f} | {lim} |")
        p = 2
        while True:
            n, c = Np / p, C / p
            tc, tm, g = dem_step(n, p, rho_bed, T_PS_BED)
            t_dem = FB["substeps"] * (tc + tm)
            t_fc = t_cell * c * (1 + FB["coupling"] / FB["fluid"])
            off = 0.0 if p <= NET["ranks_per_node"] else 0.25
            lat = (1 - off) * NET["alpha_node"] + off * NET["alpha"]
            t_fr = FLUID_REDUCTIONS * allreduce_time(p) + FLUID_HALO * min(p - 1, 6) * lat
            if t_one / (p * (t_dem + t_fc + t_fr)) < 0.5:
                break
            p *= 2
        print(f"\nefficiency below 50 % at {p} ranks ({Np / p:,.0f} spheres, {C / p:,.0f} cells per rank)")
    # The fluid alone: the cells per rank at which its synchronisations cost as much as its
    # compute (fluid + coupling), on 64 and 1024 ranks.
    for p in (64, 1024):
        off = 0.0 if p <= NET["ranks_per_node"] else 0.25
        lat = (1 - off) * NET["alpha_node"] + off * NET["alpha"]
        t_fr = FLUID_REDUCTIONS * allreduce_time(p) + FLUID_HALO * 6 * lat
        print(f"fluid on {p} ranks: synchronisations {t_fr*1e3:.2f} ms per fluid step = the compute of "
              f"{t_fr / (t_cell * (1 + FB['coupling'] / FB['fluid'])):,.0f} cells per rank")


def check_coupled(runs, t_cell, out_dir):
    """Checks of the coupled bed against this machine: the 4-rank counts predicted from the
    2-rank ones (model.py --fluid --np 2 and --np 4), and the 1 -> 2 rank speed-up of
    fluidisedBed --short."""
    counts = {}
    for np_ in (2, 4):
        f = os.path.join(out_dir, f"fluid_np{np_}.json")
        if os.path.exists(f):
            counts[np_] = {tuple(k.split(" ", 2)): v for k, v in json.load(open(f)).items()
                           if k != "gamg_cycles"}
            counts[np_]["cycles"] = json.load(open(f)).get("gamg_cycles", 0)
    if len(counts) == 2:
        print("\n## fluidisedBed --short on 4 ranks (oversubscribed): calls per fluid step, predicted "
              "from 2 ranks / measured\n")
        print("A rank's allreduces do not depend on its neighbours. Its messages: grain's exchanges "
              "(the DEM's, and the coupling's ghost exchanges) call once per direction whatever the "
              "neighbours; OpenFOAM's processor patches send those of a rank of 2 (one neighbour) "
              "times its neighbours (slabs along x: 1 at the ends, 2 inside).\n")
        print("| rank | neighbours | kind | " + " | ".join(PARTS) + " | total |")
        print("|---:|---:|---|" + "---:|" * (len(PARTS) + 1))
        for r in range(4):
            nb = 1 if r in (0, 3) else 2
            for kind in ("allreduce", "p2p"):
                cells, tp, tm = [], 0.0, 0.0
                for w in PARTS:
                    two = counts[2].get(("0", kind, w), 0.0)
                    # grain's exchanges call once per direction whatever the neighbours;
                    # OpenFOAM's processor patches send a message per neighbour.
                    fixed = two if w == "DEM" else counts[2].get(("0", kind, "coupling: grain exchanges"), 0.0) \
                        if w == "coupling" else 0.0
                    pred = two if kind == "allreduce" else fixed + (two - fixed) * nb
                    meas = counts[4].get((str(r), kind, w), 0.0)
                    tp, tm = tp + pred, tm + meas
                    cells.append(f"{pred:.1f} / {meas:.1f}")
                print(f"| {r} | {nb} | {kind} | " + " | ".join(cells) + f" | {tp:.1f} / {tm:.1f} |")
        c2, c4 = counts[2]["cycles"], counts[4]["cycles"]
        if c2 and c4:
            g = [(counts[n].get(("0", k, PARTS[2]), 0) / counts[n]["cycles"]) for n in (2, 4)
                 for k in ("allreduce", "p2p")]
            print(f"\nGAMG cycles for p per fluid step: {c2:.2f} on 2 ranks, {c4:.2f} on 4; per cycle "
                  f"(rank 0) {g[0]:.1f} / {g[2]:.1f} allreduces and {g[1]:.1f} / {g[3]:.1f} messages per neighbour")
    # 1 -> 2 ranks, fluidisedBed --short (2000 beads, 4 800 cells, 2000 fluid steps), measured:
    # 1 rank 37 s, split DEM 38 / coupling 9 / fluid 53 % (tutorials/cfd-dem/fluidisedBed/
    # README.md); 2 ranks, quiet, 38.6 s (DEM 12.65 s, coupling 2.46 s, fluid 23.5 s;
    # docs/performance.md). Predicted: each part's compute halves (the DEM's a little less: the
    # ghosts' pairs), plus each fluid step's synchronisations at the model's in-node costs.
    if 2 in counts:
        steps, t1 = 2000, 37.0
        d1, c1, f1 = 0.38 * t1, 0.09 * t1, 0.53 * t1
        rows = [(key, v) for key, v in counts[2].items()
                if len(key) == 3 and key[0] == "0" and key[2] in PARTS]
        ar = sum(v for (r, k, w), v in rows if k == "allreduce")
        msg = sum(v for (r, k, w), v in rows if k == "p2p")
        sync = steps * (ar * allreduce_time(2) + msg * NET["alpha_node"])
        t2 = d1 / 2 + c1 / 2 + f1 / 2 + sync
        t2_meas = 12.65 + 2.46 + 23.5
        print(f"\nfluidisedBed --short, 1 -> 2 ranks: predicted {t1:.1f} s -> {t2:.1f} s "
              f"(synchronisations {sync:.1f} s: {ar:.0f} allreduces and {msg:.0f} messages per fluid "
              f"step), speed-up {t1 / t2:.2f}; measured {t1:.1f} s -> {t2_meas:.1f} s, speed-up "
              f"{t1 / t2_meas:.2f}. The difference, {t2_meas - t2 + sync:.1f} s over the compute, is "
              f"{(t2_meas - (t2 - sync)) / steps / (ar + msg) * 1e6:.1f} us per synchronisation on this machine.")


# Per fluid step of fluidisedBed --short on 2 ranks (model.py --fluid, fluid steps 30-80):
# 905 allreduces, of which the 20 DEM steps make 40, the coupling none, the PIMPLE loop 865
# (838 in GAMG's 16.1 cycles for p); 839 point-to-point calls to the one neighbour, of which the
# DEM makes 45, the coupling 9 and the PIMPLE loop 785 (725 in GAMG).
FLUID_REDUCTIONS = 865  # allreduces per fluid step besides the DEM's
FLUID_HALO = 794        # halo exchanges per fluid step besides the DEM's (a message per neighbour)

if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--measure", action="store_true")
    ap.add_argument("--fluid", action="store_true")
    ap.add_argument("--np", type=int, default=2, help="ranks of --fluid (4: oversubscribed)")
    ap.add_argument("--ends", default="0.009,0.024",
                    help="end times of --fluid's two runs; their difference gives the counts per step")
    ap.add_argument("--build", default=os.environ.get("GRAINFLOW_BUILD_DIR", os.path.join(ROOT, "build")))
    ap.add_argument("--particles", type=int, default=100000)
    ap.add_argument("--steps", type=int, default=50)
    a = ap.parse_args()
    a.build = os.path.abspath(a.build)
    if a.fluid:
        measure_fluid(a.build, a.np, tuple(a.ends.split(",")))
        sys.exit(0)
    path = os.path.join(a.build, "scaling_model", "measured.json")
    if a.measure or not os.path.exists(path):
        path = measure(a.build, a.particles, a.steps)
    report(path)
