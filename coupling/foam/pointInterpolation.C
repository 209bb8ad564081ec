#include "coupling/foam/pointInterpolation.H"

#include <algorithm>

#include "FixedList.H"
#include "emptyPolyPatch.H"
#include "globalMeshData.H"
#include "pointConstraints.H"
#include "pointMesh.H"
#include "primitivePatch.H"
#include "surfaceFields.H"
#include "symmetryPlanePointPatch.H"
#include "transform.H"

namespace grainflow::foam {

namespace {

bool reproducedConstraint(const Foam::word& type) {
  return type == "processor" || type == "symmetry" || type == "symmetryPlane" || type == "empty";
}

// volPointInterpolation::pushUntransformedData (private there): every copy of a shared point
// takes the master's value.
template <class T>
void pushMaster(const Foam::polyMesh& mesh, Foam::List<T>& pointData) {
  const Foam::globalMeshData& gmd = mesh.globalData();
  const Foam::labelList& meshPoints = gmd.coupledPatch().meshPoints();
  const Foam::mapDistribute& map = gmd.globalCoPointSlavesMap();
  const Foam::labelListList& slaves = gmd.globalCoPointSlaves();
  Foam::List<T> elems(map.constructSize());
  forAll(meshPoints, i) elems[i] = pointData[meshPoints[i]];
  forAll(slaves, i) {
    for (const Foam::label s : slaves[i]) elems[s] = elems[i];
  }
  map.reverseDistribute(elems.size(), elems, false);
  forAll(meshPoints, i) pointData[meshPoints[i]] = elems[i];
}

// pointConstraints::syncUntransformedData over records: the master combines its copies in
// their order with `combine`, and every copy takes the result.
template <int width, class Combine>
void syncShared(const Foam::polyMesh& mesh, double* points, const Combine& combine) {
  using Record = Foam::FixedList<double, width>;
  const Foam::globalMeshData& gmd = mesh.globalData();
  const Foam::labelList& meshPoints = gmd.coupledPatch().meshPoints();
  const Foam::mapDistribute& map = gmd.globalCoPointSlavesMap();
  const Foam::labelListList& slaves = gmd.globalCoPointSlaves();
  Foam::List<Record> elems(map.constructSize());
  forAll(meshPoints, i) std::copy_n(points + width * meshPoints[i], width, elems[i].begin());
  map.distribute(elems, false);
  forAll(slaves, i) {
    Record& master = elems[i];
    for (const Foam::label s : slaves[i]) combine(master, elems[s]);
    for (const Foam::label s : slaves[i]) elems[s] = master;
  }
  map.reverseDistribute(elems.size(), elems, false);
  forAll(meshPoints, i) std::copy_n(elems[i].begin(), width, points + width * meshPoints[i]);
}

// pushMaster over records.
template <int width>
void pushShared(const Foam::polyMesh& mesh, double* points) {
  using Record = Foam::FixedList<double, width>;
  const Foam::globalMeshData& gmd = mesh.globalData();
  const Foam::labelList& meshPoints = gmd.coupledPatch().meshPoints();
  const Foam::mapDistribute& map = gmd.globalCoPointSlavesMap();
  const Foam::labelListList& slaves = gmd.globalCoPointSlaves();
  Foam::List<Record> elems(map.constructSize());
  forAll(meshPoints, i) std::copy_n(points + width * meshPoints[i], width, elems[i].begin());
  forAll(slaves, i) {
    for (const Foam::label s : slaves[i]) elems[s] = elems[i];
  }
  map.reverseDistribute(elems.size(), elems, false);
  forAll(meshPoints, i) std::copy_n(elems[i].begin(), width, points + width * meshPoints[i]);
}

Foam::vector vectorAt(const double* r) { return Foam::vector(r[0], r[1], r[2]); }
void store(const Foam::vector& v, double* r) {
  r[0] = v.x();
  r[1] = v.y();
  r[2] = v.z();
}

}  // namespace

PointInterpolation::PointInterpolation(const Foam::fvMesh& mesh) : mesh_(mesh) {
  using namespace Foam;
  const polyBoundaryMesh& pbm = mesh.boundaryMesh();
  forAll(pbm, patchi) {
    const word& type = pbm[patchi].type();
    if (polyPatch::constraintType(type) && !reproducedConstraint(type)) {
      unsupported_ = "patch " + pbm[patchi].name() + " is of type " + type;
      break;
    }
  }
  shared_ = Pstream::parRun();
  if (returnReduce(!unsupported_.empty(), orOp<bool>())) {
    if (unsupported_.empty()) unsupported_ = "a patch on another processor is of a type not reproduced";
    return;
  }

  // volPointInterpolation::calcBoundaryAddressing: the proper patch faces and their points.
  const label nInternal = mesh.nInternalFaces();
  const primitivePatch boundary(SubList<face>(mesh.faces(), mesh.nBoundaryFaces(), nInternal),
                                mesh.points());
  const surfaceScalarField& magSf = mesh.magSf();
  std::vector<label> faceIndex(static_cast<std::size_t>(boundary.size()), -1);
  std::vector<char> isPatchPoint(static_cast<std::size_t>(mesh.nPoints()), 0);
  forAll(pbm, patchi) {
    const polyPatch& pp = pbm[patchi];
    if (isA<emptyPolyPatch>(pp) || magSf.boundaryField()[patchi].coupled()) continue;
    label b = pp.start() - nInternal;
    forAll(pp, i) {
      faceIndex[b] = static_cast<label>(faces_.size());
      faces_.push_back({patchi, i});
      for (const label p : boundary[b]) isPatchPoint[p] = 1;
      ++b;
    }
  }

  // makeInternalWeights, makeBoundaryWeights, makeWeights: the same formulas in the same
  // order, so that the normalised weights are OpenFOAM's to the last bit.
  const pointField& points = mesh.points();
  const vectorField& cellCentres = mesh.cellCentres();
  const vectorField& faceCentres = mesh.faceCentres();
  const labelListList& pointCells = mesh.pointCells();
  const labelList& meshPoints = boundary.meshPoints();
  const labelListList& pointFaces = boundary.pointFaces();
  std::vector<label> boundaryPoint(static_cast<std::size_t>(mesh.nPoints()), -1);
  forAll(meshPoints, i) boundaryPoint[meshPoints[i]] = i;

  scalarField sumWeights(mesh.nPoints(), Zero);
  first_.assign(1, 0);
  forAll(points, p) {
    if (!isPatchPoint[p]) {
      for (const label c : pointCells[p]) {
        const scalar w = 1.0 / mag(points[p] - cellCentres[c]);
        source_.push_back(c);
        weight_.push_back(w);
        sumWeights[p] += w;
      }
    }
    first_.push_back(static_cast<label>(source_.size()));
  }
  // The boundary weights in the points' order (the sum above is per point, so this
  // reordering of makeBoundaryWeights' loop does not change any sum).
  std::vector<label> boundaryFirst(1, 0), boundarySource;
  std::vector<double> boundaryWeight;
  forAll(points, p) {
    const label i = boundaryPoint[p];
    if (isPatchPoint[p] && i >= 0) {
      sumWeights[p] = 0.0;
      for (const label f : pointFaces[i]) {
        if (faceIndex[f] < 0) continue;
        const scalar w = 1.0 / mag(points[p] - faceCentres[nInternal + f]);
        boundarySource.push_back(mesh.nCells() + faceIndex[f]);
        boundaryWeight.push_back(w);
        sumWeights[p] += w;
      }
    }
    boundaryFirst.push_back(static_cast<label>(boundarySource.size()));
  }
  pointConstraints::syncUntransformedData(mesh, sumWeights, plusEqOp<scalar>());
  // (addSeparated: nothing on processor patches, the only coupled type here)
  if (shared_) pushMaster(mesh, sumWeights);

  // Merge: a point has either cell sources or boundary sources.
  std::vector<label> first(1, 0), source;
  std::vector<double> weight;
  source.reserve(source_.size() + boundarySource.size());
  weight.reserve(source.capacity());
  forAll(points, p) {
    for (label j = first_[p]; j < first_[p + 1]; ++j) {
      source.push_back(source_[j]);
      weight.push_back(weight_[j] / sumWeights[p]);
    }
    for (label j = boundaryFirst[p]; j < boundaryFirst[p + 1]; ++j) {
      source.push_back(boundarySource[j]);
      weight.push_back(boundaryWeight[j] / sumWeights[p]);
    }
    first.push_back(static_cast<label>(source.size()));
  }
  first_ = std::move(first);
  source_ = std::move(source);
  weight_ = std::move(weight);

  // The point field's constraint patches (pointConstraints::constrain ->
  // correctBoundaryConditions): symmetry by its point normals, symmetryPlane by its normal.
  const pointMesh& pMesh = pointMesh::New(mesh);
  forAll(pMesh.boundary(), patchi) {
    const pointPatch& pp = pMesh.boundary()[patchi];
    const labelList& mp = pp.meshPoints();
    if (pp.type() == "symmetry") {
      const vectorField& nHat = pp.pointNormals();
      forAll(mp, i) symmetry_.push_back({mp[i], tensor(I - 2.0 * sqr(nHat[i]))});
    } else if (pp.type() == "symmetryPlane") {
      const vector nHat = refCast<const symmetryPlanePointPatch>(pp).n();
      const tensor t(I - 2.0 * sqr(nHat));
      forAll(mp, i) symmetry_.push_back({mp[i], t});
    }
  }
  const pointConstraints& pcs = pointConstraints::New(pMesh);
  const labelList& cornerPoints = pcs.patchPatchPointConstraintPoints();
  const tensorField& cornerTensors = pcs.patchPatchPointConstraintTensors();
  forAll(cornerPoints, i) corners_.push_back({cornerPoints[i], cornerTensors[i]});
}

template <int width>
void PointInterpolation::interpolate(const double* sources, const std::vector<int>& vectors,
                                     double* points) const {
  using namespace Foam;
  const std::size_t n = first_.size() - 1;
  // Steps 1 and 2 (interpolateInternalField, interpolateBoundaryField): pf = 0, then
  // pf += w * value, per source in OpenFOAM's order.
  for (std::size_t p = 0; p < n; ++p) {
    double r[width] = {};
    for (label j = first_[p]; j < first_[p + 1]; ++j) {
      const double* s = sources + std::size_t{width} * source_[j];
      const double w = weight_[j];
      for (int k = 0; k < width; ++k) r[k] += w * s[k];
    }
    std::copy_n(r, width, points + std::size_t{width} * p);
  }
  // Step 3: syncUntransformedData(plusEqOp), addSeparated (nothing on processor patches),
  // pushUntransformedData.
  if (shared_) {
    plusShared<width>(points);
    pushShared<width>(mesh_, points);
  }
  // Step 4: the symmetry patches, (v + transform(I - 2 n n, v)) / 2 for each vector; a
  // scalar s becomes (s + s) / 2 = s.
  for (const Transform& s : symmetry_) {
    double* r = points + std::size_t{width} * s.point;
    for (const int o : vectors) {
      const vector v = vectorAt(r + o);
      store((v + transform(s.t, v)) / 2.0, r + o);
    }
  }
  // Step 5: syncUntransformedData(maxMagSqrEqOp), then constrainCorners.
  if (shared_) largestShared<width>(points, vectors);
  for (const Transform& c : corners_) {
    double* r = points + std::size_t{width} * c.point;
    for (const int o : vectors) store(transform(c.t, vectorAt(r + o)), r + o);
  }
}

template <int width>
void PointInterpolation::plusShared(double* points) const {
  syncShared<width>(mesh_, points,
                    [](Foam::FixedList<double, width>& x, const Foam::FixedList<double, width>& y) {
                      for (int k = 0; k < width; ++k) x[k] += y[k];
                    });
}

template <int width>
void PointInterpolation::largestShared(double* points, const std::vector<int>& vectors) const {
  // maxMagSqrEqOp per field: x = magSqr(x) >= magSqr(y) ? x : y, for each vector (by its
  // magnitude) and each scalar.
  std::vector<bool> isScalar(width, true);
  for (const int o : vectors) isScalar[o] = isScalar[o + 1] = isScalar[o + 2] = false;
  syncShared<width>(
      mesh_, points,
      [&](Foam::FixedList<double, width>& x, const Foam::FixedList<double, width>& y) {
        for (const int o : vectors) {
          const Foam::vector a(x[o], x[o + 1], x[o + 2]), b(y[o], y[o + 1], y[o + 2]);
          if (!(Foam::magSqr(a) >= Foam::magSqr(b))) store(b, &x[o]);
        }
        for (int k = 0; k < width; ++k)
          if (isScalar[k] && !(Foam::magSqr(x[k]) >= Foam::magSqr(y[k]))) x[k] = y[k];
      });
}

std::size_t PointInterpolation::bytes() const {
  return faces_.size() * sizeof(Face) + first_.size() * sizeof(Foam::label) +
         source_.size() * sizeof(Foam::label) + weight_.size() * sizeof(double) +
         (symmetry_.size() + corners_.size()) * sizeof(Transform);
}

template void PointInterpolation::interpolate<10>(const double*, const std::vector<int>&,
                                                  double*) const;
template void PointInterpolation::interpolate<13>(const double*, const std::vector<int>&,
                                                  double*) const;

}  // namespace grainflow::foam
