"""Run by pvbatch: what ParaView's own XDMF reader makes of a grainflow particles.xdmf.

    pvbatch --force-offscreen-rendering paraview_dump.py INDEX PNG JSON [INDEX PNG JSON ...]

Opens INDEX with ParaView's "XDMF Reader" (XDMFReader, the XDMF 2 reader: the Xdmf3 readers
give the Polyvertex grids no cells), writes for every time step the points and every point
array of its "particles" block (each time step is a multiblock; a snapshot of no particle has
no such block: 0 points) with its components and values into JSON, and renders the last step
(beads as spheres of their radius, coloured by speed) into PNG (PNG "-": no picture); the
JSON also holds the share of the picture's pixels that differ from the background.
tests/dem/app/paraview_reads_snapshots.py compares it all with the HDF5 files.
"""
import json
import sys

from paraview import servermanager as sm
from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetColorTransferFunction,
                             ResetCamera, SaveScreenshot, Show, XDMFReader)
from paraview.vtk.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOImage import vtkPNGReader



def particles_block(multiblock):
    """The block the reader made of the time step's "particles" grid (None: no such grid)."""
    found = None
    it = multiblock.NewIterator()
    it.InitTraversal()
    while not it.IsDoneWithTraversal():
        if it.GetCurrentMetaData().Get(multiblock.NAME()).split("[")[0] == "particles":
            found = it.GetCurrentDataObject()
        it.GoToNextItem()
    return found


def read_steps(index):
    """The reader of INDEX and, for every time step, its particles' points and arrays."""
    reader = XDMFReader(FileNames=[index])
    reader.PointArrayStatus = reader.GetProperty("PointArrayInfo")[::2]  # every array
    reader.UpdatePipelineInformation()
    steps = []
    for t in reader.TimestepValues:
        reader.UpdatePipeline(t)
        data = particles_block(sm.Fetch(reader))
        if data is None:
            steps.append({"time": t, "points": 0, "cells": 0, "positions": [], "arrays": {}})
            continue
        arrays = {}
        pd = data.GetPointData()
        for i in range(pd.GetNumberOfArrays()):
            a = pd.GetArray(i)
            arrays[a.GetName()] = {"components": a.GetNumberOfComponents(),
                                   "type": a.GetDataTypeAsString(),
                                   "values": vtk_to_numpy(a).tolist()}
        steps.append({"time": t, "points": data.GetNumberOfPoints(),
                      "cells": data.GetNumberOfCells(),
                      "positions": vtk_to_numpy(data.GetPoints().GetData()).tolist(),
                      "arrays": arrays})
    return reader, steps


def render(reader, png):
    """The last step drawn into PNG; its size and the share of pixels off the background."""
    view = GetActiveViewOrCreate("RenderView")
    view.ViewSize = [800, 600]
    view.ViewTime = reader.TimestepValues[-1]
    view.OrientationAxesVisibility = 0
    shown = Show(reader, view)
    shown.SetRepresentationType("Point Gaussian")
    shown.ScaleByArray = 1
    shown.SetScaleArray = ["POINTS", "radius"]
    shown.UseScaleFunction = 0
    shown.GaussianRadius = 1.0
    shown.ShaderPreset = "Sphere"
    ColorBy(shown, ("POINTS", "velocity", "Magnitude"))
    shown.RescaleTransferFunctionToDataRange(True, False)
    shown.SetScalarBarVisibility(view, True)
    GetColorTransferFunction("velocity").ApplyPreset("Viridis (matplotlib)", True)
    view.CameraPosition = [0.06, -0.05, 0.04]
    view.CameraViewUp = [0, 0, 1]
    ResetCamera(view)
    SaveScreenshot(png, view, ImageResolution=[800, 600])
    image = vtkPNGReader()
    image.SetFileName(png)
    image.Update()
    pixels = vtk_to_numpy(image.GetOutput().GetPointData().GetScalars())[:, :3].astype(int)
    background = pixels[0]  # a corner
    drawn = float((abs(pixels - background).sum(axis=1) > 30).mean())
    dims = image.GetOutput().GetDimensions()
    return {"width": dims[0], "height": dims[1], "drawn": drawn}


# One pvbatch (one X connection, the flaky part under Xvfb) for every INDEX PNG JSON triple.
args = sys.argv[1:]
for k in range(0, len(args) - 2, 3):
    index, png, out = args[k:k + 3]
    reader, steps = read_steps(index)
    result = {"steps": steps}
    if png != "-":
        result["image"] = render(reader, png)
    json.dump(result, open(out, "w"))
