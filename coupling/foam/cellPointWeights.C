#include <cmath>

#include "cellPointWeight.H"
#include "coupling/foam/cellPointWeights.H"
#include "tetIndices.H"

namespace grainflow::foam {
namespace {

// Flatness of a box face: its points off the face's plane by at most this, relative to the
// cell's diagonal (block meshes: round-off, ~1e-16).
constexpr double kFlat = 1e-12;

}  // namespace

CellPointWeights::CellPointWeights(const Foam::polyMesh& mesh)
    : mesh_(mesh), tol_(Foam::cellPointWeight::tol) {
  const Foam::label n = mesh.nCells();
  (void)mesh.tetBasePtIs();  // built once by the mesh, as interpolationCellPoint does
  box_.assign(static_cast<std::size_t>(n), -1);
  boxes_.reserve(static_cast<std::size_t>(n));
  first_.assign(static_cast<std::size_t>(n) + 1, 0);
  for (Foam::label c = 0; c < n; ++c) {
    Box box;
    if (prepareBox(c, box)) {
      box_[c] = static_cast<Foam::label>(boxes_.size());
      boxes_.push_back(box);
    } else {
      prepareTets(c);
    }
    first_[c + 1] = static_cast<Foam::label>(tets_.size());
  }
}

bool CellPointWeights::prepareBox(Foam::label celli, Box& box) const {
  // A box: six quadrilateral faces, each flat and normal to an axis, one on every side. Its
  // centroid (OpenFOAM's cell centre, the tetrahedra's common vertex) is the box's centre.
  using namespace Foam;
  const cell& c = mesh_.cells()[celli];
  if (c.size() != 6) return false;
  const pointField& points = mesh_.points();
  const faceList& faces = mesh_.faces();
  const boundBox bb(points, c.labels(faces), false);
  const double size = mag(bb.span());
  box.centre = mesh_.cellCentres()[celli];
  for (int ax = 0; ax < 3; ++ax) box.halfWidthInverse[ax] = 2 / bb.span()[ax];
  std::array<bool, 6> seen{};
  for (const label facei : c) {
    const face& f = faces[facei];
    if (f.size() != 4) return false;
    vector n = mesh_.faceAreas()[facei];
    if (mesh_.faceOwner()[facei] != celli) n = -n;  // outward
    int a = 0;
    for (int ax = 1; ax < 3; ++ax)
      if (std::abs(n[ax]) > std::abs(n[a])) a = ax;
    const int side = 2 * a + (n[a] > 0 ? 1 : 0);
    if (seen[side]) return false;
    seen[side] = true;
    const double plane = n[a] > 0 ? bb.max()[a] : bb.min()[a];
    const int b = (a + 1) % 3, cc = (a + 2) % 3;
    std::array<bool, 4> filled{};
    std::array<int, 4> quadrant{};
    for (label k = 0; k < 4; ++k) {
      const point& p = points[f[k]];
      if (std::abs(p[a] - plane) > kFlat * size) return false;
      // A corner of the face: at the box's bounds on both in-plane axes.
      int q = 0;
      for (const int ax : {b, cc}) {
        const bool hi = std::abs(p[ax] - bb.max()[ax]) <= kFlat * size;
        const bool lo = std::abs(p[ax] - bb.min()[ax]) <= kFlat * size;
        if (hi == lo) return false;
        if (hi) q += ax == b ? 1 : 2;
      }
      if (filled[q]) return false;
      filled[q] = true;
      quadrant[k] = q;
      box.corner[side][q] = f[k];
    }
    // The face's triangles (base, base + 1, base + 2) and (base, base + 2, base + 3) share
    // the diagonal from the base point (tetIndices::faceTriIs: base 0 when none is valid).
    label base = mesh_.tetBasePtIs()[facei];
    if (base < 0) base = 0;
    const int qBase = quadrant[base % 4];
    box.diagonal[side] = (qBase == 0 || qBase == 3) ? 0 : 1;
  }
  return true;
}

void CellPointWeights::prepareTets(Foam::label celli) {
  using namespace Foam;
  const pointField& points = mesh_.points();
  const vector& a = mesh_.cellCentres()[celli];
  const scalar volume = mesh_.cellVolumes()[celli];
  // polyMeshTetDecomposition::cellTetIndices: the cell's faces in order, triangles 1 ..
  // n - 2 of each.
  for (const label facei : mesh_.cells()[celli]) {
    const face& f = mesh_.faces()[facei];
    for (label k = 1; k < f.size() - 1; ++k) {
      const triFace tri = tetIndices(celli, facei, k).faceTriIs(mesh_);
      const vector& b = points[tri[0]];
      const vector& c = points[tri[1]];
      const vector& d = points[tri[2]];
      // tetrahedron::pointToBarycentric: columns a - d, b - d, c - d.
      const vector e0(a - d), e1(b - d), e2(c - d);
      const tensor t(e0.x(), e1.x(), e2.x(), e0.y(), e1.y(), e2.y(), e0.z(), e1.z(), e2.z());
      const scalar detT = det(t);
      Tet tet;
      // cellPointWeight::findTetrahedron passes over tetrahedra with |det / V| <= tol in its
      // search: they never take a point.
      tet.usable = mag(detT / volume) > tol_;
      tet.degenerate = mag(detT) < SMALL;
      tet.inverse = tet.degenerate ? tensor::zero : inv(t, detT);
      tet.d = d;
      tet.point = {tri[0], tri[1], tri[2]};
      tets_.push_back(tet);
    }
  }
}

std::size_t CellPointWeights::bytes() const {
  return box_.capacity() * sizeof(Foam::label) + boxes_.capacity() * sizeof(Box) +
         first_.capacity() * sizeof(Foam::label) + tets_.capacity() * sizeof(Tet);
}

CellPointWeight CellPointWeights::orderedSearch(const Foam::point& x, Foam::label cell) const {
  CellPointWeight s;
  s.cell = cell;
  for (Foam::label k = first_[cell]; k < first_[cell + 1]; ++k) {
    const Tet& tet = tets_[k];
    if (!tet.usable) continue;
    double* w = s.w.data();
    if (tet.degenerate) {
      w[0] = w[1] = w[2] = w[3] = 0.25;
    } else {
      // tetrahedron::pointToBarycentric: res = inv(t, detT) & (pt - d), (res, 1 - sum res).
      const Foam::vector res = tet.inverse & (x - tet.d);
      w[0] = res.x();
      w[1] = res.y();
      w[2] = res.z();
      w[3] = 1 - Foam::cmptSum(res);
    }
    // cellPointWeight::findTetrahedron's test, term for term.
    if (w[0] + tol_ > 0 && w[1] + tol_ > 0 && w[2] + tol_ > 0 && w[0] + w[1] + w[2] < 1 + tol_) {
      s.point = tet.point;
      return s;
    }
  }
  return nearest(x, cell);
}

CellPointWeight CellPointWeights::nearest(const Foam::point& x, Foam::label cell) const {
  // Outside the cell: OpenFOAM's nearest-tetrahedron rule, by OpenFOAM (rare: not per step).
  ++outside_;
  const Foam::cellPointWeight foam(mesh_, x, cell);
  CellPointWeight s;
  s.cell = cell;
  for (int j = 0; j < 4; ++j) s.w[j] = foam.weights()[j];
  for (int j = 0; j < 3; ++j) s.point[j] = foam.faceVertices()[j];
  return s;
}

}  // namespace grainflow::foam
