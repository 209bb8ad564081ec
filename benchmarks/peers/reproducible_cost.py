#!/usr/bin/env python3
"""The cost of `parallel: {reproducible: true}` on the settled bed of settling_bed.yaml.

    scripts/python.sh benchmarks/peers/reproducible_cost.py --grain build/bin/grain [--rounds 3] [--ranks 1 2]

grain alone (no peer): the bed of compare_liggghts.py (30 720 spheres, settled once and cached
in --work) runs its timed steps with the mode off and on, side by side in each round (off, on,
off, on, ...). Prints each run's particle-steps/s (grain's own loop timer) and, per rank count,
the median over the rounds of the ratio on/off within a round (of the loop's wall time, and of
the process's CPU time, less sensitive to other jobs on the machine), and the two modes' final
beds (they differ only in summation order: round-off).
"""
import argparse
import os
import pathlib
import statistics

import yaml

import compare_liggghts as peers


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grain", required=True, help="the grain executable")
    ap.add_argument("--description", default=str(peers.HERE / "settling_bed.yaml"))
    ap.add_argument("--quick", action="store_true", help="the small bed (quick_lattice, quick_steps)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--work", default=str(peers.HERE / "output"), help="folder for inputs and runs")
    args = ap.parse_args()
    os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")

    bed = peers.Bed(yaml.safe_load(open(args.description)), args.quick)
    grain = pathlib.Path(args.grain).resolve()
    gcase, _ = peers.prepare(bed, grain, pathlib.Path(args.work).resolve())
    cases = {}
    for mode in ("off", "on"):
        case = gcase.parent / f"reproducible_{mode}"
        case.mkdir(exist_ok=True)
        (case / "settled.h5").write_bytes((gcase / "settled.h5").read_bytes())
        for n in args.ranks:
            text = (gcase / f"scene_np{n}.yaml").read_text()
            if mode == "on":
                text = text.replace("parallel: {grid:", "parallel: {reproducible: true, grid:")
            (case / f"scene_np{n}.yaml").write_text(text)
        cases[mode] = case
    print(f"bed: {bed.count} spheres, {bed.steps} timed steps; {args.rounds} interleaved rounds",
          flush=True)
    results = {}
    for k in range(args.rounds):
        for n in args.ranks:
            for mode in ("off", "on"):
                r = peers.run_grain(grain, cases[mode], n)
                results.setdefault((mode, n), []).append(r)
                print(f"round {k + 1}: {n} rank(s), reproducible {mode:3s}: {r['rate']:.4g} "
                      f"particle-steps/s (loop {r['loop']:.2f} s, CPU {r['cpu']:.2f} s, "
                      f"{r['rss_kb'] / 1024:.0f} MiB)", flush=True)
    print()
    for n in args.ranks:
        off, on = results[("off", n)], results[("on", n)]
        ratios = [b["loop"] / a["loop"] for a, b in zip(off, on)]
        cpu = [b["cpu"] / a["cpu"] for a, b in zip(off, on)]
        print(f"{n} rank(s): loop time on/off per round " + ", ".join(f"{x:.3f}" for x in ratios)
              + f"; median {statistics.median(ratios):.3f} (+{100 * (statistics.median(ratios) - 1):.1f} %); "
              f"CPU time of the process (start-up included) on/off: median {statistics.median(cpu):.3f}; "
              f"peak RSS on/off {statistics.median(b['rss_kb'] for b in on) / statistics.median(a['rss_kb'] for a in off):.3f}")
        dh = abs(on[0]["height"] / off[0]["height"] - 1)
        print(f"  same bed: height differs by {dh:.1e} (relative), kinetic energy "
              f"{on[0]['kinetic']:.4e} vs {off[0]['kinetic']:.4e} J")


if __name__ == "__main__":
    main()
