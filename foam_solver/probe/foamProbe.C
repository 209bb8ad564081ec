// foamProbe: opens an OpenFOAM case's mesh through Debian's OpenFOAM v1912 libraries and
// prints one machine-readable line, so that the build (headers from the Debian source package,
// libraries from /usr/lib, see DESIGN.md section 8) is checked end to end:
//
//   foamProbe: cells=120 volume=0.006 bbmin=0,0,0 bbmax=0.1,0.2,0.3 grad_mean=1,0,0 ... status=ok
//
// It also evaluates one finiteVolume operation, the Gauss gradient of the cell-centre
// x-coordinate. Summed over the cells (weighted by volume), the internal faces cancel and only
// boundary faces remain, where the value is the exact face-centre x; for planar boundary faces
// that is the exact surface integral, so the mean gradient is (1,0,0) up to round-off on any
// mesh, however skewed inside. (Warped boundary faces break this: the check then fails.)
// Exit status: 0 if every check passes, 1 otherwise.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>

#include "Time.H"
#include "argList.H"
#include "fvMesh.H"
#include "fvcGrad.H"
#include "volFields.H"

namespace {

std::string csv(const Foam::vector& v) {
  std::ostringstream s;
  s.precision(17);
  s << v.x() << ',' << v.y() << ',' << v.z();
  return s.str();
}

// Round-off bound for sums of O(nCells) terms of order one, with ample margin; a wrong build
// (mismatched headers, wrong label size) gives errors of order one, not 1e-9.
constexpr double kGradTolerance = 1e-9;

}  // namespace

int main(int argc, char* argv[]) {
  Foam::argList::addNote(
      "Opens the case's mesh and prints cells, total volume, bounding box and a check of "
      "fvc::grad on one machine-readable line (grainflow build check).");
  Foam::argList args(argc, argv);
  if (!args.checkRootCase()) {
    Foam::FatalError.exit();
  }
  Foam::Time runTime(Foam::Time::controlDictName, args);
  Foam::fvMesh mesh(Foam::IOobject(Foam::fvMesh::defaultRegion, runTime.timeName(), runTime,
                                   Foam::IOobject::MUST_READ));

  // Global values: the reductions make the same code right for a decomposed case.
  const Foam::label cells = Foam::returnReduce(mesh.nCells(), Foam::sumOp<Foam::label>());
  const double volume = Foam::gSum(mesh.V().field());
  const double minCellVolume = Foam::gMin(mesh.V().field());
  const Foam::boundBox& box = mesh.bounds();

  const Foam::volScalarField x("x", mesh.C().component(Foam::vector::X));
  const Foam::volVectorField gradX("gradX", Foam::fvc::grad(x));
  const Foam::vector gradMean = Foam::gSum(mesh.V().field() * gradX.primitiveField()) / volume;
  const Foam::vector expected(1, 0, 0);
  const double gradMeanError = Foam::mag(gradMean - expected);
  // Cell-wise the Gauss gradient is exact only where linear interpolation hits face centres
  // (e.g. uniform hexahedra), so this is reported, not checked.
  const double gradMaxCellError = Foam::gMax(Foam::mag(gradX.primitiveField() - expected)());

  bool ok = true;
  auto check = [&ok](bool passed, const char* what) {
    if (!passed) {
      ok = false;
      if (Foam::Pstream::master()) std::fprintf(stderr, "foamProbe: check failed: %s\n", what);
    }
  };
  check(cells > 0, "the mesh has no cells");
  check(minCellVolume > 0, "a cell has zero or negative volume (mesh.V())");
  check(std::isfinite(volume), "total volume is not finite");
  check(std::isfinite(gradMeanError) && gradMeanError < kGradTolerance,
        "volume-weighted mean of fvc::grad(x) differs from (1,0,0)");

  if (Foam::Pstream::master()) {
    std::ostringstream line;
    line.precision(17);
    line << "foamProbe: cells=" << cells << " volume=" << volume
         << " min_cell_volume=" << minCellVolume << " bbmin=" << csv(box.min())
         << " bbmax=" << csv(box.max()) << " grad_mean=" << csv(gradMean)
         << " grad_mean_error=" << gradMeanError << " grad_max_cell_error=" << gradMaxCellError
         << " nprocs=" << Foam::Pstream::nProcs() << " status=" << (ok ? "ok" : "failed");
    std::cout << line.str() << std::endl;
  }
  return ok ? 0 : 1;
}
