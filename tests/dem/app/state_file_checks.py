#!/usr/bin/env python3
"""Hostile checkpoints and snapshots (docs/reliability.md, "What is checked on read").

    state_file_checks.py GRAIN SCENE WORKDIR setup
    state_file_checks.py GRAIN SCENE WORKDIR checkpoint|snapshot CASE

`setup` runs SCENE (periodic along x and y, bounded along z, one material) into
WORKDIR/base: its checkpoint and first snapshot are the real files every case copies.
A case copies one of them, changes one value with h5py (which writes the chunk anew with a
correct checksum, so only the rules can see the change) or flips one bit in the file's bytes
(which only the Fletcher32 checksum can see), and starts from it: `grain run SCENE --restart
COPY` for a checkpoint, a scene inserting `{type: snapshot, file: COPY}` for a snapshot.
Each case must exit with code 1 and a message naming the file, the dataset, the index and
the rule broken, and must leave every file of the output directory as it was.
"""
import glob
import hashlib
import os
import re
import shutil
import subprocess
import sys

import h5py
import numpy as np

grain, scene, work, kind = sys.argv[1:5]
case = sys.argv[5] if len(sys.argv) > 5 else ""
base = os.path.join(work, "base")


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


if kind == "setup":
    shutil.rmtree(base, ignore_errors=True)
    os.makedirs(base)
    r = subprocess.run([grain, "run", scene, "--output", "out", "--no-progress"], cwd=base,
                       capture_output=True, text=True)
    print(r.stdout + r.stderr)
    if r.returncode != 0 or not glob.glob(os.path.join(base, "out", "checkpoint_*.h5")):
        fail("the run that makes the real files failed")
    print("PASS")
    sys.exit(0)

source = sorted(glob.glob(os.path.join(base, "out", "checkpoint_*.h5")))[0] \
    if kind == "checkpoint" else os.path.join(base, "out", "particles_000000.h5")
here = os.path.join(work, kind + "_" + case)
shutil.rmtree(here, ignore_errors=True)
os.makedirs(os.path.join(here, "out"))
# The damaged file lies in the output directory beside an intact checkpoint of the same run,
# which the refused start must leave alone.
name = os.path.basename(source) if kind == "checkpoint" else "snapshot.h5"
target = os.path.join(here, "out", name)
shutil.copy(source, target)
shutil.copy(source, os.path.join(here, "out", "checkpoint_000000001.h5"))
g = "particles/" if kind == "checkpoint" else ""
relative = os.path.join("out", name)


def edit(change):
    with h5py.File(target, "r+") as f:
        return change(f)


def flip_low_bit(dataset, row, col):
    """Flips the lowest mantissa bit of dataset[row, col] in the file's bytes (little-endian
    doubles in one Fletcher32-checked chunk), as a damaged disk sector would."""
    with h5py.File(target, "r") as f:
        d = f[dataset]
        assert d.fletcher32, "the file was written without checksums"
        info = d.id.get_chunk_info(0)
        offset = info.byte_offset + (row * d.shape[1] + col) * 8
        assert d.chunks[0] > row
        before = d[row, col]
    with open(target, "r+b") as raw:
        raw.seek(offset)
        byte = raw.read(1)[0]
        raw.seek(offset)
        raw.write(bytes([byte ^ 1]))
    return before


def flip_bytes_bit(offset, bit):
    """Flips one bit of the file's raw bytes."""
    with open(target, "r+b") as raw:
        raw.seek(offset)
        byte = raw.read(1)[0]
        raw.seek(offset)
        raw.write(bytes([byte ^ (1 << bit)]))


def attribute_offset(name):
    """Where the root attribute's value lies in the file's bytes (its value must occur once)."""
    with h5py.File(target, "r") as f:
        value = np.asarray(f.attrs[name]).tobytes()
    data = open(target, "rb").read()
    assert data.count(value) == 1, f"attribute {name}'s bytes occur {data.count(value)} times"
    return data.index(value)


def chunk_key_offset(dataset):
    """Where the v1 B-tree key of the dataset's single chunk lies: chunk size (4 bytes), filter
    mask (4), the chunk's offset per dimension and one for the element (8 each), then the
    chunk's address (8): found by that pattern."""
    import struct
    with h5py.File(target, "r") as f:
        d = f[dataset]
        info = d.id.get_chunk_info(0)
        rank = len(d.shape)
    key = struct.pack("<II", info.size, info.filter_mask) + b"\0" * (8 * (rank + 1)) + \
        struct.pack("<Q", info.byte_offset)
    data = open(target, "rb").read()
    assert data.count(key) == 1, f"{dataset}: the chunk key occurs {data.count(key)} times"
    return data.index(key)


def set_spring(f, particle, partner):
    """Replaces the springs with one (particle, partner) spring, as grain writes them."""
    for k in ("particle", "partner", "tangential", "rolling"):
        del f["springs/" + k]
    f.create_dataset("springs/particle", data=np.array([particle], "<i8"), chunks=(1,),
                     fletcher32=True)
    f.create_dataset("springs/partner", data=np.array([partner], "<i8"), chunks=(1,),
                     fletcher32=True)
    for k in ("tangential", "rolling"):
        f.create_dataset("springs/" + k, data=np.zeros((1, 3)), chunks=(1, 3), fletcher32=True)


def setitem(path, index, value):
    def change(f):
        d = f[path]
        old = d[index]
        d[index] = value
        return old
    return change


ids = edit(lambda f: f[g + "id"][...])
# The regex the message must match: file, dataset, index, rule.
# A snapshot's path is as the scene resolves it (relative to the scene's folder).
f_ = re.escape(relative) if kind == "checkpoint" else r"\S*" + re.escape(relative)
particle = lambda i: r"index %d \(particle id %d\)" % (i, ids[i])
if case == "material_max":  # 2^31-1: a segmentation fault before these checks
    edit(setitem(g + "material", 0, 2**31 - 1))
    # A snapshot names its writer's materials (material_names), mapped by name to the scene's.
    expect = f_ + r": error: dataset '/%smaterial', %s: the material index 2147483647 is not " \
        r"one of the scene's 1 material\(s\) \(allowed: 0 to 0" % (g, particle(0)) \
        if kind == "checkpoint" else \
        f_ + r": error: dataset '/material', index 0 \(particle id \d+\): the material index " \
        r"2147483647 is not one of the 1 materials of the scene that wrote it"
elif case == "material_past":
    edit(setitem(g + "material", 3, 1))
    expect = f_ + r": error: dataset '/%smaterial', %s: the material index 1 is not one of" % (
        g, particle(3))
elif case == "position_bounded":  # z is bounded
    edit(setitem(g + "position", (5, 2), 1e300))
    expect = (f_ + r": error: dataset '/%sposition', %s: the position \(.*, 1e\+300\) is outside "
              r"the domain along z \(bounded" % (g, particle(5))) if kind == "checkpoint" else \
        (f_ + r": error: dataset '/position', %s: the particle lies outside the domain: its "
         r"centre z = 1e\+300 is outside the bounded range" % particle(5))
elif case == "position_periodic":  # x is periodic
    edit(setitem(g + "position", (5, 0), 1e300))
    expect = (f_ + r": error: dataset '/%sposition', %s: the position \(1e\+300, .*\) is outside "
              r"the domain along x \(periodic" % (g, particle(5))) if kind == "checkpoint" else \
        (f_ + r": error: dataset '/position', %s: the particle lies outside the domain: its "
         r"centre x = 1e\+300 is outside the periodic range" % particle(5))
elif case == "negative_radius":
    edit(setitem(g + "radius", 2, -edit(lambda f: f[g + "radius"][2])))
    expect = f_ + r": error: dataset '/%sradius', %s: the radius -[0-9.e-]+ m is not a finite " \
        r"number > 0" % (g, particle(2))
elif case == "equal_ids":
    edit(setitem(g + "id", 4, ids[3]))
    expect = f_ + r": error: dataset '/%sid', index 4: the particle id %d is also at index 3; " \
        r"ids must be unique" % (g, ids[3])
elif case == "zero_mass":
    edit(setitem(g + "mass", 6, 0.0))
    expect = f_ + r": error: dataset '/%smass', %s: the mass 0 kg is not rho \(4/3\) pi r\^3 = " \
        r"[0-9.e-]+ kg of material 'glass' \(density 2500 kg/m\^3, radius [0-9.e-]+ m; relative " \
        r"tolerance 1e-06\)" % (g, particle(6))
elif case == "mass_not_rho_v":  # issue 17 item 8: twice rho V
    edit(setitem(g + "mass", 6, 2 * edit(lambda f: f[g + "mass"][6])))
    expect = f_ + r": error: dataset '/%smass', %s: the mass [0-9.e-]+ kg is not rho \(4/3\) pi " \
        r"r\^3" % (g, particle(6))
elif case == "velocity_bit":  # only the checksum sees it
    flip_low_bit(g + "velocity", 7, 0)
    expect = (r"cannot read checkpoint '%s': dataset '/particles/velocity' cannot be read: its "
              r"Fletcher32 checksum does not match the data" % f_) if kind == "checkpoint" else \
        (f_ + r": error: cannot read dataset '/velocity': its Fletcher32 checksum does not "
         r"match the data")
elif case in ("dt_bit", "time_bit"):  # attributes have no HDF5 checksum: only grainflow's
    name = case.split("_")[0]
    flip_bytes_bit(attribute_offset(name), 0)  # the lowest mantissa bit: one ulp
    expect = f_ + r": error: the root group's attributes \(time, dt, step, next_id, rebuilds, " \
        r"material_coarse_grain, material_real, wall_impulse, largest_radius, removed, skin, " \
        r"rayleigh_fraction\) do not match their checksum, " \
        r"attribute 'attributes_checksum' \(stored 0x[0-9a-f]{8}, computed 0x[0-9a-f]{8}\): the " \
        r"checkpoint was changed or damaged after it was written"
elif case == "chunk_record":  # HDF5 then reads zeros for every position, with no error
    with h5py.File(target, "r") as f:
        rank = len(f[g + "position"].shape)
    # The high byte of the element dimension's offset: the chunk is looked for elsewhere.
    flip_bytes_bit(chunk_key_offset(g + "position") + 8 + 8 * rank + 7, 6)
    expect = (r"cannot read checkpoint '%s': dataset '/particles/position' cannot be read: "
              r"chunk 0 \(rows 0 on\) is not where the file's record says" % f_) \
        if kind == "checkpoint" else \
        (f_ + r": error: cannot read dataset '/position': chunk 0 \(rows 0 on\) is not where the "
         r"file's record says")
elif case == "end_before":  # an intact checkpoint, a scene that ends before it
    text = open(scene).read()
    assert "end: 0.01}" in text
    scene = os.path.join(here, "ends_early.yaml")
    with open(scene, "w") as out:
        out.write(text.replace("end: 0.01}", "end: 0.003}"))
    line = 1 + text[:text.index("end: 0.01}")].count("\n")
    expect = r"ends_early\.yaml:%d: error: time\.end = 0\.003 s is before the checkpoint's " \
        r"time, t = 0\.00[45]\d* s \(step \d+, '%s'\): the restart would run no step; raise " \
        r"time\.end" % (line, f_)
elif case == "step_changed":  # an intact checkpoint, a scene whose time.step is another
    text = open(scene).read()
    assert "rayleigh_fraction: 0.15," in text
    scene = os.path.join(here, "step_changed.yaml")
    with open(scene, "w") as out:
        out.write(text.replace("rayleigh_fraction: 0.15,", "step: 1e-6,"))
    line = 1 + text[:text.index("rayleigh_fraction: 0.15,")].count("\n")
    expect = r"step_changed\.yaml:%d: error: time\.step = 1e-06 s, but checkpoint '%s' was " \
        r"written with a step of ([0-9.e-]+) s, which a restart keeps .*: set time\.step to " \
        r"([0-9.e-]+) to restart" % (line, f_)
elif case == "spring_partner":
    edit(lambda f: set_spring(f, ids[0], 10**9))
    expect = f_ + r": error: dataset '/springs/partner', index 0 \(particle id %d\): the spring's " \
        r"partner id 1000000000 is not a particle of the file" % ids[0]
elif case == "spring_wall":  # the scene has one plane: wall history column 0 only
    edit(lambda f: set_spring(f, ids[0], -1 - 7))
    expect = f_ + r": error: dataset '/springs/partner', index 0 \(particle id %d\): the spring's " \
        r"partner -8 names wall history column 7, but the scene's walls have 1" % ids[0]
elif case == "next_id":
    edit(lambda f: f.attrs.__setitem__("next_id", np.int64(ids.max())))
    expect = f_ + r": error: attribute 'next_id' of the root group: next_id = %d is not above " \
        r"the largest particle id %d" % (ids.max(), ids.max())
elif case == "largest_radius":  # below the beads' own radii: the bins would miss contacts
    edit(lambda f: f.attrs.__setitem__("largest_radius", np.float64(1e-4)))
    expect = f_ + r": error: attribute 'largest_radius' of the root group: the interaction " \
        r"range's radius 1e-0?4 m is not a finite number between the largest particle radius " \
        r"\([0-9.e-]+ m\) and half the domain's longest side"
elif case == "removed":
    edit(lambda f: f.attrs.__setitem__("removed", np.int64(-3)))
    expect = f_ + r": error: attribute 'removed' of the root group: the count of removed " \
        r"particles -3 is negative"
elif case == "grid_ranks":  # written on 1 rank: a 1 x 1 x 1 grid said to be of 2 ranks
    edit(setitem("decomposition/ranks", 0, 2))
    expect = f_ + r": error: dataset '/decomposition/dims', index 0: the grid 1 x 1 x 1 has 1 " \
        r"boxes, but the file was written by 2 ranks"
elif case == "grid_planes":  # 3 ranks along x whose middle planes go backwards
    def planes(f):
        f["decomposition/ranks"][0] = 3
        f["decomposition/dims"][...] = np.array([3, 1, 1], "<i4")
        del f["decomposition/cuts_x"]
        f.create_dataset("decomposition/cuts_x", data=np.array([0, 0.009, 0.006, 0.015]),
                         chunks=(4,), fletcher32=True)
    edit(planes)
    expect = f_ + r": error: dataset '/decomposition/cuts_x', index 2: the plane 0.006 m is not " \
        r"a finite number above the one before, 0.009 m \(the planes must increase strictly\)"
else:
    fail("unknown case " + case)

before = {p: hashlib.sha256(open(os.path.join(here, "out", p), "rb").read()).hexdigest()
          for p in os.listdir(os.path.join(here, "out"))}
if kind == "checkpoint":
    cmd = [grain, "run", scene, "--output", "out", "--no-progress", "--restart", relative]
else:
    text = open(scene).read()
    text = re.sub(r"(?ms)^insert:.*?(?=^\S)", "insert:\n  - {type: snapshot, file: %s}\n"
                  % relative, text)
    with open(os.path.join(here, "scene.yaml"), "w") as out:
        out.write(text)
    cmd = [grain, "run", "scene.yaml", "--output", "out", "--no-progress"]
r = subprocess.run(cmd, cwd=here, capture_output=True, text=True, timeout=60)
out = r.stdout + r.stderr
print(" ".join(cmd))
print(out)
if r.returncode != 1:
    fail("exit code %d, expected 1" % r.returncode)
if not re.search(expect, out):
    fail("no message matching: " + expect)
after = {p: hashlib.sha256(open(os.path.join(here, "out", p), "rb").read()).hexdigest()
         for p in os.listdir(os.path.join(here, "out"))}
if after != before:
    fail("the output directory changed: %s -> %s" % (sorted(before), sorted(after)))
if case == "step_changed":  # the message's advice, taken as written, restarts
    advised = re.search(expect, out).group(2)
    text = open(scene).read().replace("step: 1e-6,", "step: %s," % advised)
    with open(scene, "w") as out_file:
        out_file.write(text)
    r = subprocess.run(cmd, cwd=here, capture_output=True, text=True, timeout=60)
    print(" ".join(cmd) + "   # with time.step: " + advised)
    print(r.stdout + r.stderr)
    if r.returncode != 0 or "the checkpoint's step, which the restart keeps" not in r.stdout:
        fail("the advised time.step %s did not restart (exit %d)" % (advised, r.returncode))
print("PASS")
