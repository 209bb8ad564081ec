#!/usr/bin/env python3
"""Where grain's instructions go: a callgrind profile split by DEM phase.

    valgrind --tool=callgrind --callgrind-out-file=cg.out grain run SCENE --no-progress
    callgrind_breakdown.py cg.out [more.out ...]

Prints, per profile, the instructions of the time loop (run_scene minus set-up) split into
pair forces, walls, integration, neighbour lists, communication and the per-step checks,
as inclusive counts of the functions that make each phase (callgrind_annotate --tree=calling).
Instruction counts do not depend on the machine's load, unlike timings; time spent waiting
in MPI is not an instruction count and shows up only in the timings. Valgrind (3.19) does not
decode AVX-512: profile a build configured with `-DGRAINFLOW_AVX=ON` (the AVX sweep, the same
results); a build whose sweep is compiled for AVX-512 stops under valgrind before the first
step with a message that names that option.
"""
import re
import subprocess
import sys

# phase -> [(caller, callee pattern, sign)]: inclusive cost of callee as called from caller
# ("@self": the caller's own instructions, outside its callees). The phases include the one
# force evaluation of the start-up (initialise), a fraction 1/steps of the pair and wall rows.
PHASES = [
    ("pair forces (particle-particle sweep)", [("::sweep<", "local_pair_sweep<", 1),
                                               ("::sweep<", "ghost_pair_sweep<", 1)]),
    ("walls (particle-wall sweep)", [("::sweep<", "wall_sweep<", 1)]),
    ("integration (two half kicks, drift, gravity)", [("Simulation::step()", "half_kick", 1),
                                                      ("Simulation::step()", "drift()", 1),
                                                      ("Simulation::step()", "@self", 1),
                                                      ("Simulation::compute_forces()", "@self", 1)]),
    ("neighbour lists (rebuilds without their exchanges, skin check)",
     [("Simulation::step()", "Simulation::rebuild(", 1), ("Simulation::rebuild(", "Exchange::migrate(", -1),
      ("Simulation::rebuild(", "Exchange::borders(", -1), ("Simulation::step()", "needs_rebuild()", 1)]),
    ("particles leaving the domain (mark_leaving)", [("Simulation::step()", "mark_leaving()", 1)]),
    ("communication (ghost update; migration and ghost lists at rebuilds; contact guards' check)",
     [("Simulation::step()", "Exchange::forward(", 1), ("Simulation::rebuild(", "Exchange::migrate(", 1),
      ("Simulation::rebuild(", "Exchange::borders(", 1), ("Simulation::compute_forces()", "check_contacts(", 1), ("Simulation::step()", "check_contacts(", 1)]),
    ("steps-per-contact guard (its gate every step; its pass when the gate opens)",
     [("Simulation::compute_forces()", "contact_may_be_unresolved(", 1),
      ("Simulation::compute_forces()", "steps_per_contact_sweep(", 1)]),
    ("non-finite guard (run loop, every step)", [("run_scene(", "guard_finite(", 1)]),
    ("output (log rows, snapshots)", [("run_scene(", "global_state()", 1), ("run_scene(", "SnapshotWriter::write", 1),
                                      ("run_scene(", "LogTable::write", 1)]),
]


def blocks(tree):
    """{caller name: (inclusive, self, {callee name: inclusive})} from --tree=calling output."""
    out, cur = {}, None
    for line in tree.splitlines():
        m = re.match(r"^\s*([0-9,]+) \([ 0-9.%]+\)\s+([*>])\s+(.*)$", line)
        if not m:
            continue
        cost = int(m.group(1).replace(",", ""))
        name = m.group(3)
        if m.group(2) == "*":
            cur = name
            out[cur] = [cost, {}]
        elif cur is not None:
            out[cur][1][name] = out[cur][1].get(name, 0) + cost
    return out


def find(b, pattern):
    keys = [k for k in b if pattern in k]
    return keys


def breakdown(path):
    tree = subprocess.run(["callgrind_annotate", "--show=Ir", "--inclusive=yes", "--tree=calling", path],
                          capture_output=True, text=True, check=True).stdout
    b = blocks(tree)
    loop = 0
    run = find(b, "grainflow::run_scene(")[0]
    for callee, cost in b[run][1].items():
        if "Simulation::step()" in callee or "guard_finite(" in callee or "global_state()" in callee \
                or "SnapshotWriter::write" in callee or "LogTable::write" in callee:
            loop += cost
    rows = []
    for phase, parts in PHASES:
        total = 0
        for caller_pat, callee_pat, sign in parts:
            for caller in find(b, caller_pat):
                inclusive, callees = b[caller]
                if callee_pat == "@self":
                    total += sign * (inclusive - sum(callees.values()))
                else:
                    total += sign * sum(c for n, c in callees.items() if callee_pat in n)
        rows.append((phase, total))
    return loop, rows


def main():
    results = [(p, *breakdown(p)) for p in sys.argv[1:]]
    print("| phase | " + " | ".join(p for p, _, _ in results) + " |")
    print("|---|" + "---:|" * len(results))
    for k, (phase, _) in enumerate(results[0][2]):
        cells = [f"{rows[k][1] / 1e9:.2f} G ({rows[k][1] / loop:.1%})" for _, loop, rows in results]
        print(f"| {phase} | " + " | ".join(cells) + " |")
    print("| **time loop, total** | " + " | ".join(f"**{loop / 1e9:.2f} G**" for _, loop, _ in results) + " |")


if __name__ == "__main__":
    main()
