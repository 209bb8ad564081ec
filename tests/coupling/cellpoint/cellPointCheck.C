// cellPointCheck: grainflow's cellPoint interpolation (coupling/foam/cellPointWeights) against
// OpenFOAM's own interpolationCellPoint<Type>::interpolate(x, cell) on a case's mesh (test
// coupling.cellpoint_interpolation, cases in tests/coupling/cellpoint/).
//
// Fields: a vector and a scalar field, smooth and non-linear in x, y, z (so that the choice
// of tetrahedron, and of the diagonal that splits a face, changes the interpolated value:
// with the closed form's diagonals swapped the check fails by 2.4e-2 (uniform) and 5.2e-2
// (graded) of the field's magnitude), with their exact values on fixedValue patches
// and the mesh's constraint types elsewhere; point values by volPointInterpolation, as
// interpolationCellPoint computes them.
//
// Points, in every cell: the centre, the face centres and face points, the midpoints of the
// face edges, points on the faces of OpenFOAM's tetrahedra (their shared sides: the face
// diagonals and the triangles through the centre), random points inside random tetrahedra
// (seeded), and two points just outside the cell (1e-6 of the centre-to-corner distance).
//
// Check: |ours - OpenFOAM's| <= 1e-12 * (the field's largest magnitude) for every point
// and both fields. Why 1e-12: in cells that are not boxes grainflow evaluates OpenFOAM's
// own arithmetic (the difference must be 0, and is reported); in box cells it evaluates
// the same barycentric coordinates in closed form, from other roundings (a few 1e-16 per
// weight, four weights), so the values differ by ~1e-15 of the field's magnitude (measured:
// 1.9e-15 uniform, 1.1e-15 graded). 1e-12 leaves three orders of magnitude for that and is
// ten below what a wrong diagonal gives (above). The line printed:
//
//   cellPointCheck: cells=.. boxCells=.. points=.. boxPoints=.. outside=.. maxBox=..
//   maxOther=.. exactOther=.. searches=.. sameCell=.. faceTies=.. wrongCell=0 status=ok
//
// Also the coupling's cell search (coupling/foam/cellSearch.H, findCellNear): every point
// above, with five hints each (its cell, a random face neighbour, a neighbour's neighbour, a
// random cell, none), must be given the cell OpenFOAM's findCell gives (sameCell), or, for a
// point on a face the two cells share, the other of them (faceTies: pointInCell holds for the
// cell given); -1 exactly where findCell gives -1. A search that took the hint or a
// neighbour without testing it gives wrongCell > 0.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "Time.H"
#include "argList.H"
#include "coupling/foam/cellPointWeights.H"
#include "coupling/foam/cellSearch.H"
#include "fvMesh.H"
#include "interpolationCellPoint.H"
#include "polyMeshTetDecomposition.H"
#include "tests/coupling/foamTestFields.H"
#include "volFields.H"
#include "volPointInterpolation.H"

namespace {

using grainflow::foam::CellPointWeights;

// The test fields, of the point x scaled by the mesh's size L.
Foam::vector vectorField(const Foam::point& x, double L) {
  const double a = x.x() / L, b = x.y() / L, c = x.z() / L;
  return Foam::vector(std::sin(3 * a) * std::cos(2 * b) + c * c, a * b * c + std::exp(-a),
                      std::cos(a + 2 * b - c));
}
double scalarField(const Foam::point& x, double L) {
  const double a = x.x() / L, b = x.y() / L, c = x.z() / L;
  return 0.5 + 0.3 * std::sin(2 * a) * std::cos(3 * b) * (1 + c * c);
}

using grainflow::foam::test::makeField;

double magnitude(const Foam::vector& v) { return Foam::mag(v); }
double magnitude(double s) { return std::abs(s); }

// Points to test in cell c (see the header).
std::vector<Foam::point> testPoints(const Foam::fvMesh& mesh, Foam::label c, std::mt19937& rng) {
  using namespace Foam;
  std::vector<point> out;
  const point& centre = mesh.cellCentres()[c];
  const pointField& points = mesh.points();
  out.push_back(centre);
  for (const label f : mesh.cells()[c]) {
    const face& fc = mesh.faces()[f];
    out.push_back(mesh.faceCentres()[f]);
    forAll(fc, k) {
      out.push_back(points[fc[k]]);
      out.push_back(0.5 * (points[fc[k]] + points[fc.nextLabel(k)]));
    }
  }
  std::uniform_real_distribution<double> u(0, 1);
  const List<tetIndices> tets = polyMeshTetDecomposition::cellTetIndices(mesh, c);
  for (const tetIndices& t : tets) {
    const tetPointRef tet = t.tet(mesh);
    const point v[4] = {tet.a(), tet.b(), tet.c(), tet.d()};
    // On each of the tetrahedron's four sides: a random point of that triangle.
    for (int skip = 0; skip < 4; ++skip) {
      double w[4], sum = 0;
      for (int k = 0; k < 4; ++k) sum += (w[k] = k == skip ? 0.0 : u(rng));
      point x = Zero;
      for (int k = 0; k < 4; ++k) x += (w[k] / sum) * v[k];
      out.push_back(x);
    }
    // Inside: two random points.
    for (int n = 0; n < 2; ++n) {
      double w[4], sum = 0;
      for (double& wk : w) sum += (wk = u(rng));
      point x = Zero;
      for (int k = 0; k < 4; ++k) x += (w[k] / sum) * v[k];
      out.push_back(x);
    }
  }
  // Just outside, beyond two corners.
  const face& first = mesh.faces()[mesh.cells()[c][0]];
  for (int k = 0; k < 2; ++k) out.push_back(centre + (1 + 1e-6) * (points[first[k]] - centre));
  return out;
}

struct Result {
  double maxBox = 0, maxOther = 0;
  long points = 0, boxPoints = 0, exactOther = 0, otherPoints = 0;
  long searches = 0, sameCell = 0, faceTies = 0, wrongCell = 0;
};

// findCellNear against findCell for every test point, with five hints (see the header).
void checkCellSearch(const Foam::fvMesh& mesh, const std::vector<std::vector<Foam::point>>& points,
                     std::mt19937& rng, Result& r) {
  const Foam::labelListList& neighbours = mesh.cellCells();
  std::uniform_int_distribution<Foam::label> anyCell(0, mesh.nCells() - 1);
  auto pick = [&rng](const Foam::labelList& cells, Foam::label fallback) {
    if (cells.empty()) return fallback;
    return cells[std::uniform_int_distribution<Foam::label>(0, cells.size() - 1)(rng)];
  };
  for (std::size_t c = 0; c < points.size(); ++c) {
    const Foam::label cell = static_cast<Foam::label>(c);
    for (const Foam::point& x : points[c]) {
      const Foam::label expected = mesh.findCell(x);
      const Foam::label neighbour = pick(neighbours[cell], cell);
      const Foam::label hints[5] = {cell, neighbour, pick(neighbours[neighbour], neighbour),
                                    anyCell(rng), -1};
      for (const Foam::label hint : hints) {
        const Foam::label got = grainflow::foam::findCellNear(mesh, x, hint);
        ++r.searches;
        if (got == expected)
          ++r.sameCell;
        else if (got >= 0 && expected >= 0 && mesh.pointInCell(x, got, Foam::polyMesh::CELL_TETS))
          ++r.faceTies;
        else
          ++r.wrongCell;
      }
    }
  }
}

template <class Type>
void compare(const Foam::fvMesh& mesh,
             const Foam::GeometricField<Type, Foam::fvPatchField, Foam::volMesh>& field,
             const CellPointWeights& ours, const std::vector<std::vector<Foam::point>>& points,
             const std::vector<bool>& box, Result& r) {
  const Foam::interpolationCellPoint<Type> foam(field);
  const auto pointValues = Foam::volPointInterpolation::New(mesh).interpolate(
      field, "check(" + field.name() + ')', false);
  double scale = 0;
  for (const Type& v : field.primitiveField()) scale = std::max(scale, magnitude(v));
  for (const Type& v : pointValues().primitiveField()) scale = std::max(scale, magnitude(v));
  for (std::size_t c = 0; c < points.size(); ++c)
    for (const Foam::point& x : points[c]) {
      const Foam::label cell = static_cast<Foam::label>(c);
      const Type expected = foam.interpolate(x, cell);
      const Type got =
          CellPointWeights::interpolate(ours.at(x, cell), field.primitiveField(), pointValues());
      const double diff = magnitude(got - expected) / scale;
      ++r.points;
      if (box[c]) {
        ++r.boxPoints;
        r.maxBox = std::max(r.maxBox, diff);
      } else {
        ++r.otherPoints;
        r.maxOther = std::max(r.maxOther, diff);
        if (diff == 0) ++r.exactOther;
      }
    }
}

int run(const Foam::argList& args) {
  Foam::Time runTime(Foam::Time::controlDictName, args);
  Foam::fvMesh mesh(Foam::IOobject(Foam::fvMesh::defaultRegion, runTime.timeName(), runTime,
                                   Foam::IOobject::MUST_READ));
  const double L = Foam::mag(mesh.bounds().span());
  const auto U =
      makeField<Foam::vector>(mesh, "U", [L](const Foam::point& x) { return vectorField(x, L); });
  const auto eps =
      makeField<Foam::scalar>(mesh, "eps", [L](const Foam::point& x) { return scalarField(x, L); });

  const CellPointWeights ours(mesh);
  std::mt19937 rng(12345);
  std::vector<std::vector<Foam::point>> points(static_cast<std::size_t>(mesh.nCells()));
  std::vector<bool> box(points.size());
  for (Foam::label c = 0; c < mesh.nCells(); ++c) points[c] = testPoints(mesh, c, rng);
  // The cells that should take the closed form: hexahedra with quadrilateral faces normal
  // to the axes (the class's own test also asks for flat faces; the meshes here have them).
  for (Foam::label c = 0; c < mesh.nCells(); ++c) {
    bool isBox = mesh.cells()[c].size() == 6;
    for (const Foam::label f : mesh.cells()[c]) {
      const Foam::vector n = mesh.faceAreas()[f] / Foam::mag(mesh.faceAreas()[f]);
      const double largest = std::max({std::abs(n.x()), std::abs(n.y()), std::abs(n.z())});
      if (mesh.faces()[f].size() != 4 || largest < 1 - 1e-12) isBox = false;
    }
    box[c] = isBox;
  }
  const long expectedBoxes = std::count(box.begin(), box.end(), true);

  Result r;
  compare(mesh, U(), ours, points, box, r);
  compare(mesh, eps(), ours, points, box, r);
  checkCellSearch(mesh, points, rng, r);

  // The bound and its reason: see the header.
  constexpr double kTolerance = 1e-12;
  const bool ok = r.maxBox <= kTolerance && r.maxOther <= kTolerance &&
                  ours.boxCells() == expectedBoxes && r.wrongCell == 0;
  std::printf(
      "cellPointCheck: cells=%d boxCells=%d points=%ld boxPoints=%ld outside=%ld maxBox=%.3g "
      "maxOther=%.3g exactOther=%ld/%ld searches=%ld sameCell=%ld faceTies=%ld wrongCell=%ld "
      "status=%s\n",
      mesh.nCells(), ours.boxCells(), r.points, r.boxPoints, ours.outside(), r.maxBox, r.maxOther,
      r.exactOther, r.otherPoints, r.searches, r.sameCell, r.faceTies, r.wrongCell,
      ok ? "ok" : "FAIL");
  if (ours.boxCells() != expectedBoxes)
    std::printf("cellPointCheck: %d cells took the closed form, %ld are boxes\n", ours.boxCells(),
                expectedBoxes);
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char* argv[]) {
  Foam::argList::noParallel();
  Foam::argList::addNote(
      "Checks grainflow's cellPoint weights against OpenFOAM's interpolationCellPoint on the "
      "case's mesh (test coupling.cellpoint_interpolation).");
  Foam::argList args(argc, argv);
  if (!args.checkRootCase()) Foam::FatalError.exit();
  const int status = run(args);
  // argList's destructor would end the process with status 0 (Pstream::exit): exit here.
  Foam::Pstream::exit(status);
  return status;
}
