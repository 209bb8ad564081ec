// pointInterpolationCheck: grainflow's point interpolation of records (coupling/foam/
// pointInterpolation) against OpenFOAM's volPointInterpolation::interpolate(vf, pf), field by
// field, on a case's mesh, serial or -parallel (test coupling.point_interpolation, cases in
// tests/coupling/pointinterp/).
//
// Fields: three vector fields and a scalar field, smooth and non-linear in x, y, z, side by
// side in records of 10 doubles (vectors at 0, 3 and 6, the scalar at 9: the layout of the
// coupling's cellPoint sampling) and the same width-13 layout with a fourth vector. Their
// values on the patches that are not constraints are exact (fixedValue); constraint patches
// keep their types, so the symmetry patches hold the tangential part of the cell value.
//
// Check: every point value of every field equal, to the last bit, to OpenFOAM's. The class
// evaluates OpenFOAM's weights with OpenFOAM's formulas and sums in OpenFOAM's order, so no
// tolerance is needed; a tolerance would hide a changed order of summation.
//
// Also the coupling's grad p (coupling/foam/gaussLinearGrad.H) against fvc::grad with the
// case's "Gauss linear": every cell and boundary value of the scalar field's gradient, bit for
// bit (grad=..: the values compared and how many differ).
//
// On a mesh with a
// patch type the class does not reproduce it must say so (unsupported=...), and the test
// expects that where the case asks for it. The line printed (by the master):
//
//   pointInterpolationCheck: ranks=.. points=.. values=.. differing=.. maxDiff=.. status=ok
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "Time.H"
#include "argList.H"
#include "coupling/foam/gaussLinearGrad.H"
#include "coupling/foam/pointInterpolation.H"
#include "tests/coupling/foamTestFields.H"
#include "fvcGrad.H"
#include "fvMesh.H"
#include "pointFields.H"
#include "volFields.H"
#include "volPointInterpolation.H"

namespace {

using grainflow::foam::PointInterpolation;

Foam::vector vectorField(const Foam::point& x, double L, int k) {
  const double a = x.x() / L, b = x.y() / L, c = x.z() / L;
  return Foam::vector(std::sin(3 * a + k) * std::cos(2 * b) + c * c,
                      a * b * c + std::exp(-a * (k + 1)), std::cos(a + 2 * b - c * k));
}
double scalarField(const Foam::point& x, double L) {
  const double a = x.x() / L, b = x.y() / L, c = x.z() / L;
  return 0.5 + 0.3 * std::sin(2 * a) * std::cos(3 * b) * (1 + c * c);
}

using grainflow::foam::test::makeField;

// OpenFOAM's point values, as the coupling's fallback computes them (particleCoupling.C).
template <class Type>
Foam::tmp<Foam::GeometricField<Type, Foam::pointPatchField, Foam::pointMesh>> foamPoints(
    const Foam::GeometricField<Type, Foam::fvPatchField, Foam::volMesh>& field) {
  using PointField = Foam::GeometricField<Type, Foam::pointPatchField, Foam::pointMesh>;
  const Foam::fvMesh& mesh = field.mesh();
  const Foam::pointMesh& pMesh = Foam::pointMesh::New(mesh);
  Foam::tmp<PointField> tp(new PointField(
      Foam::IOobject("volPointInterpolate(" + field.name() + ')', field.instance(), pMesh.thisDb(),
                     Foam::IOobject::NO_READ, Foam::IOobject::NO_WRITE, false),
      pMesh, field.dimensions()));
  Foam::volPointInterpolation::New(mesh).interpolate(field, tp.ref());
  return tp;
}

struct Tally {
  long values = 0, differing = 0;
  double maxDiff = 0;
  void add(double ours, double foam) {
    ++values;
    // Bitwise: +0 and -0 count as equal (OpenFOAM's own order can give either sign to an
    // exact zero), NaN never does.
    if (!(ours == foam)) {
      ++differing;
      maxDiff = std::max(maxDiff, std::abs(ours - foam));
    }
  }
};

template <int width>
void check(const Foam::fvMesh& mesh, const PointInterpolation& ours,
           const std::vector<const Foam::volVectorField*>& vectors,
           const Foam::volScalarField& scalar, Tally& tally) {
  using namespace Foam;
  // The records: vectors at 0, 3, 6 (and 10), the scalar at 9.
  std::vector<int> offsets = {0, 3, 6};
  if (width == 13) offsets.push_back(10);
  const std::size_t nSources = mesh.nCells() + ours.faces().size();
  std::vector<double> sources(width * nSources, 0.0);
  const auto put = [&](std::size_t record, int offset, const double* v, int n) {
    std::copy_n(v, n, &sources[width * record + offset]);
  };
  for (label c = 0; c < mesh.nCells(); ++c) {
    for (std::size_t f = 0; f < offsets.size(); ++f)
      put(c, offsets[f], (*vectors[f])[c].cdata(), 3);
    put(c, 9, &scalar[c], 1);
  }
  forAll(ours.faces(), i) {
    const PointInterpolation::Face& face = ours.faces()[i];
    const std::size_t record = mesh.nCells() + i;
    for (std::size_t f = 0; f < offsets.size(); ++f)
      put(record, offsets[f], vectors[f]->boundaryField()[face.patch][face.face].cdata(), 3);
    put(record, 9, &scalar.boundaryField()[face.patch][face.face], 1);
  }
  std::vector<double> points(width * mesh.nPoints());
  ours.interpolate<width>(sources.data(), offsets, points.data());

  for (std::size_t f = 0; f < offsets.size(); ++f) {
    const tmp<pointVectorField> foam = foamPoints(*vectors[f]);
    forAll(foam(), p)
      for (int d = 0; d < 3; ++d) tally.add(points[width * p + offsets[f] + d], foam()[p][d]);
  }
  const tmp<pointScalarField> foam = foamPoints(scalar);
  forAll(foam(), p) tally.add(points[width * p + 9], foam()[p]);
}

int run(const Foam::argList& args) {
  using namespace Foam;
  Time runTime(Time::controlDictName, args);
  fvMesh mesh(IOobject(fvMesh::defaultRegion, runTime.timeName(), runTime, IOobject::MUST_READ));
  // The same length on every rank: the fields are one field over the decomposed mesh.
  const double L = returnReduce(mag(mesh.bounds().span()), maxOp<scalar>());
  std::vector<tmp<volVectorField>> fields;
  for (int k = 0; k < 4; ++k)
    fields.push_back(makeField<vector>(mesh, "V" + std::to_string(k),
                                       [L, k](const point& x) { return vectorField(x, L, k); }));
  const tmp<volScalarField> eps =
      makeField<scalar>(mesh, "eps", [L](const point& x) { return scalarField(x, L); });

  // grad: ours against fvc::grad (Gauss linear, from the case's fvSchemes).
  Tally grad;
  {
    volVectorField mine(IOobject("grad(eps)", runTime.timeName(), mesh, IOobject::NO_READ,
                                 IOobject::NO_WRITE, false),
                        mesh, dimensionedVector("zero", dimless / dimLength, Zero),
                        extrapolatedCalculatedFvPatchField<vector>::typeName);
    grainflow::foam::gaussLinearGrad(eps(), mine);
    const tmp<volVectorField> foam = fvc::grad(eps());
    forAll(mine, c)
      for (int d = 0; d < 3; ++d) grad.add(mine[c][d], foam()[c][d]);
    forAll(mine.boundaryField(), patch)
      forAll(mine.boundaryField()[patch], f)
        for (int d = 0; d < 3; ++d)
          grad.add(mine.boundaryField()[patch][f][d], foam().boundaryField()[patch][f][d]);
  }
  const long gradValues = returnReduce(grad.values, sumOp<long>());
  const long gradDiffering = returnReduce(grad.differing, sumOp<long>());

  const PointInterpolation ours(mesh);
  if (!ours.unsupported().empty()) {
    Info << "pointInterpolationCheck: ranks=" << Pstream::nProcs()
         << " unsupported=" << ours.unsupported().c_str() << " grad=" << gradDiffering << '/'
         << gradValues << (gradDiffering == 0 ? " status=unsupported" : " status=FAIL") << endl;
    return gradDiffering == 0 ? 0 : 1;
  }

  Tally tally;
  check<10>(mesh, ours, {&fields[0](), &fields[1](), &fields[2]()}, eps(), tally);
  check<13>(mesh, ours, {&fields[0](), &fields[1](), &fields[2](), &fields[3]()}, eps(), tally);
  const long points = returnReduce(long(mesh.nPoints()), sumOp<long>());
  const long values = returnReduce(tally.values, sumOp<long>());
  const long differing = returnReduce(tally.differing, sumOp<long>());
  const double maxDiff = returnReduce(tally.maxDiff, maxOp<double>());
  const bool ok = differing == 0 && values > 0 && gradDiffering == 0 && gradValues > 0;
  char line[320];
  std::snprintf(line, sizeof line,
                "pointInterpolationCheck: ranks=%d points=%ld values=%ld differing=%ld "
                "maxDiff=%.3g grad=%ld/%ld status=%s",
                Pstream::nProcs(), points, values, differing, maxDiff, gradDiffering, gradValues,
                ok ? "ok" : "FAIL");
  Info << line << endl;
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char* argv[]) {
  Foam::argList::addNote(
      "Checks grainflow's point interpolation of records against OpenFOAM's "
      "volPointInterpolation on the case's mesh (test coupling.point_interpolation).");
  Foam::argList args(argc, argv);
  if (!args.checkRootCase()) Foam::FatalError.exit();
  const int status = Foam::returnReduce(run(args), Foam::maxOp<int>());
  Foam::Pstream::exit(status);
  return status;
}
