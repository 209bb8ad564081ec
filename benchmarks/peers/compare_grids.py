#!/usr/bin/env python3
"""The default processor grid against fixed grids, on the settled bed of settling_bed.yaml.

    compare_grids.py --grain BUILD/bin/grain [--quick] [--rounds 3] [--work DIR] [--ranks 2]

Runs grain alone (no LIGGGHTS) on the bed of compare_liggghts.py (settled once, cached in
--work), on `--ranks` ranks, with
  * `parallel: {grid: [N, 1, 1]}` (the least-cut-area grid of this box alone, uniform planes),
  * no `parallel.grid` (the default: docs/parallel.md, "The default grid"),
and the same bed in a domain four times as tall (its least-cut-area grid by the box alone,
1 x 1 x N, cuts the bed across its height), with the three grids N x 1 x 1, default and
1 x 1 x N. Rounds are interleaved (every configuration once per round, every other round in
reverse order) so that the noise of a shared machine hits all alike; prints the load average
before each round, each run's rate and the median over rounds of the per-round ratio to
N x 1 x 1 in the same domain.
"""
import argparse
import os
import pathlib
import re
import statistics

import yaml

from compare_liggghts import HERE, Bed, mpirun, prepare


def variant(text, grid, tall):
    lines = []
    for line in text.splitlines():
        if line.startswith("parallel:"):
            if grid is not None:
                lines.append(f"parallel: {{grid: {grid}}}")
            continue
        if tall and line.startswith("domain:"):
            top = float(re.search(r"max: \[[^,]+, [^,]+, ([^\]]+)\]", line).group(1))
            line = line.replace(f", {top!r}]}}", f", {4 * top!r}]}}")
            assert repr(4 * top) in line, line
        lines.append(line)
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grain", required=True)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--ranks", type=int, default=2)
    ap.add_argument("--work", default=str(HERE / "output"))
    ap.add_argument("--box-only", action="store_true", help="leave out the tall domain")
    args = ap.parse_args()
    os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    bed = Bed(yaml.safe_load(open(HERE / "settling_bed.yaml")), args.quick)
    gcase, _ = prepare(bed, pathlib.Path(args.grain).resolve(), pathlib.Path(args.work).resolve())
    n = args.ranks
    base = (gcase / f"scene_np2.yaml").read_text()
    configs = {
        ("box", f"{n} x 1 x 1"): variant(base, [n, 1, 1], False),
        ("box", "default"): variant(base, None, False),
        ("tall box", f"{n} x 1 x 1"): variant(base, [n, 1, 1], True),
        ("tall box", "default"): variant(base, None, True),
        ("tall box", f"1 x 1 x {n}"): variant(base, [1, 1, n], True),
    }
    if args.box_only:
        configs = {k: v for k, v in configs.items() if k[0] == "box"}
    names = {}
    for k, (key, text) in enumerate(configs.items()):
        names[key] = f"grids_{k}.yaml"
        (gcase / names[key]).write_text(text)
    print(f"bed: {bed.count} spheres, {bed.steps} steps, {n} ranks; inputs in {gcase}", flush=True)
    rates = {key: [] for key in configs}
    grids = {}
    for r in range(args.rounds):
        # The machine's load (a shared machine's noise hits every configuration of a round).
        print(f"round {r + 1}: load average {os.getloadavg()[0]:.2f}", flush=True)
        # Odd rounds in reverse order: a load that drifts during a round favours neither side.
        for key in (list(configs) if r % 2 == 0 else list(configs)[::-1]):
            out, seconds, _, _ = mpirun(n, [args.grain, "run", names[key], "--no-progress"], gcase, gcase)
            m = re.search(r"done: .*? ([0-9.e+]+) particle-steps/s", out)
            g = re.search(r"MPI ranks: .*", out)
            grids[key] = g.group(0) if g else ""
            rates[key].append(float(m.group(1)))
            print(f"round {r + 1}: {key[0]:8s} {key[1]:10s} {rates[key][-1]:.4g} particle-steps/s "
                  f"({seconds:.1f} s)", flush=True)
    print("\n| domain | grid | chosen | particle-steps/s (median) | rounds | ratio to N x 1 x 1 (median of rounds) |")
    print("|---|---|---|---:|---|---:|")
    for key in configs:
        ref = rates[(key[0], f"{n} x 1 x 1")]
        ratio = statistics.median(a / b for a, b in zip(rates[key], ref))
        print(f"| {key[0]} | {key[1]} | {grids[key]} | {statistics.median(rates[key]):.4g} | "
              f"{', '.join(f'{x:.4g}' for x in rates[key])} | {ratio:.3f} |")


if __name__ == "__main__":
    main()
