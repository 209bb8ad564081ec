// fluxReconstructionCheck: grainflow::foam::reconstructFlux (coupling/foam/fluxReconstruction.H,
// the cell velocity grainFoam corrects U with) against its closed form on a case's mesh (test
// coupling.flux_reconstruction, meshes of tests/coupling/cellpoint/ and reconstruct/flat).
//
// The flux of a uniform velocity U0, phi_f = S_f . U0, reconstructs to U0 in every cell and on
// every boundary face but those of constraint patches, on any mesh: sum_f n_f S_f^T U0 = (sum_f n_f
// S_f^T) U0. A 2-D mesh (one direction empty) has no faces along it, and the component along it is
// 0; U0 is then given without it. Check: |u - U0| <= 1e-12 |U0| everywhere (round-off of a 3 x 3
// inverse and of the face sums: measured up to a few 1e-15), also with the mesh scaled by 2^-20
// (sub-micrometre cells) and 2^10, which scale the face areas but must not change u.
//
// Printed for the docs, not checked: the error of OpenFOAM v1912's own fvc::reconstruct on
// the same flux (fluxReconstruction.H says why it is wrong). The line printed:
//
//   fluxReconstructionCheck: cells=.. nonOrthogonal=.. maxError=.. fvcReconstructError=..
//   status=ok
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "Time.H"
#include "argList.H"
#include "coupling/foam/fluxReconstruction.H"
#include "fvMesh.H"
#include "fvcReconstruct.H"

namespace {

// Largest |u - u0| / |u0| over the cells and boundary faces.
double largestError(const Foam::volVectorField& u, const Foam::vector& u0) {
  double e = 0;
  for (const Foam::vector& v : u.primitiveField())
    e = std::max(e, Foam::mag(v - u0) / Foam::mag(u0));
  // Boundary values: the adjacent cell's, on every patch that is not a constraint (symmetry
  // planes hold the tangential part, cyclic and empty patches none of their own).
  for (const auto& patch : u.boundaryField())
    if (patch.type() == Foam::extrapolatedCalculatedFvPatchVectorField::typeName)
      for (const Foam::vector& v : patch) e = std::max(e, Foam::mag(v - u0) / Foam::mag(u0));
  return e;
}

}  // namespace

int main(int argc, char* argv[]) {
  using namespace Foam;
  argList::noParallel();
  argList args(argc, argv);
  Time runTime(Time::controlDictName, args);
  fvMesh mesh(IOobject(fvMesh::defaultRegion, runTime.timeName(), runTime, IOobject::MUST_READ));

  // A 2-D mesh reconstructs no component along its empty direction.
  vector u0(0.3, -0.2, 0.7);
  const Vector<label>& solved = mesh.solutionD();
  for (direction d = 0; d < vector::nComponents; ++d)
    if (solved[d] < 0) u0[d] = 0;

  double error = 0, fvcError = 0;
  for (const double scale : {1.0, std::ldexp(1.0, -20), std::ldexp(1.0, 10)}) {
    if (scale != 1) {
      pointField points(mesh.points() * scale);
      mesh.movePoints(points);
    }
    const surfaceScalarField flux(IOobject("flux", runTime.timeName(), mesh), mesh.Sf() & u0);
    error = std::max(error, largestError(grainflow::foam::reconstructFlux(flux)(), u0));
    if (scale == 1) fvcError = largestError(fvc::reconstruct(flux)(), u0);
    if (scale != 1) {
      pointField points(mesh.points() / scale);
      mesh.movePoints(points);
    }
  }
  // Cells with a face whose normal is not along the line of the cell centres.
  label nonOrthogonal = 0;
  {
    std::vector<char> skew(static_cast<std::size_t>(mesh.nCells()), 0);
    forAll(mesh.owner(), f) {
      const vector delta = mesh.C()[mesh.neighbour()[f]] - mesh.C()[mesh.owner()[f]];
      const vector n = mesh.Sf()[f] / mesh.magSf()[f];
      if (mag(n ^ (delta / mag(delta))) > 1e-9)
        skew[static_cast<std::size_t>(mesh.owner()[f])] =
            skew[static_cast<std::size_t>(mesh.neighbour()[f])] = 1;
    }
    for (const char s : skew) nonOrthogonal += s;
  }
  const bool ok = error <= 1e-12;
  std::printf(
      "fluxReconstructionCheck: cells=%d nonOrthogonal=%d maxError=%.3g "
      "fvcReconstructError=%.3g status=%s\n",
      mesh.nCells(), nonOrthogonal, error, fvcError, ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
