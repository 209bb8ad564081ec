"""What the grainFoam command-test drivers share (tests/coupling/grainfoam_cases.py and
tests/coupling_stress/stress_cases.py): a runner for OpenFOAM programs on fresh copies of a
case, the check collector, parsers of grainFoam's log lines, written fields and particle
snapshots, and the command line."""
import argparse
import os
import re
import shutil
import subprocess
import time

import h5py
import numpy as np

# Round-off of one fluid step: the printed sums add a few hundred to a few thousand cell
# and particle volumes (relative error ~1e-16 each); 1e-12 leaves room for that and for
# nothing physical (one 1 mm bead of 300 is 3e-3 of the total).
ROUND_OFF = 1e-12

FLOAT = r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[-+]?nan|[-+]?inf)"
VOID_LINE = re.compile(
    r"grainFoam void fraction: sum \(1-eps\) V = " + FLOAT + r" m\^3, clamped away " + FLOAT +
    r" m\^3, particles " + FLOAT + r" m\^3, relative difference " + FLOAT)
VEC = r"\(" + FLOAT + " " + FLOAT + " " + FLOAT + r"\)"
BALANCE_LINE = re.compile(r"grainFoam exchange balance: particles " + VEC + r" N, fluid " +
                          VEC + r" N, relative imbalance " + FLOAT)
PARTICLES_LINE = re.compile(r"grainFoam particles: (\d+) particles, .*?removed (\d+)"
                            r".*?void fraction clamped (\d+) cell-steps")
NAN_WORD = re.compile(r"\b(nan|inf)\b", re.IGNORECASE)


class Checks:
    """Collects failed checks so that one run reports all of them."""

    def __init__(self):
        self.failures = []

    def expect(self, ok, what):
        print(("  ok    " if ok else "  FAIL  ") + what)
        if not ok:
            self.failures.append(what)


class Runner:
    def __init__(self, args):
        self.foam_env = args.foam_env
        self.solver = args.solver
        self.mpiexec = args.mpiexec
        self.cases = args.cases
        self.work = args.work
        # superficialVelocityInlet (dense_bed): OpenFOAM's `libs` dlopen()s the bare name.
        self.env = dict(os.environ)
        if getattr(args, "lib_dir", ""):
            self.env["LD_LIBRARY_PATH"] = os.pathsep.join(
                p for p in (args.lib_dir, os.environ.get("LD_LIBRARY_PATH", "")) if p)

    def fresh_case(self, source, name, edits=()):
        """A fresh copy of cases/<source> as <work>/<name>, with text edits applied:
        each edit is (file, old, new) and `old` must occur in the file."""
        case = os.path.join(self.work, name)
        shutil.rmtree(case, ignore_errors=True)
        shutil.copytree(os.path.join(self.cases, source), case)
        for path, old, new in edits:
            full = os.path.join(case, path)
            with open(full) as f:
                text = f.read()
            if old not in text:
                raise RuntimeError(f"{full}: no '{old}' to replace")
            with open(full, "w") as f:
                f.write(text.replace(old, new, 1))
        return case

    def run(self, case, log, *command, ranks=1, expect_failure=False):
        """Runs an OpenFOAM program in `case`; returns its output (stdout + stderr)."""
        cmd = [self.foam_env]
        if ranks > 1:
            cmd += [self.mpiexec, "-np", str(ranks), "--oversubscribe"]
        cmd += list(command) + ["-case", case]
        if ranks > 1:
            cmd.append("-parallel")
        t0 = time.monotonic()
        r = subprocess.run(cmd, cwd=case, env=self.env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           text=True, timeout=300)
        with open(os.path.join(case, "log." + log), "w") as f:
            f.write(r.stdout)
        print(f"  ran   {log} ({time.monotonic() - t0:.1f} s, exit {r.returncode})")
        if expect_failure:
            if r.returncode == 0:
                raise RuntimeError(f"{log} should have failed but exited 0; see {case}/log.{log}")
        elif r.returncode != 0:
            raise RuntimeError(f"{log} failed (exit {r.returncode}); {case}/log.{log}:\n"
                               + r.stdout[-3000:])
        elif command[0] == self.solver and not re.search(r"^End\s*$", r.stdout, re.M):
            # A SIGTERM or SIGINT stops grainFoam with exit 0 after a checkpoint (a batch
            # system's time limit); its numbers are then not the full run's.
            raise RuntimeError(f"{log} exited 0 without OpenFOAM's closing 'End' (stopped by a "
                               f"signal before its end time); see {case}/log.{log}")
        return r.stdout

    def solve(self, case, ranks=1):
        """blockMesh, [decomposePar,] grainFoam, [reconstructPar]; returns grainFoam's log."""
        self.run(case, "blockMesh", "blockMesh")
        if ranks == 1:
            return self.run(case, "grainFoam", self.solver)
        self.run(case, "decomposePar", "decomposePar")
        out = self.run(case, "grainFoam", self.solver, ranks=ranks)
        self.run(case, "reconstructPar", "reconstructPar", "-fields", "(voidfraction)")
        return out


def void_lines(log):
    return [tuple(float(x) for x in m.groups()) for m in VOID_LINE.finditer(log)]


def balance_lines(log):
    out = []
    for m in BALANCE_LINE.finditer(log):
        v = [float(x) for x in m.groups()]
        out.append((np.array(v[0:3]), np.array(v[3:6]), v[6]))
    return out


def particle_lines(log):
    """(count, removed, clamped cell-steps) of every `grainFoam particles:` line."""
    return [tuple(int(x) for x in m.groups()) for m in PARTICLES_LINE.finditer(log)]


def read_scalar_field(path):
    """internalField of an ASCII volScalarField (uniform or nonuniform List<scalar>)."""
    with open(path) as f:
        text = f.read()
    m = re.search(r"internalField\s+uniform\s+" + FLOAT, text)
    if m:
        return np.array([float(m.group(1))])
    m = re.search(r"internalField\s+nonuniform\s+List<scalar>\s*(\d+)\s*\(([^)]*)\)", text)
    if not m:
        raise RuntimeError(f"{path}: no internalField")
    values = np.array(m.group(2).split(), dtype=float)
    if len(values) != int(m.group(1)):
        raise RuntimeError(f"{path}: {len(values)} values, header says {m.group(1)}")
    return values


def snapshots(case, folder="particles"):
    """Particle snapshots of a case (in <case>/<folder>), sorted by time:
    [(time, {dataset: array})], every dataset a file holds (the scene's output.fields), rows
    sorted by id."""
    folder = os.path.join(case, folder)
    out = []
    for name in sorted(os.listdir(folder)):
        if name.startswith("particles_") and name.endswith(".h5"):  # not the checkpoints
            with h5py.File(os.path.join(folder, name), "r") as f:
                order = np.argsort(f["id"][:])
                data = {k: f[k][:][order] for k in f.keys()}
                out.append((float(f.attrs["time"]), data))
    return sorted(out, key=lambda s: s[0])


def time_folders(case):
    """Written time folders of a (reconstructed) case, except 0, sorted by time."""
    out = []
    for name in os.listdir(case):
        try:
            t = float(name)
        except ValueError:
            continue
        if t > 0 and os.path.exists(os.path.join(case, name, "voidfraction")):
            out.append(name)
    return sorted(out, key=float)


def main(tests, prefix, doc):
    """Command line of a driver: runs tests[TEST] and prints `<prefix>.<TEST>: N failed checks`."""
    parser = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    parser.add_argument("test", choices=sorted(tests))
    parser.add_argument("--foam-env", required=True)
    parser.add_argument("--solver", required=True)
    parser.add_argument("--mpiexec", default="mpiexec")
    parser.add_argument("--lib-dir", default="", help="folder of libgrainflowFoamBCs.so")
    parser.add_argument("--cases", required=True)
    parser.add_argument("--work", required=True)
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    checks = Checks()
    t0 = time.monotonic()
    try:
        tests[args.test](Runner(args), checks)
    except (RuntimeError, subprocess.TimeoutExpired) as e:
        checks.expect(False, str(e))
    print(f"{prefix}.{args.test}: {len(checks.failures)} failed checks, "
          f"{time.monotonic() - t0:.1f} s")
    return 1 if checks.failures else 0
