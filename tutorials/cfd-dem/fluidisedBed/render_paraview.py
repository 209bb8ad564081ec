"""The fluidised bed's last write time drawn by ParaView: the beads as spheres of their size
coloured by speed, and beside them the fluid's void fraction on the column's mid-plane.

usage (Allrun calls it when pvbatch is installed):
    ../../../scripts/pvbatch.sh render_paraview.py [--short] [CASE]

Reads CASE/particles/particles.xdmf with ParaView's XDMF reader and the OpenFOAM case with
its OpenFOAM reader (through CASE/case.foam, an empty file it creates; Allclean removes it),
both at the last time they share, and writes CASE/fluidisedBed_paraview.png (with --short:
fluidisedBed_short_paraview.png). Exits 1 when the picture comes out blank.
"""
import argparse
import os
import sys

from paraview.simple import (Calculator, ColorBy, GetActiveViewOrCreate,
                             GetColorTransferFunction, GetScalarBar, OpenFOAMReader,
                             SaveScreenshot, Show, Slice, Transform, XDMFReader)
from paraview.vtk.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOImage import vtkPNGReader

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("case", nargs="?", default=os.path.dirname(os.path.abspath(__file__)))
ap.add_argument("--short", action="store_true", help="the Allrun --short case's picture name")
args = ap.parse_args()
case = os.path.abspath(args.case)
png = os.path.join(case, "fluidisedBed_short_paraview.png" if args.short
                   else "fluidisedBed_paraview.png")

beads = XDMFReader(FileNames=[os.path.join(case, "particles", "particles.xdmf")])
beads.UpdatePipelineInformation()
foam_file = os.path.join(case, "case.foam")
open(foam_file, "w").close()
fluid = OpenFOAMReader(FileName=foam_file)
if os.path.isdir(os.path.join(case, "processor0")):  # Allrun -np N (not reconstructed)
    fluid.CaseType = "Decomposed Case"
fluid.MeshRegions = ["internalMesh"]
fluid.CellArrays = ["voidfraction", "U"]
fluid.UpdatePipelineInformation()
common = sorted(set(round(t, 9) for t in beads.TimestepValues) &
                set(round(t, 9) for t in fluid.TimestepValues))
if not common:
    sys.exit(f"render_paraview: no time both in {case}/particles and in the OpenFOAM case")
t = common[-1]

view = GetActiveViewOrCreate("RenderView")
view.ViewSize = [1200, 900]
view.ViewTime = t
view.OrientationAxesVisibility = 0
view.Background = [1, 1, 1]
try:  # ParaView 5.10+: the palette's background would override the colour above
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass

speed = Calculator(Input=beads, ResultArrayName="speed", Function="mag(velocity)")
shown = Show(speed, view)
shown.SetRepresentationType("Point Gaussian")
shown.ScaleByArray = 1
shown.SetScaleArray = ["POINTS", "radius"]
shown.UseScaleFunction = 0
shown.GaussianRadius = 1.0
shown.ShaderPreset = "Sphere"
ColorBy(shown, ("POINTS", "speed"))
speed_lut = GetColorTransferFunction("speed")
speed_lut.ApplyPreset("Viridis (matplotlib)", True)
shown.RescaleTransferFunctionToDataRange(False, True)
shown.SetScalarBarVisibility(view, True)
bar = GetScalarBar(speed_lut, view)
bar.Title = "bead speed [m/s]"
bar.ComponentTitle = ""

# The void fraction on the mid-plane y = 4.5 mm, drawn 70 mm to the right of the beads.
cut = Slice(Input=fluid)
cut.SliceType = "Plane"
cut.SliceType.Origin = [0.03, 0.0045, 0.12]
cut.SliceType.Normal = [0, 1, 0]
beside = Transform(Input=cut)
beside.Transform = "Transform"
beside.Transform.Translate = [0.07, 0, 0]
plane = Show(beside, view)
ColorBy(plane, ("CELLS", "voidfraction"))
eps_lut = GetColorTransferFunction("voidfraction")
eps_lut.ApplyPreset("Blues", True)  # packed (low void fraction) dark, clear gas light
eps_lut.RescaleTransferFunction(0.35, 1.0)
plane.SetScalarBarVisibility(view, True)
eps_bar = GetScalarBar(eps_lut, view)
eps_bar.Title = "void fraction"
# Both bars right of the plane, the speed's below the void fraction's.
for b, y in ((bar, 0.06), (eps_bar, 0.55)):
    b.TitleColor = b.LabelColor = [0, 0, 0]
    b.WindowLocation = "Any Location"
    b.Position = [0.87, y]
    b.ScalarBarLength = 0.38

# Front view (along +y) of the lower half of the column, where the bed is.
view.CameraParallelProjection = 1
view.CameraFocalPoint = [0.074, 0.0045, 0.062]
view.CameraPosition = [0.074, -0.5, 0.062]
view.CameraViewUp = [0, 0, 1]
view.CameraParallelScale = 0.066
SaveScreenshot(png, view, ImageResolution=[1200, 900])

image = vtkPNGReader()
image.SetFileName(png)
image.Update()
pixels = vtk_to_numpy(image.GetOutput().GetPointData().GetScalars())[:, :3].astype(int)
drawn = float((abs(pixels - [255, 255, 255]).sum(axis=1) > 30).mean())
print(f"render_paraview: t = {t:g} s, {png} ({drawn:.0%} of the pixels drawn)")
if drawn < 0.05:
    raise SystemExit("render_paraview: the picture is blank")
# No sys.exit on success: pvbatch then tears down the render window in an order that Xvfb's
# GLX answers with GLXBadContext, and exits with an error.
