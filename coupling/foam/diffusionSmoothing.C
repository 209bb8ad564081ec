#include <cmath>

#include "coupling/foam/diffusionSmoothing.H"

namespace grainflow::foam {

DiffusionSmoothing::DiffusionSmoothing(const Foam::fvMesh& mesh, double bandwidth, double maxSteps)
    : mesh_(mesh), bandwidth_(bandwidth) {
  using namespace Foam;
  // |S_f| / |d_f| per face: deltaCoeffs is 1 / |d| between the two cell centres (across a
  // coupled patch, to the neighbour's centre).
  const surfaceScalarField& delta = mesh.deltaCoeffs();
  const surfaceScalarField& magSf = mesh.magSf();
  internalCoeff_ = magSf.primitiveField() * delta.primitiveField();
  patchCoeff_.setSize(mesh.boundary().size());
  scalarField rate(mesh.nCells(), 0.0);  // sum_f |S|/|d| / V per cell
  const labelUList& owner = mesh.owner();
  const labelUList& neighbour = mesh.neighbour();
  forAll(internalCoeff_, f) {
    rate[owner[f]] += internalCoeff_[f];
    rate[neighbour[f]] += internalCoeff_[f];
  }
  forAll(mesh.boundary(), patch) {
    const fvPatch& fp = mesh.boundary()[patch];
    if (!fp.coupled()) continue;
    const scalarField& area = magSf.boundaryField()[patch];
    const scalarField& inverseDistance = delta.boundaryField()[patch];
    patchCoeff_[patch] = area * inverseDistance;
    const labelUList& cells = fp.faceCells();
    forAll(cells, i) rate[cells[i]] += patchCoeff_[patch][i];
  }
  rV_ = 1.0 / mesh.V().field();
  rate *= rV_;
  const double maxRate = gMax(rate);
  // Pseudo-time T = b^2 / 4: full steps of the largest size 1 / (2 maxRate) and one last step
  // of the remainder. (The operator is then a continuous function of b: on a uniform mesh
  // (1 - Lambda/12)^(k-1) (1 - r Lambda) in cell units, which the lattice self-disturbance
  // tables with diffusionBandwidth assume; docs/models/undisturbed-velocity.md.)
  const double T = 0.25 * bandwidth * bandwidth;
  const double full = 0.5 / maxRate;
  // Counted in double: b^2 / (4 full) exceeds an int for bandwidths far beyond the mesh.
  neededSteps_ = std::max(1.0, std::ceil(T / full - 1e-9));
  maxBandwidth_ = 2 * std::sqrt(maxSteps * full);
  if (!(neededSteps_ <= maxSteps)) return;
  steps_ = static_cast<int>(neededSteps_);
  const double dtau = std::min(T, full);
  lastScale_ = steps_ > 1 ? (T - (steps_ - 1) * full) / full : 1.0;
  stepRate_ = dtau * maxRate;
  internalCoeff_ *= dtau;
  forAll(patchCoeff_, patch) patchCoeff_[patch] *= dtau;
}

template <class Type>
void DiffusionSmoothing::smooth(
    Foam::GeometricField<Type, Foam::fvPatchField, Foam::volMesh>& field) const {
  using namespace Foam;
  const labelUList& owner = mesh_.owner();
  const labelUList& neighbour = mesh_.neighbour();
  Field<Type>& phi = field.primitiveFieldRef();
  Field<Type> change(phi.size());
  for (int step = 0; step < steps_; ++step) {
    change = Zero;
    forAll(internalCoeff_, f) {
      const Type flux = internalCoeff_[f] * (phi[neighbour[f]] - phi[owner[f]]);
      change[owner[f]] += flux;
      change[neighbour[f]] -= flux;
    }
    // Coupled patches: the neighbour's cell values (processor exchange, cyclic mapping).
    field.correctBoundaryConditions();
    const auto& boundary = field.boundaryField();
    forAll(boundary, patch) {
      if (!boundary[patch].coupled()) continue;
      const scalarField& c = patchCoeff_[patch];
      const tmp<Field<Type>> other = boundary[patch].patchNeighbourField();
      const labelUList& cells = mesh_.boundary()[patch].faceCells();
      forAll(cells, i) change[cells[i]] += c[i] * (other()[i] - phi[cells[i]]);
    }
    if (step + 1 < steps_ || lastScale_ == 1.0)
      forAll(phi, cell) phi[cell] += rV_[cell] * change[cell];
    else
      forAll(phi, cell) phi[cell] += lastScale_ * rV_[cell] * change[cell];
  }
  field.correctBoundaryConditions();
}

void DiffusionSmoothing::apply(Foam::volScalarField& field) const { smooth(field); }
void DiffusionSmoothing::apply(Foam::volVectorField& field) const { smooth(field); }

}  // namespace grainflow::foam
