// superficialVelocityInlet: U_b = U_s(t) / eps_b (see the header for the physics and usage).
#include "addToRunTimeSelectionTable.H"
#include "superficialVelocityInletFvPatchVectorField.H"
#include "volFields.H"

namespace Foam {

namespace {

autoPtr<Function1<vector>> readSuperficialVelocity(const fvPatch& p,
                                                   const DimensionedField<vector, volMesh>& iF,
                                                   const dictionary& dict) {
  if (!dict.found("superficialVelocity", keyType::LITERAL)) {
    FatalIOErrorInFunction(dict)
        << "patch " << p.name() << " of field " << iF.name()
        << ": type superficialVelocityInlet needs the entry 'superficialVelocity', the "
           "superficial velocity U_s [m/s] as a vector Function1 of time, e.g."
        << nl << "    superficialVelocity constant (0 0 0.5);" << nl << "or a table for steps, e.g."
        << nl << "    superficialVelocity table ((0 (0 0 0.2)) (10 (0 0 0.2)) (10.001 (0 0 0.4)));"
        << exit(FatalIOError);
  }
  return Function1<vector>::New("superficialVelocity", dict);
}

}  // namespace

superficialVelocityInletFvPatchVectorField::superficialVelocityInletFvPatchVectorField(
    const fvPatch& p, const DimensionedField<vector, volMesh>& iF)
    : fixedValueFvPatchVectorField(p, iF),
      superficialVelocity_(),
      voidFractionName_(defaultVoidFractionName),
      minVoidFraction_(defaultMinVoidFraction),
      constructed_(true),
      fallbackWarned_(false),
      clampWarned_(false) {}

superficialVelocityInletFvPatchVectorField::superficialVelocityInletFvPatchVectorField(
    const fvPatch& p, const DimensionedField<vector, volMesh>& iF, const dictionary& dict)
    : fixedValueFvPatchVectorField(p, iF, dict, false),
      superficialVelocity_(readSuperficialVelocity(p, iF, dict)),
      voidFractionName_(dict.getOrDefault<word>("voidFraction", defaultVoidFractionName)),
      minVoidFraction_(dict.getOrDefault<scalar>("minVoidFraction", defaultMinVoidFraction)),
      constructed_(false),
      fallbackWarned_(false),
      clampWarned_(false) {
  if (!(minVoidFraction_ > 0 && minVoidFraction_ <= 1)) {
    FatalIOErrorInFunction(dict)
        << "patch " << p.name() << " of field " << iF.name() << ": minVoidFraction "
        << minVoidFraction_
        << " is outside (0, 1]. It only guards the division U_s/eps_b against eps_b = 0; "
           "remove the entry to use the default "
        << defaultMinVoidFraction << exit(FatalIOError);
  }

  if (dict.found("value")) {
    fvPatchVectorField::operator=(vectorField("value", dict, p.size()));
  } else {
    // Usually before the void fraction exists, hence with the eps_b = 1 fallback.
    evaluate(Pstream::commsTypes::blocking);
  }
  constructed_ = true;
}

superficialVelocityInletFvPatchVectorField::superficialVelocityInletFvPatchVectorField(
    const superficialVelocityInletFvPatchVectorField& ptf, const fvPatch& p,
    const DimensionedField<vector, volMesh>& iF, const fvPatchFieldMapper& mapper)
    : fixedValueFvPatchVectorField(ptf, p, iF, mapper),
      superficialVelocity_(ptf.superficialVelocity_.clone()),
      voidFractionName_(ptf.voidFractionName_),
      minVoidFraction_(ptf.minVoidFraction_),
      constructed_(true),
      fallbackWarned_(ptf.fallbackWarned_),
      clampWarned_(ptf.clampWarned_) {}

superficialVelocityInletFvPatchVectorField::superficialVelocityInletFvPatchVectorField(
    const superficialVelocityInletFvPatchVectorField& ptf)
    : fixedValueFvPatchVectorField(ptf),
      superficialVelocity_(ptf.superficialVelocity_.clone()),
      voidFractionName_(ptf.voidFractionName_),
      minVoidFraction_(ptf.minVoidFraction_),
      constructed_(true),
      fallbackWarned_(ptf.fallbackWarned_),
      clampWarned_(ptf.clampWarned_) {}

superficialVelocityInletFvPatchVectorField::superficialVelocityInletFvPatchVectorField(
    const superficialVelocityInletFvPatchVectorField& ptf,
    const DimensionedField<vector, volMesh>& iF)
    : fixedValueFvPatchVectorField(ptf, iF),
      superficialVelocity_(ptf.superficialVelocity_.clone()),
      voidFractionName_(ptf.voidFractionName_),
      minVoidFraction_(ptf.minVoidFraction_),
      constructed_(true),
      fallbackWarned_(ptf.fallbackWarned_),
      clampWarned_(ptf.clampWarned_) {}

void superficialVelocityInletFvPatchVectorField::updateCoeffs() {
  if (updated()) {
    return;
  }
  if (!superficialVelocity_.valid()) {
    FatalErrorInFunction << "patch " << patch().name() << " of field " << internalField().name()
                         << ": superficialVelocityInlet was built without a dictionary and has "
                            "no superficialVelocity; construct it from a field file entry."
                         << exit(FatalError);
  }

  const vector Us = superficialVelocity_->value(db().time().timeOutputValue());
  vectorField Ub(patch().size());

  if (db().foundObject<volScalarField>(voidFractionName_)) {
    const fvPatchScalarField& epsb =
        patch().lookupPatchField<volScalarField, scalar>(voidFractionName_);
    label nClamped = 0;
    scalar epsMin = GREAT;
    forAll(Ub, facei) {
      epsMin = min(epsMin, epsb[facei]);
      scalar eps = epsb[facei];
      if (eps < minVoidFraction_) {
        eps = minVoidFraction_;
        ++nClamped;
      }
      Ub[facei] = Us / eps;
    }
    // All processors hold every global patch (empty where absent) and evaluate it together,
    // as flowRateInletVelocity's gSum relies on; the flag stays equal across processors.
    if (!clampWarned_) {
      const label nClampedAll = returnReduce(nClamped, sumOp<label>());
      if (nClampedAll > 0) {
        const scalar epsMinAll = returnReduce(epsMin, minOp<scalar>());
        WarningInFunction << "patch " << patch().name() << " of field " << internalField().name()
                          << ", time " << db().time().timeName() << ": " << nClampedAll
                          << " face(s) have void fraction '" << voidFractionName_
                          << "' below minVoidFraction " << minVoidFraction_ << " (lowest "
                          << epsMinAll
                          << "); U_s/minVoidFraction is used there, so the inlet flux is not "
                             "exactly U_s.S. The bed fills the inlet: check the particle walls "
                             "near this patch. (Reported once.)"
                          << endl;
        clampWarned_ = true;
      }
    }
  } else {
    if (constructed_ && !fallbackWarned_) {
      WarningInFunction << "patch " << patch().name() << " of field " << internalField().name()
                        << ", time " << db().time().timeName() << ": no volScalarField '"
                        << voidFractionName_
                        << "' is registered, so the void fraction is taken as 1 (U_b = U_s). "
                           "Expected in utilities that read U alone; in a CFD-DEM solver set "
                           "'voidFraction' to the name of its void-fraction field. "
                           "(Reported once.)"
                        << endl;
      fallbackWarned_ = true;
    }
    Ub = Us;
  }

  fvPatchVectorField::operator==(Ub);
  fixedValueFvPatchVectorField::updateCoeffs();
}

void superficialVelocityInletFvPatchVectorField::write(Ostream& os) const {
  fvPatchVectorField::write(os);
  if (superficialVelocity_.valid()) {
    superficialVelocity_->writeData(os);
  }
  os.writeEntry("voidFraction", voidFractionName_);
  os.writeEntry("minVoidFraction", minVoidFraction_);
  writeEntry("value", os);
}

makePatchTypeField(fvPatchVectorField, superficialVelocityInletFvPatchVectorField)

}  // namespace Foam
