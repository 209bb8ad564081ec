#!/usr/bin/env python3
"""ParaView's own XDMF reader opens what `grain run` writes (docs/scene-reference.md).

    paraview_reads_snapshots.py GRAIN SCENE WORKDIR PVBATCH_SH EMPTY_TIMES_SCENE

Runs `grain run SCENE` (tests/data/scenes/paraview_snapshots.yaml: 300 beads falling onto a
floor, five snapshots with force, torque, coordination, fluid_force and overlap_max), then
runs paraview_dump.py under pvbatch (scripts/pvbatch.sh) on out/particles.xdmf and compares
what ParaView read with the HDF5 files read by h5py:
  - the time steps are the files' `time` attributes, exactly;
  - each step has `count` points and as many (vertex) cells;
  - the point coordinates are /position and each point array is the dataset of its name with
    its components (1 or 3), bit for bit; the array set is the file's datasets less
    position;
  - at least one bead touches the floor in the last step (coordination > 0, force not just
    gravity), so the compared values are not all trivial;
  - the picture (800 x 600 PNG) has beads drawn on at least 2 % of its pixels.
Then runs EMPTY_TIMES_SCENE (tests/data/scenes/paraview_empty_times.yaml: a stream falling
through an open floor, so the first and the last snapshots hold no particle) and asks the
same of every time, the empty ones read as 0 points, with no error from the reader.
"""
import json
import os
import subprocess
import sys

import h5py
import numpy as np

FIELDS = ["velocity", "radius", "material", "force", "torque", "coordination", "fluid_force",
          "overlap_max"]


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def run_grain(grain, scene, out):
    run = subprocess.run([grain, "run", scene, "--output", out, "--no-progress"],
                         capture_output=True, text=True)
    if run.returncode != 0:
        fail(f"grain run {scene} exited {run.returncode}:\n{run.stdout}{run.stderr}")


def read_all(pvbatch, runs):
    """What ParaView reads of each (output folder, picture or "-"), in one pvbatch (one X
    connection); returns the dumps and pvbatch's output."""
    dump = os.path.join(os.path.dirname(os.path.abspath(__file__)), "paraview_dump.py")
    args = []
    for out, picture in runs:
        args += [f"{out}/particles.xdmf", picture, out + ".json"]
    pv = subprocess.run(["bash", pvbatch, dump] + args, capture_output=True, text=True)
    if pv.returncode != 0 or not all(os.path.exists(out + ".json") for out, _ in runs):
        fail(f"pvbatch exited {pv.returncode}:\n{pv.stdout}{pv.stderr}")
    return [json.load(open(out + ".json")) for out, _ in runs], pv.stdout + pv.stderr


def compare(out, steps, fields):
    """Every time step ParaView read against the HDF5 file of its snapshot; returns the files
    and the datasets compared."""
    files = sorted(n for n in os.listdir(out) if n.startswith("particles_") and n.endswith(".h5"))
    if len(steps) != len(files):
        fail(f"{out}: ParaView sees {len(steps)} time steps, the run wrote {len(files)}")
    held = []
    for name, step in zip(files, steps):
        with h5py.File(os.path.join(out, name), "r") as f:
            t, n = float(f.attrs["time"]), int(f.attrs["count"])
            if step["time"] != t:
                fail(f"{name}: ParaView's time {step['time']!r}, the file's {t!r}")
            if step["points"] != n or step["cells"] != n:
                fail(f"{name}: ParaView has {step['points']} points and {step['cells']} cells, "
                     f"the file {n} particles")
            if n == 0:
                continue
            if not np.array_equal(np.array(step["positions"]), f["position"][()]):
                fail(f"{name}: ParaView's points are not /position")
            held = sorted(k for k in f.keys() if k != "position")
            if sorted(step["arrays"]) != held or sorted(held) != sorted(fields + ["id"]):
                fail(f"{name}: ParaView's arrays {sorted(step['arrays'])}, the file's {held}")
            for key in held:
                data = f[key][()]
                array = step["arrays"][key]
                components = 1 if data.ndim == 1 else data.shape[1]
                values = np.array(array["values"]).reshape(data.shape)
                if array["components"] != components or not np.array_equal(values, data):
                    fail(f"{name}:{key}: ParaView's {array['components']} component(s) / values "
                         f"differ from the file's {components}")
    return files, held


def main():
    grain, scene, work, pvbatch, empty_scene = sys.argv[1:6]
    subprocess.run(["rm", "-rf", work], check=True)
    os.makedirs(work)
    os.chdir(work)
    run_grain(grain, scene, "out")
    run_grain(grain, empty_scene, "empty_times")
    (seen, seen_empty), said = read_all(pvbatch, [("out", "out/particles.png"),
                                                  ("empty_times", "-")])
    steps = seen["steps"]
    if len(steps) != 5:
        fail(f"ParaView sees {len(steps)} time steps (expected 5)")
    files, held = compare("out", steps, FIELDS)
    with h5py.File(os.path.join("out", files[-1]), "r") as f:
        touching = int((f["coordination"][()] > 0).sum())
        if touching == 0 or float(f["overlap_max"][()].max()) <= 0:
            fail(f"{files[-1]}: no bead touches anything; the compared values are trivial")
    image = seen["image"]
    if (image["width"], image["height"]) != (800, 600) or image["drawn"] < 0.02:
        fail(f"the picture is {image['width']} x {image['height']} with {image['drawn']:.1%} "
             f"of its pixels drawn")
    print(f"ParaView (XDMFReader) read {len(steps)} time steps of {steps[-1]['points']} points "
          f"with {len(held)} arrays equal to the HDF5 files; {touching} beads in contact at "
          f"the end; out/particles.png has beads on {image['drawn']:.1%} of its pixels")

    steps = seen_empty["steps"]
    compare("empty_times", steps, ["velocity", "radius"])
    counts = [s["points"] for s in steps]
    if counts[0] != 0 or counts[-1] != 0 or max(counts) == 0:
        fail(f"empty_times: the snapshots hold {counts} particles; the scene should give none "
             f"at the first and the last time and some between")
    # The XDMF reader's own complaints (an empty geometry gave "XDMF Error in ... Error in
    # Update() of Geometry" and "vtkXdmfReader ... Failed to read data"); pvbatch.sh's retries
    # of a lost X connection are not the reader's.
    errors = [line for line in said.splitlines()
              if "Xdmf" in line or "XDMF" in line or "Failed to read" in line]
    if errors:
        fail("ParaView's reader reported errors:\n" +
             "\n".join(errors[:10]))
    print(f"ParaView read the {len(steps)} times of a stream through an open floor, "
          f"{counts} points, the empty ones without an error")
    print("PASS")


if __name__ == "__main__":
    main()
