#!/usr/bin/env python3
"""The cost of a change: two grain builds side by side on the settled bed of settling_bed.yaml.

    scripts/python.sh benchmarks/peers/build_cost.py --base A/bin/grain --new B/bin/grain \
        [--quick] [--rounds 5] [--ranks 1] [--new-contact "dashpot_velocity: predicted"]

The bed of compare_liggghts.py (settled once with --base, cached in --work) runs its timed
steps with each build in turn within a round (base, new, base, new, ...), so that both see the
same load on a shared machine. Prints each run's particle-steps/s (grain's own loop timer) and,
per rank count, the median over the rounds of the ratio new/base within a round, of the loop's
wall time and of the process's CPU time, with the machine's load average before and after.
--new-contact adds entries to the `contact` block of the new build's scene only (a setting the
base build does not know).
"""
import argparse
import os
import pathlib
import statistics

import yaml

import compare_liggghts as peers


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", required=True, help="the reference grain executable")
    ap.add_argument("--new", required=True, help="the grain executable to measure")
    ap.add_argument("--description", default=str(peers.HERE / "settling_bed.yaml"))
    ap.add_argument("--quick", action="store_true", help="the small bed (quick_lattice, quick_steps)")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--ranks", type=int, nargs="+", default=[1])
    ap.add_argument("--work", default=str(peers.HERE / "output"), help="folder for inputs and runs")
    ap.add_argument("--new-contact", default="", help="entries added to the new build's contact block")
    args = ap.parse_args()
    os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")

    bed = peers.Bed(yaml.safe_load(open(args.description)), args.quick)
    grains = {"base": pathlib.Path(args.base).resolve(), "new": pathlib.Path(args.new).resolve()}
    gcase, _ = peers.prepare(bed, grains["base"], pathlib.Path(args.work).resolve())
    cases = {}
    for label in grains:
        case = gcase.parent / f"build_{label}"
        case.mkdir(exist_ok=True)
        (case / "settled.h5").write_bytes((gcase / "settled.h5").read_bytes())
        for n in args.ranks:
            text = (gcase / f"scene_np{n}.yaml").read_text()
            if label == "new" and args.new_contact:
                old = "contact: {normal: hertz, tangential: history}"
                if old not in text:
                    raise SystemExit(f"build_cost.py: no `{old}` in the scene to extend")
                text = text.replace(old, old[:-1] + ", " + args.new_contact + "}")
            (case / f"scene_np{n}.yaml").write_text(text)
        cases[label] = case
    if args.rounds < 1:
        return
    load_before = os.getloadavg()
    print(f"bed: {bed.count} spheres, {bed.steps} timed steps; {args.rounds} interleaved rounds; "
          f"load average {load_before[0]:.2f}", flush=True)
    results = {}
    for k in range(args.rounds):
        for n in args.ranks:
            for label in (("base", "new") if k % 2 == 0 else ("new", "base")):
                r = peers.run_grain(grains[label], cases[label], n)
                results.setdefault((label, n), []).append(r)
                print(f"round {k + 1}: {n} rank(s), {label:4s}: {r['rate']:.4g} particle-steps/s "
                      f"(loop {r['loop']:.2f} s, CPU {r['cpu']:.2f} s)", flush=True)
    load_after = os.getloadavg()
    print()
    for n in args.ranks:
        base, new = results[("base", n)], results[("new", n)]
        loop = [b["loop"] / a["loop"] for a, b in zip(base, new)]
        cpu = [b["cpu"] / a["cpu"] for a, b in zip(base, new)]
        print(f"{n} rank(s): loop time new/base per round " + ", ".join(f"{x:.3f}" for x in loop)
              + f"; median {statistics.median(loop):.3f}; CPU time of the process new/base per "
              "round " + ", ".join(f"{x:.3f}" for x in cpu) + f"; median {statistics.median(cpu):.3f}")
        print(f"  median rates: base {statistics.median(r['rate'] for r in base):.4g}, new "
              f"{statistics.median(r['rate'] for r in new):.4g} particle-steps/s; final beds: height "
              f"{base[0]['height']:.6e} vs {new[0]['height']:.6e} m, kinetic energy "
              f"{base[0]['kinetic']:.4e} vs {new[0]['kinetic']:.4e} J")
    print(f"load average (1 min) before {load_before[0]:.2f}, after {load_after[0]:.2f}")


if __name__ == "__main__":
    main()
