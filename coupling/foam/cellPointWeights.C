#include <cmath>

#include "cellPointWeight.H"
#include "coupling/foam/cellPointWeights.H"
#include "tetIndices.H"

namespace grainflow::foam {
namespace {

// Margin of the closed-form search on box grids (see the header): a point whose barycentric
// coordinates in a tetrahedron all exceed it is that far inside, relative to the
// tetrahedron's heights (a few mm here), i.e. ~1e-12 m for mm cells: six orders of magnitude
// above OpenFOAM's acceptance tolerance of 1e-15 and far above the round-off of the
// coordinates (~1e-16), so no neighbouring tetrahedron can accept the point.
constexpr double kInsideMargin = 1e-9;

}  // namespace

CellPointWeights::CellPointWeights(const Foam::polyMesh& mesh)
    : mesh_(mesh), tol_(Foam::cellPointWeight::tol) {
  using namespace Foam;
  const cellList& cells = mesh.cells();
  const faceList& faces = mesh.faces();
  const pointField& points = mesh.points();
  const vectorField& centres = mesh.cellCentres();
  const scalarField& volumes = mesh.cellVolumes();
  (void)mesh.tetBasePtIs();  // built once by the mesh, as interpolationCellPoint does

  label count = 0;
  for (const cell& c : cells)
    for (const label f : c) count += faces[f].size() - 2;
  first_.assign(cells.size() + 1, 0);
  tets_.reserve(static_cast<std::size_t>(count));
  sideTet_.assign(cells.size(), std::array<label, 6>{-1, -1, -1, -1, -1, -1});
  halfWidthInverse_.assign(cells.size(), vector::zero);

  forAll(cells, celli) {
    // polyMeshTetDecomposition::cellTetIndices: the cell's faces in order, triangles 1 ..
    // n - 2 of each.
    for (const label facei : cells[celli]) {
      const face& f = faces[facei];
      for (label k = 1; k < f.size() - 1; ++k) {
        const tetIndices ti(celli, facei, k);
        const triFace tri = ti.faceTriIs(mesh);
        const vector& a = centres[celli];
        const vector& b = points[tri[0]];
        const vector& c = points[tri[1]];
        const vector& d = points[tri[2]];
        // tetrahedron::pointToBarycentric: columns a - d, b - d, c - d.
        const vector e0(a - d), e1(b - d), e2(c - d);
        const tensor t(e0.x(), e1.x(), e2.x(), e0.y(), e1.y(), e2.y(), e0.z(), e1.z(), e2.z());
        const scalar detT = det(t);
        Tet tet;
        // cellPointWeight::findTetrahedron passes over tetrahedra with |det / V| <= tol: they
        // never take a point in its first pass.
        tet.usable = mag(detT / volumes[celli]) > tol_;
        tet.degenerate = mag(detT) < SMALL;
        tet.inverse = tet.degenerate ? tensor::zero : inv(t, detT);
        tet.d = d;
        tet.point = {tri[0], tri[1], tri[2]};
        tets_.push_back(tet);
      }
    }
    first_[celli + 1] = static_cast<label>(tets_.size());
    const std::array<label, 6> sides = boxSides(celli);
    if (sides[0] < 0) continue;
    const boundBox bb(points, cells[celli].labels(faces), false);
    const vector span = bb.max() - bb.min();
    for (int ax = 0; ax < 3; ++ax) halfWidthInverse_[celli][ax] = 2 / span[ax];
    sideTet_[celli] = sides;
  }
}

std::array<Foam::label, 6> CellPointWeights::boxSides(Foam::label celli) const {
  // A box: six quadrilateral faces, each flat and normal to an axis, one on every side; every
  // one of its tetrahedra usable and not degenerate. Then the cell's tetrahedra partition it
  // (a convex cell with planar faces, its centroid inside) and the closed form applies.
  using namespace Foam;
  const std::array<label, 6> none{-1, -1, -1, -1, -1, -1};
  const cell& c = mesh_.cells()[celli];
  if (c.size() != 6) return none;
  const pointField& points = mesh_.points();
  const boundBox bb(points, c.labels(mesh_.faces()), false);
  const double size = mag(bb.span());
  std::array<label, 6> sides = none;
  label offset = 0;
  for (const label facei : c) {
    const face& f = mesh_.faces()[facei];
    if (f.size() != 4) return none;
    vector n = mesh_.faceAreas()[facei];
    if (mesh_.faceOwner()[facei] != celli) n = -n;  // outward
    int axis = 0;
    for (int ax = 1; ax < 3; ++ax)
      if (std::abs(n[ax]) > std::abs(n[axis])) axis = ax;
    const int side = 2 * axis + (n[axis] > 0 ? 1 : 0);
    const double plane = n[axis] > 0 ? bb.max()[axis] : bb.min()[axis];
    for (const label p : f)
      if (std::abs(points[p][axis] - plane) > 1e-12 * size) return none;
    if (sides[side] != -1) return none;
    sides[side] = offset;
    for (label k = offset; k < offset + 2; ++k) {
      const Tet& t = tets_[first_[celli] + k];
      if (!t.usable || t.degenerate) return none;
    }
    offset += 2;
  }
  return sides;
}

Foam::label CellPointWeights::boxCells() const {
  Foam::label n = 0;
  for (const auto& sides : sideTet_) n += sides[0] >= 0 ? 1 : 0;
  return n;
}

std::size_t CellPointWeights::bytes() const {
  return tets_.capacity() * sizeof(Tet) + first_.capacity() * sizeof(Foam::label) +
         sideTet_.capacity() * sizeof(sideTet_[0]) +
         halfWidthInverse_.capacity() * sizeof(Foam::vector);
}

void CellPointWeights::barycentric(const Tet& t, const Foam::point& x, double w[4]) {
  if (t.degenerate) {
    w[0] = w[1] = w[2] = w[3] = 0.25;
    return;
  }
  // vector res = inv(t, detT) & (pt - d); bary = (res, 1 - cmptSum(res)).
  const Foam::vector res = t.inverse & (x - t.d);
  w[0] = res.x();
  w[1] = res.y();
  w[2] = res.z();
  w[3] = 1 - Foam::cmptSum(res);
}

bool CellPointWeights::accepts(const double w[4]) const {
  // cellPointWeight::findTetrahedron's test, term for term.
  return w[0] + tol_ > 0 && w[1] + tol_ > 0 && w[2] + tol_ > 0 && w[0] + w[1] + w[2] < 1 + tol_;
}

CellPointWeight CellPointWeights::at(const Foam::point& x, Foam::label cell) const {
  ++calls_;
  if (sideTet_[cell][0] >= 0) {
    const Foam::vector& centre = mesh_.cellCentres()[cell];
    const Foam::vector& hInv = halfWidthInverse_[cell];
    int axis = 0;
    double best = -1, sign = 0;
    for (int ax = 0; ax < 3; ++ax) {
      const double s = (x[ax] - centre[ax]) * hInv[ax];
      if (std::abs(s) > best) {
        best = std::abs(s);
        axis = ax;
        sign = s;
      }
    }
    const Foam::label k0 = first_[cell] + sideTet_[cell][2 * axis + (sign > 0 ? 1 : 0)];
    for (Foam::label k = k0; k < k0 + 2; ++k) {
      CellPointWeight s;
      barycentric(tets_[k], x, s.w.data());
      if (s.w[0] > kInsideMargin && s.w[1] > kInsideMargin && s.w[2] > kInsideMargin &&
          s.w[3] > kInsideMargin) {
        s.cell = cell;
        s.point = tets_[k].point;
        return s;
      }
    }
    ++ordered_;
  }
  return orderedSearch(x, cell);
}

CellPointWeight CellPointWeights::orderedSearch(const Foam::point& x, Foam::label cell) const {
  CellPointWeight s;
  s.cell = cell;
  for (Foam::label k = first_[cell]; k < first_[cell + 1]; ++k) {
    if (!tets_[k].usable) continue;
    barycentric(tets_[k], x, s.w.data());
    if (accepts(s.w.data())) {
      s.point = tets_[k].point;
      return s;
    }
  }
  // Outside every tetrahedron of the cell: OpenFOAM's nearest-tetrahedron rule, by OpenFOAM.
  ++outside_;
  const Foam::cellPointWeight foam(mesh_, x, cell);
  for (int j = 0; j < 4; ++j) s.w[j] = foam.weights()[j];
  for (int j = 0; j < 3; ++j) s.point[j] = foam.faceVertices()[j];
  return s;
}

}  // namespace grainflow::foam
