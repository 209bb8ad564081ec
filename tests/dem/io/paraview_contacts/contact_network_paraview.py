"""ParaView's own XDMF reader (pvbatch) on a snapshot series with output.contacts: true.

Usage: pvbatch contact_network_paraview.py <output folder> [<picture.png>]

For every time of particles.xdmf, the reader's multiblock holds the particles' points and
one line per contact of each network group, and the lines' cell arrays are the file's
datasets: checked against the HDF5 files read independently with h5py (the count attribute,
the datasets themselves). Exits 1 on the first mismatch, naming it. With a picture path, the
last time is rendered: the contact lines coloured by their normal force, over the beads.
"""
import os
import sys

import h5py
import numpy as np
from paraview import servermanager
from paraview.simple import (ColorBy, GetActiveViewOrCreate, Render, ResetCamera,
                             SaveScreenshot, Show, XDMFReader)
from vtkmodules.numpy_interface import dataset_adapter as dsa

GROUPS = {"contacts": ["point", "normal_force", "tangential_force",
                       "normal_force_magnitude", "overlap"],
          "wall_contacts": ["id", "wall", "point", "normal_force", "tangential_force",
                            "normal_force_magnitude", "overlap"]}


def fail(message):
    print("contact_network_paraview: " + message, file=sys.stderr)
    sys.exit(1)


def blocks_by_name(multiblock):
    out = {}
    it = multiblock.NewIterator()
    it.InitTraversal()
    while not it.IsDoneWithTraversal():
        name = it.GetCurrentMetaData().Get(multiblock.NAME())
        out[name.split("[")[0]] = it.GetCurrentDataObject()
        it.GoToNextItem()
    return out


def main():
    folder = sys.argv[1]
    picture = sys.argv[2] if len(sys.argv) > 2 else None
    index = os.path.join(folder, "particles.xdmf")
    files = sorted(f for f in os.listdir(folder) if f.startswith("particles_") and f.endswith(".h5"))
    # The XDMF 2 reader ("XDMF Reader"): the Xdmf3 readers give Polyvertex grids no cells.
    reader = XDMFReader(FileNames=[index])
    times = list(reader.TimestepValues)
    if len(times) != len(files):
        fail(f"{index}: ParaView sees {len(times)} times, the folder holds {len(files)} snapshots")
    lines_total = 0
    for t, name in zip(times, files):
        reader.UpdatePipeline(t)
        data = servermanager.Fetch(reader)
        blocks = blocks_by_name(data)
        with h5py.File(os.path.join(folder, name), "r") as h5:
            # The reader names a block after its grid, with the time's index appended; a group
            # without contacts has no grid.
            want = ["particles"] + [g for g in GROUPS if h5[g].attrs["count"] > 0]
            if sorted(blocks) != sorted(want):
                fail(f"t = {t}: blocks {sorted(blocks)}, expected {want}")
            if abs(h5.attrs["time"] - t) > 1e-12 * max(1.0, abs(t)):
                fail(f"{name}: time {h5.attrs['time']} read as {t}")
            particles = blocks["particles"]
            if particles.GetNumberOfPoints() != h5.attrs["count"]:
                fail(f"{name}: {particles.GetNumberOfPoints()} points, {h5.attrs['count']} particles")
            for group, arrays in GROUPS.items():
                m = int(h5[group].attrs["count"])
                if m == 0:
                    continue
                block = blocks[group]
                if block.GetNumberOfCells() != m:
                    fail(f"{name}: {group}: {block.GetNumberOfCells()} lines, count {m}")
                for c in range(m):
                    if block.GetCell(c).GetNumberOfPoints() != 2:
                        fail(f"{name}: {group}: line {c} has {block.GetCell(c).GetNumberOfPoints()} nodes")
                cells = dsa.WrapDataObject(block).CellData
                for array in arrays:
                    want = h5[group][array][()]
                    if array not in cells.keys():
                        fail(f"{name}: {group}: no cell array '{array}' (has {list(cells.keys())})")
                    got = np.asarray(cells[array]).reshape(want.shape)
                    if not np.array_equal(got, want):
                        fail(f"{name}: {group}/{array} differs from the file")
                if group == "contacts":
                    ids = h5[group]["id"][()]
                    for column, array in enumerate(["id_a", "id_b"]):
                        if array not in cells.keys():
                            fail(f"{name}: {group}: no cell array '{array}'")
                        if not np.array_equal(np.asarray(cells[array]), ids[:, column]):
                            fail(f"{name}: {group}/{array} is not column {column} of id")
                ends = h5[group]["ends"][()]
                if not np.array_equal(np.asarray(dsa.WrapDataObject(block).Points), ends):
                    fail(f"{name}: {group}: the line nodes are not the file's ends")
                lines_total += m
    if lines_total == 0:
        fail("no contact in any snapshot: nothing was checked")
    print(f"contact_network_paraview: {len(times)} times, {lines_total} contact lines read "
          f"by ParaView's XDMF reader, equal to the files")
    if picture:
        # The reader's blocks are named per time ("contacts[3]"), so the whole multiblock is
        # shown: the lines coloured by their normal force, the beads (no such array) as grey
        # points.
        view = GetActiveViewOrCreate("RenderView")
        view.ViewSize = [800, 600]
        view.ViewTime = times[-1]
        reader.UpdatePipeline(times[-1])
        display = Show(reader, view)
        ColorBy(display, ("CELLS", "normal_force_magnitude"))
        display.LineWidth = 3
        display.PointSize = 4
        display.RescaleTransferFunctionToDataRange(False, True)
        display.SetScalarBarVisibility(view, True)
        view.CameraPosition = [0.03, -0.03, 0.015]
        view.CameraFocalPoint = [0, 0, 0.003]
        view.CameraViewUp = [0, 0, 1]
        ResetCamera()
        Render()
        SaveScreenshot(picture, view)
        print(f"contact_network_paraview: wrote {picture}")

main()
