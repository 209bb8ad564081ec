#!/usr/bin/env python3
"""ParaView's own XDMF reader opens what `grain run` writes (docs/scene-reference.md).

    paraview_reads_snapshots.py GRAIN SCENE WORKDIR PVBATCH_SH

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


def main():
    grain, scene, work, pvbatch = sys.argv[1:5]
    subprocess.run(["rm", "-rf", work], check=True)
    os.makedirs(work)
    os.chdir(work)
    run = subprocess.run([grain, "run", scene, "--output", "out", "--no-progress"],
                         capture_output=True, text=True)
    if run.returncode != 0:
        fail(f"grain run exited {run.returncode}:\n{run.stdout}{run.stderr}")
    dump = os.path.join(os.path.dirname(os.path.abspath(__file__)), "paraview_dump.py")
    pv = subprocess.run(["bash", pvbatch, dump, "out/particles.xdmf", "out/particles.png",
                         "paraview.json"], capture_output=True, text=True)
    if pv.returncode != 0 or not os.path.exists("paraview.json"):
        fail(f"pvbatch exited {pv.returncode}:\n{pv.stdout}{pv.stderr}")
    seen = json.load(open("paraview.json"))

    files = sorted(n for n in os.listdir("out") if n.startswith("particles_") and n.endswith(".h5"))
    steps = seen["steps"]
    if len(steps) != len(files) or len(files) != 5:
        fail(f"ParaView sees {len(steps)} time steps, the run wrote {len(files)} (expected 5)")
    for name, step in zip(files, steps):
        with h5py.File(os.path.join("out", name), "r") as f:
            t, n = float(f.attrs["time"]), int(f.attrs["count"])
            if step["time"] != t:
                fail(f"{name}: ParaView's time {step['time']!r}, the file's {t!r}")
            if step["points"] != n or step["cells"] != n:
                fail(f"{name}: ParaView has {step['points']} points and {step['cells']} cells, "
                     f"the file {n} particles")
            if not np.array_equal(np.array(step["positions"]), f["position"][()]):
                fail(f"{name}: ParaView's points are not /position")
            held = sorted(k for k in f.keys() if k != "position")
            if sorted(step["arrays"]) != held or sorted(held) != sorted(FIELDS + ["id"]):
                fail(f"{name}: ParaView's arrays {sorted(step['arrays'])}, the file's {held}")
            for key in held:
                data = f[key][()]
                array = step["arrays"][key]
                components = 1 if data.ndim == 1 else data.shape[1]
                values = np.array(array["values"]).reshape(data.shape)
                if array["components"] != components or not np.array_equal(values, data):
                    fail(f"{name}:{key}: ParaView's {array['components']} component(s) / values "
                         f"differ from the file's {components}")
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
    print("PASS")


if __name__ == "__main__":
    main()
