// grainFoam: incompressible volume-averaged Navier–Stokes (VANS) for unresolved CFD-DEM,
// PIMPLE, coupled to the grainflow DEM through grainflow::foam::ParticleCoupling.
//
// U is the interstitial fluid velocity, phi the superficial volumetric flux (eps U)_f.S,
// p the kinematic pressure WITHOUT its hydrostatic part (so gravity does not appear: the
// particles get Archimedes' buoyancy as a listed force). Per unit fluid density:
//
//   continuity   d(eps)/dt + div(eps U) = 0          (d(eps)/dt switchable)
//   momentum     d(eps U)/dt + div(phi U) - div(eps_nu nu grad U)
//                   = - c grad p - Ksl/rho (U - Us) + f/rho
//   model A: c = eps, eps_nu = eps;  model B: c = 1, eps_nu = 1   (DESIGN.md §4;
//   Zhou, Kuang, Chu & Yu 2010, J. Fluid Mech. 661:482).
//
// Gravity is absent from both models: in model A, -eps grad(P) + eps rho g = -eps grad(p)
// for P = p + rho g.x; in model B the remaining -(1-eps) rho g is cancelled exactly by the
// particles' buoyancy returned through the exchange, so neither is applied.
// With couplingProperties meanPressureGradient suspensionWeight (a box periodic along g),
// the pressure gradient is grad p + G/rho with a uniform G [Pa/m] carrying the particles'
// buoyant weight (ParticleCoupling::meanPressureGradient): periodic p cannot hold a mean
// slope, so without G nothing would stop the suspension from falling. G is a cell source
// -c G/rho of the momentum equation (in H, hence in the flux), whose volume integral is
// exactly the force the particles' weight needs; the particles sample grad p + G.
// Ksl = sum K / V_cell goes on the matrix diagonal (implicit), Ksl Us = sum K v / V_cell
// and f (explicit forces the model returns to the fluid) are explicit sources.
// Pressure–velocity coupling: U = HbyA - rAU c grad p inserted into continuity gives
//   laplacian(eps_f c_f rAU_f, p) = div(eps_f phiHbyA) + d(eps)/dt.
// With couplingProperties facePressure dragSeries the cell gradient of p in the predictor and
// in the corrected U = HbyA - rAU c grad p is ParticleCoupling::seriesGradient (face pressures
// of half cells crossed in series with their drag resistances); otherwise Gauss linear and
// U = HbyA - reconstruct(rAU_f c_f snGrad p) (coupling/foam/fluxReconstruction.H, not
// fvc::reconstruct, which v1912 compiles wrong).
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "coupling/floating_point_traps.hpp"
#include "coupling/foam/fluxReconstruction.H"
#include "coupling/foam/particleCoupling.H"
#include "coupling/written_files.hpp"
#include "dem/core/suggestion.hpp"
#include "dem/engine/stop_signals.hpp"
#include "fileOperation.H"
#include "fixedFluxPressureFvPatchScalarField.H"
#include "fvCFD.H"
#include "pimpleControl.H"

namespace {

// OpenFOAM traps floating-point exceptions (FOAM_SIGFPE): a linear solve that diverges dies in
// its smoother with a stack trace and no word on why. The fluid's solves and updates run with
// the traps off instead (grainflow::FloatingPointTrapsOff), and their results are checked
// (stopIfDiverged): a non-finite U, p or T stops the run with what the coupling did to the
// fluid in that step and what changes it.
using TrapsOff = grainflow::FloatingPointTrapsOff;

// Collective: whether any rank has a cell where `bad(cell)` holds; `at` is then the centre of
// the first such cell on the lowest such rank.
template <class Bad>
bool anyCell(const Foam::fvMesh& mesh, const Bad& bad, Foam::vector& at) {
  using namespace Foam;
  label badCell = -1;
  forAll(mesh.C(), i) {
    if (bad(i)) {
      badCell = i;
      break;
    }
  }
  const label me = Pstream::myProcNo(), none = Pstream::nProcs();
  const label badRank = returnReduce(badCell >= 0 ? me : none, minOp<label>());
  if (badRank == none) return false;
  at = returnReduce(me == badRank ? mesh.C()[badCell] : vector::zero, sumOp<vector>());
  return true;
}

// " at t = 0.003608 s (time index 35): <what> is not finite, first in the cell at (x y z) m"
std::string notFinite(const Foam::fvMesh& mesh, const char* what, const Foam::vector& at,
                      const char* is = "is not finite") {
  std::ostringstream m;
  m.precision(4);
  m << " at t = " << mesh.time().value() << " s (time index " << mesh.time().timeIndex()
    << "): " << what << " " << is << ", first in the cell at (" << at.x() << " " << at.y() << " "
    << at.z() << ") m";
  return m.str();
}

// Collective: stops the run (FatalError on every rank) when U or p holds a non-finite value
// after `stage`, with the fluid's state in the step (ParticleCoupling::fluidState: the largest
// change of the void fraction in one cell, the speed and Courant number before the step) and
// the coupling settings that smooth such jumps (jumpRemedies).
void stopIfDiverged(const char* stage, const Foam::volVectorField& U, const Foam::volScalarField& p,
                    const grainflow::foam::ParticleCoupling& particles) {
  using namespace Foam;
  const auto finite = [](const vector& v) {
    return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
  };
  vector at;
  if (!anyCell(
          U.mesh(), [&](label i) { return !finite(U[i]) || !std::isfinite(p[i]); }, at))
    return;
  const grainflow::foam::ParticleCoupling::FluidState state = particles.fluidState(true);
  std::ostringstream m;
  m << "grainFoam: error: the fluid diverged in " << stage << notFinite(U.mesh(), "U or p", at)
    << ". " << state.text.c_str();
  if (state.courant <= 1 || state.jump > 0.25)
    m << " Particles as large as the cells move their whole volume from one cell to the next "
         "as they cross a face, and continuity turns that change of eps into div(eps U): a "
         "jump drives the velocity beyond what the step carries.";
  m << " What changes it: " << particles.remedies(state).c_str();
  FatalErrorInFunction << m.str().c_str() << exit(FatalError);
}

// Collective: stops the run when the fluid temperature holds a non-finite value after its
// equation. U and p are finite by then (checked above), so the equation's coefficients come
// from a finite flux and the particles' exchange: the check turns what would be NaN handed to
// every particle's temperature into a stop that says where.
void stopIfTemperatureDiverged(const Foam::volScalarField& T,
                               const grainflow::foam::ParticleCoupling& particles,
                               const Foam::word& startTime) {
  using namespace Foam;
  vector at;
  if (!anyCell(
          T.mesh(), [&](label i) { return !std::isfinite(T[i]) || !(T[i] > 0); }, at))
    return;
  std::ostringstream m;
  m << "grainFoam: error: the fluid temperature diverged in the energy equation"
    << notFinite(T.mesh(), "T", at, "is not finite or not above 0 K")
    << ", while U and p are finite. " << particles.fluidState(true).text.c_str()
    << " The equation's sources are the flux and the particles' heat exchange in each cell "
       "(heat response and heat source, constant/transportProperties: Cp, kappa); check "
       "the fluid's starting T ("
    << startTime.c_str() << "/T) and the particles' temperatures in the scene.";
  FatalErrorInFunction << m.str().c_str() << exit(FatalError);
}

// Collective: a starting fluid temperature that is not a positive, finite number of kelvin
// (the scene's temperatures must be > 0 K too) stops the run before the first step, naming
// the file, the internal field or patch, and where. A T <= 0 ran to the end: the energy
// equation is linear in T, and nothing in it is bounded below.
void checkStartingTemperature(const Foam::volScalarField& T, const Foam::word& startTime) {
  using namespace Foam;
  const auto bad = [](scalar t) { return !(t > 0) || !std::isfinite(t); };
  scalar value = 1;
  vector where = Zero;
  label part = -2;  // -2: none, -1: the internal field, else the patch
  forAll(T, i) {
    if (bad(T[i])) {
      value = T[i];
      where = T.mesh().C()[i];
      part = -1;
      break;
    }
  }
  forAll(T.boundaryField(), patch) {
    if (part != -2) break;
    const fvPatch& fp = T.mesh().boundary()[patch];
    if (fp.coupled()) continue;  // cyclic and processor faces repeat cells' values
    forAll(fp, f) {
      if (bad(T.boundaryField()[patch][f])) {
        value = T.boundaryField()[patch][f];
        where = fp.Cf()[f];
        part = patch;
        break;
      }
    }
  }
  const label me = Pstream::myProcNo(), none = Pstream::nProcs();
  const label first = returnReduce(part != -2 ? me : none, minOp<label>());
  if (first == none) return;
  const bool mine = me == first;
  value = returnReduce(mine ? value : 0.0, sumOp<scalar>());
  where = returnReduce(mine ? where : vector::zero, sumOp<vector>());
  part = returnReduce(mine ? part : labelMin, maxOp<label>());
  const word in = part >= 0 ? "patch " + T.mesh().boundary()[part].name() : "internalField";
  std::ostringstream m;
  m.precision(6);
  m << "grainFoam: error: " << startTime.c_str() << "/T holds " << value << " K (its " << in
    << ", at (" << where.x() << " " << where.y() << " " << where.z()
    << ") m): the fluid temperature is absolute, in kelvin, and must be above 0 K, as the "
       "scene's temperatures are (e.g. 293.15 for 20 degrees Celsius)";
  FatalErrorInFunction << m.str().c_str() << exit(FatalError);
}

// The files of each write time, with their checksums (coupling/written_files.hpp), checked
// when a run restarts from that time: OpenFOAM's field files carry none. Only with the
// uncollated file handler, where each rank's folder holds its own files (a collated one
// writes them into processors<N>/ from a thread).
bool writtenFilesRecorded() { return Foam::fileHandler().type() == "uncollated"; }

// After everything of a write time is written (the fields, uniform/, the DEM checkpoint's
// name): each rank records its own folder.
void recordWrittenFiles(const Foam::Time& runTime) {
  using namespace Foam;
  if (!writtenFilesRecorded()) return;
  std::ostringstream who;
  if (Pstream::parRun())
    who << "processor" << Pstream::myProcNo() << " of " << Pstream::nProcs() << " ranks";
  else
    who << "1 rank";
  who << ", time " << runTime.timeName().c_str();
  try {
    grainflow::coupling::record_written_files(runTime.timePath(), who.str());
  } catch (const std::exception& e) {
    FatalErrorInFunction << "grainFoam: error: recording the files written at time "
                         << runTime.timeName() << ": " << e.what() << exit(FatalError);
  }
}

// Collective: before the start time's fields are read, every rank compares its folder with
// the record written with it; any difference stops the run on every rank with the message
// of the lowest rank that found one.
void checkWrittenFiles(const Foam::Time& runTime) {
  using namespace Foam;
  if (!writtenFilesRecorded()) return;
  grainflow::coupling::WrittenFilesCheck check =
      grainflow::coupling::check_written_files(runTime.timePath());
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  int first = check.problem.empty() ? size : rank;
  MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first < size) {
    long length = static_cast<long>(check.problem.size());
    MPI_Bcast(&length, 1, MPI_LONG, first, MPI_COMM_WORLD);
    check.problem.resize(static_cast<std::size_t>(length));
    MPI_Bcast(check.problem.data(), static_cast<int>(length), MPI_CHAR, first, MPI_COMM_WORLD);
    FatalErrorInFunction << check.problem.c_str() << exit(FatalError);
  }
  const label unrecorded = returnReduce(label(check.recorded ? 0 : 1), sumOp<label>());
  const label checked = returnReduce(label(check.checked), sumOp<label>());
  if (unrecorded == 0)
    Info << "grainFoam: time folder " << runTime.timeName() << ": its " << checked
         << " files match the checksums grainFoam recorded when it wrote them ("
         << grainflow::coupling::kWrittenFilesRecord << ")" << endl;
  else if (runTime.timeIndex() > 0)
    Info << "grainFoam: time folder " << runTime.timeName() << " has no record of its files ("
         << grainflow::coupling::kWrittenFilesRecord
         << "; decomposePar and reconstructPar write none) on " << unrecorded << " of "
         << Pstream::nProcs() << (Pstream::nProcs() == 1 ? " rank" : " ranks")
         << ": its fields are read unchecked" << endl;
}

// grainFoam solves a Newtonian fluid of constant rho and nu (with heat, constant Cp and
// kappa): another viscosity model would run as if it were not there, and is refused at its
// line; the other keys are named as not read.
void checkTransportKeys(const Foam::dictionary& transport) {
  using namespace Foam;
  std::string problems;
  label first = -1;  // the first refused key's line, for the message's "file:" line
  const auto lineOf = [&transport, &first](const word& key) {
    const entry* e = transport.findEntry(key, keyType::LITERAL);
    if (!e) return std::string();
    if (first < 0) first = e->startLineNumber();
    return " at line " + std::to_string(e->startLineNumber());
  };
  const word model = transport.lookupOrDefault<word>("transportModel", "Newtonian");
  if (model != "Newtonian")
    problems += "transportModel " + std::string(model) + lineOf("transportModel") +
                ": grainFoam solves a Newtonian fluid (constant nu); set transportModel "
                "Newtonian or remove it\n";
  // Other keys are said, not refused: the unused coefficient blocks of other models that
  // OpenFOAM's tutorials keep beside `transportModel Newtonian`, and helper values a `$name`
  // refers to, are inert.
  const std::vector<std::string> allowed{"transportModel", "rho", "nu", "Cp", "kappa"};
  for (const word& key : transport.toc())
    if (std::find(allowed.begin(), allowed.end(), std::string(key)) == allowed.end()) {
      const entry* e = transport.findEntry(key, keyType::LITERAL);
      Info << "grainFoam: note: constant/transportProperties: '" << key.c_str() << "'"
           << (e ? " at line " + std::to_string(e->startLineNumber()) : std::string()).c_str()
           << grainflow::suggestion(key, allowed).c_str()
           << " is not read by grainFoam, which reads transportModel (Newtonian), rho, nu, and "
              "with the scene's heat Cp and kappa"
           << endl;
    }
  if (problems.empty()) return;
  problems.pop_back();
  FatalIOError(FUNCTION_NAME, __FILE__, __LINE__, transport.name(), first, first)
      << problems.c_str() << exit(FatalIOError);
}

// Where a run from `start` to `end` in steps of dt stops: OpenFOAM's Time::run() goes on while
// t < end - dt/2 and each step adds dt to t, so the run takes the whole number of steps
// nearest (end - start)/dt, and stops after or before `end` when that is not whole. The same
// sums as OpenFOAM's, so the time is the one the run reaches (a closed form beyond 1e8 steps).
struct RunEnd {
  double time = 0;  // the last step's time
  long steps = 0;
  bool whole = true;  // time = end to 1e-3 of a step: (end - start)/dt is whole
};
RunEnd runEnd(double start, double end, double dt) {
  RunEnd r;
  r.time = start;
  if ((end - start) / dt > 1e8) {
    r.steps = static_cast<long>(std::ceil((end - start) / dt - 0.5));
    r.time = start + static_cast<double>(r.steps) * dt;
  } else {
    while (r.time < end - 0.5 * dt) {
      r.time += dt;
      ++r.steps;
    }
  }
  r.whole = std::abs(r.time - end) <= 1e-3 * dt;
  return r;
}

// Times as typed (6 digits), not at the case's writePrecision.
std::string typed(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

// The start-up note when the run's end is not a whole number of fluid steps from its start:
// which time it ends at, and the two nearest ends that are whole (12 digits, so that a value
// typed back is whole to round-off).
std::string endNote(const std::string& which, const std::string& source, const std::string& key,
                    double start, double end, double dt, const RunEnd& r) {
  std::ostringstream s;
  s << "grainFoam: note: " << which << " " << typed(end) << " s"
    << (source.empty() ? std::string() : " (" + source + ")") << " is " << std::setprecision(6)
    << (end - start) / dt << " fluid steps of deltaT " << typed(dt)
    << " s from the start (t = " << typed(start) << " s), not a whole number: the run takes "
    << r.steps << (r.steps == 1 ? " step" : " steps")
    << ", the nearest whole number, and ends at t = " << typed(r.time) << " s, "
    << (r.time > end ? "after" : "before") << " it. To end exactly at " << key
    << ", set it to a whole number of steps from the "
       "start, e.g. ";
  const long low = static_cast<long>(std::floor((end - start) / dt));
  s << std::setprecision(12);
  if (low >= 1) s << start + static_cast<double>(low) * dt << " (" << low << " steps) or ";
  s << start + static_cast<double>(low + 1) * dt << " (" << low + 1 << " steps)";
  return s.str();
}

// With runTimeModifiable, OpenFOAM re-reads system/controlDict (and any dictionary registered
// MUST_READ_IF_MODIFIED) at the start of each step, in Time::run(). What the coupling fixed at
// start-up must survive it: deltaT is a whole number of DEM steps (the DEM's sub-steps and a
// restart's step count depend on it), and the run's end is the earlier of controlDict's
// endTime and the scene's time.end. A re-read endTime is taken with the scene's end still
// holding; a re-read deltaT is not taken (said once per value); edits of the coupling's and
// the fluid's property files are not taken during a run (said once per file).
class RunTimeEdits {
 public:
  RunTimeEdits(Foam::Time& runTime, double sceneEnd, const std::string& sceneEndSource)
      : runTime_(runTime),
        deltaT_(runTime.deltaTValue()),
        seenDeltaT_(deltaT_),
        sceneEnd_(sceneEnd),
        foamEnd_(runTime.endTime().value()),
        sceneEndSource_(sceneEndSource) {
    using namespace Foam;
    // Time::readDict takes deltaT from a re-read controlDict unless it has been set.
    runTime.setDeltaT(deltaT_, false);
    setEnd();
    // The property files: the master compares them (the warning is the master's line).
    const fileName constant = runTime.rootPath() / runTime.globalCaseName() / "constant";
    if (Pstream::master())
      for (const char* name : {"couplingProperties", "transportProperties"}) {
        Watched w;
        w.path = constant / name;
        w.shown = "constant/" + std::string(name);
        w.stamp = highResLastModified(w.path);
        w.text = contents(w.path);
        watched_.push_back(w);
      }
  }
  // After Time::run() (its re-read): true when the run has reached its end.
  bool reachedEnd() {
    using namespace Foam;
    if (runTime_.endTime().value() != end_) {  // controlDict re-read (or stopAt)
      foamEnd_ = runTime_.endTime().value();
      const scalar before = end_;
      setEnd();
      if (end_ != before && foamEnd_ < 0.1 * GREAT) {
        const RunEnd r = runEnd(runTime_.value(), end_, runTime_.deltaTValue());
        Info << "grainFoam: system/controlDict re-read: endTime " << text(foamEnd_).c_str()
             << " s; the run ends at t = " << text(r.time).c_str() << " s, "
             << (r.whole ? "" : "the fluid step nearest ") << endName().c_str() << endl;
      }
    }
    const scalar dt = runTime_.controlDict().lookupOrDefault<scalar>("deltaT", deltaT_);
    if (dt != seenDeltaT_ && dt != deltaT_)
      Info << "grainFoam: warning: system/controlDict was re-read with deltaT " << text(dt).c_str()
           << " s; the run keeps deltaT " << text(deltaT_).c_str()
           << " s. The coupling fixes deltaT at start-up as a whole number of DEM steps, and a "
              "restart continues with the deltaT its time was run with, so a changed deltaT "
              "is not taken during a run. To run with another deltaT, start a new run from "
              "time 0 (set deltaT back to "
           << text(deltaT_).c_str() << " in system/controlDict to silence this)" << endl;
    seenDeltaT_ = dt;
    if (runTime_.runTimeModifiable())
      for (Watched& w : watched_) {
        const double stamp = highResLastModified(w.path);
        if (stamp == w.stamp) continue;
        w.stamp = stamp;
        if (w.warned || contents(w.path) == w.text) continue;
        w.warned = true;
        Info << "grainFoam: warning: " << w.shown.c_str()
             << " was edited during the run; grainFoam read it at start-up and does not "
                "take changes to it during a run: the run goes on with the settings it "
                "started with (said once)"
             << endl;
      }
    return runTime_.value() >= end_ - 0.5 * runTime_.deltaTValue();
  }
  // The last line when the run reached its end and that was the scene's time.end, or a time
  // other than the end (the end not a whole number of steps from the start); empty
  // otherwise. It states the time the run reached.
  std::string finalLine() const {
    const double t = runTime_.value(), dt = runTime_.deltaTValue();
    if (t < end_ - 0.5 * dt) return std::string();  // stopped before its end
    const bool whole = std::abs(t - end_) <= 1e-3 * dt;
    if (sceneEnd_ < foamEnd_)
      return whole ? "grainFoam: stopped at the scene's time.end, t = " + text(t) + " s (" +
                         sceneEndSource_ + "), before system/controlDict's endTime " +
                         text(foamEnd_) + " s; to run longer, raise both"
                   : "grainFoam: stopped at t = " + text(t) +
                         " s, the fluid step nearest the scene's time.end " + text(sceneEnd_) +
                         " s (" + sceneEndSource_ + "), before system/controlDict's endTime " +
                         text(foamEnd_) + " s; to run longer, raise both";
    if (whole) return std::string();
    return "grainFoam: stopped at t = " + text(t) +
           " s, the fluid step nearest system/controlDict's endTime " + text(foamEnd_) + " s";
  }

 private:
  struct Watched {
    Foam::fileName path;
    std::string shown, text;
    double stamp = 0;
    bool warned = false;
  };
  static std::string contents(const Foam::fileName& path) {
    std::ifstream in(path.c_str(), std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }
  // As typed (6 digits), not at the case's writePrecision.
  static std::string text(double x) {
    std::ostringstream s;
    s << x;
    return s.str();
  }
  std::string endName() const {
    return sceneEnd_ < foamEnd_ ? "the scene's time.end (" + sceneEndSource_ + ")"
                                : std::string("system/controlDict's endTime");
  }
  void setEnd() {
    end_ = std::min(sceneEnd_, foamEnd_);
    runTime_.setEndTime(end_);
  }
  Foam::Time& runTime_;
  const double deltaT_;
  double seenDeltaT_;
  const double sceneEnd_;
  double foamEnd_;
  double end_ = 0;
  const std::string sceneEndSource_;
  std::vector<Watched> watched_;
};

// The solver proper; everything it creates (the DEM included) is gone when it returns,
// before MPI is finalised.
void solve(const Foam::argList& args) {
  using namespace Foam;
  // Reading the case runs with the traps off: OpenFOAM's number reader overflows on a value
  // beyond the double range (1e400 in 0/U) and the trap would end the run with a stack trace
  // where the reader's own error names the file and line. They are back on for the time loop.
  std::optional<grainflow::FloatingPointTrapsOff> readingTraps(std::in_place);
  Time runTime(Time::controlDictName, args);
  checkWrittenFiles(runTime);
  // A restart takes its time value from the folder's name (timePrecision digits), not from
  // the exact value the stopped run stored in <time>/uniform/time: the continued times then
  // differ from the uninterrupted run's in their last bits, and so does everything that
  // depends on the time (a time table at an inlet). Continue from the stored value when it
  // names this folder.
  {
    IOdictionary timeDict(IOobject("time", runTime.timeName(), "uniform", runTime,
                                   IOobject::READ_IF_PRESENT, IOobject::NO_WRITE, false));
    scalar stored = 0;
    if (runTime.timeIndex() > 0 && timeDict.readIfPresent("value", stored) &&
        runTime.timeName(stored) == runTime.timeName() && stored != runTime.value())
      runTime.setTime(stored, runTime.timeIndex());
  }
  const word startTime = runTime.timeName();  // the folder the fields start from
  fvMesh mesh(IOobject(fvMesh::defaultRegion, runTime.timeName(), runTime, IOobject::MUST_READ));
  pimpleControl pimple(mesh);

  IOdictionary transport(IOobject("transportProperties", runTime.constant(), mesh,
                                  IOobject::MUST_READ_IF_MODIFIED, IOobject::NO_WRITE));
  checkTransportKeys(transport);
  const dimensionedScalar rho("rho", dimDensity, transport);
  const dimensionedScalar nu("nu", dimViscosity, transport);

  volScalarField p(IOobject("p", runTime.timeName(), mesh, IOobject::MUST_READ,
                            IOobject::AUTO_WRITE),
                   mesh);
  volVectorField U(IOobject("U", runTime.timeName(), mesh, IOobject::MUST_READ,
                            IOobject::AUTO_WRITE),
                   mesh);
  label pRefCell = 0;
  scalar pRefValue = 0;
  setRefCell(p, pimple.dict(), pRefCell, pRefValue);
  mesh.setFluxRequired(p.name());

  grainflow::foam::ParticleCoupling particles(mesh, U, p, rho.value(), nu.value());
  const volScalarField& eps = particles.voidFraction();

  // Heat (the DEM scene has `heat:`): the fluid temperature T [K] and the fluid's c_p and
  // k_f from transportProperties; without heat neither is read nor anything solved.
  std::unique_ptr<volScalarField> temperature;
  dimensionedScalar rhoCp("rhoCp", dimensionSet(1, -1, -2, -1, 0), 0);
  dimensionedScalar alpha("alpha", dimViscosity, 0);  // k_f / (rho c_p)
  if (particles.heatOn()) {
    for (const char* key : {"Cp", "kappa"})
      if (!transport.found(key))
        FatalIOErrorInFunction(transport)
            << "the DEM scene has heat on: " << transport.objectPath() << " needs `" << key
            << (std::string(key) == "Cp" ? "  <J/(kg K)>;` (the fluid's heat capacity c_p)"
                                          : "  <W/(m K)>;` (the fluid's conductivity k_f)")
            << exit(FatalIOError);
    const dimensionedScalar Cp("Cp", dimensionSet(0, 2, -2, -1, 0), transport);
    const dimensionedScalar kappa("kappa", dimensionSet(1, 1, -3, -1, 0), transport);
    rhoCp = rho * Cp;
    alpha = kappa / rhoCp;
    temperature.reset(new volScalarField(IOobject("T", runTime.timeName(), mesh,
                                                  IOobject::MUST_READ, IOobject::AUTO_WRITE),
                                         mesh));
    checkStartingTemperature(*temperature, startTime);
    particles.setTemperature(*temperature, rhoCp.value(), kappa.value(), transport.objectPath());
  } else
    for (const char* key : {"Cp", "kappa"})
      if (transport.found(key))
        Info << "grainFoam: warning: " << key << " (constant/transportProperties) has no effect: "
             << "the scene has no heat: block, so no fluid temperature is solved" << endl;
  const bool modelA = particles.model() == 'A';
  const bool meanGradP = particles.meanPressureGradientOn();

  // The superficial flux, from the initial U and eps.
  surfaceScalarField phi(IOobject("phi", runTime.timeName(), mesh, IOobject::READ_IF_PRESENT,
                                  IOobject::AUTO_WRITE),
                         fvc::interpolate(eps) * fvc::flux(U));

  // SIGTERM / SIGINT (a batch system's time limit, Ctrl-C): finish the step, write the
  // fields and the DEM checkpoint, and exit 0; a restart (startFrom latestTime) continues
  // bit-identically.
  const grainflow::StopSignals stopSignals(true);

  // The run ends at the earlier of system/controlDict's endTime and the scene's time.end.
  // When the scene's is earlier, the last line says so again: a log read from its tail should
  // not look like a run to controlDict's endTime.
  {
    const scalar sceneEnd = particles.sceneEndTime(), foamEnd = runTime.endTime().value();
    const auto text = typed;
    const scalar end = min(sceneEnd, foamEnd), start = runTime.value();
    const scalar half = 0.5 * runTime.deltaTValue();
    // OpenFOAM ends at the fluid step nearest the end: said when that is not the end itself.
    const RunEnd reach = end > start + half ? runEnd(start, end, runTime.deltaTValue()) : RunEnd{};
    const std::string nearest = reach.whole ? "" : "the fluid step nearest ";
    const bool nothing = end < start + half;  // said below
    if (nothing) {
    } else if (sceneEnd < foamEnd) {
      Info << "grainFoam: ends at t = " << text(reach.whole ? sceneEnd : reach.time).c_str()
           << " s, " << nearest.c_str() << "the scene's time.end "
           << (reach.whole ? "" : text(sceneEnd) + " s ").c_str() << "("
           << particles.sceneEndTimeSource().c_str() << "), before system/controlDict's endTime "
           << text(foamEnd).c_str() << " s" << endl;
    } else {
      Info << "grainFoam: ends at t = " << text(reach.whole ? foamEnd : reach.time).c_str()
           << " s, " << nearest.c_str() << "system/controlDict's endTime "
           << (reach.whole ? "" : text(foamEnd) + " s ").c_str() << "(the scene's time.end, "
           << particles.sceneEndTimeSource().c_str() << ", is " << text(sceneEnd).c_str() << " s)"
           << endl;
    }
    if (!nothing && !reach.whole)
      Info << endNote(sceneEnd < foamEnd ? "the scene's time.end" : "system/controlDict's endTime",
                      sceneEnd < foamEnd ? particles.sceneEndTimeSource() : std::string(),
                      sceneEnd < foamEnd ? "time.end" : "endTime", start, end,
                      runTime.deltaTValue(), reach)
                  .c_str()
           << endl;
    // An end before the start is a typo (or a scene from another case): nothing would run
    // and the run would still end as if done.
    const std::string which = sceneEnd < foamEnd
                                  ? "the scene's time.end (" + particles.sceneEndTimeSource() + ")"
                                  : std::string("system/controlDict's endTime");
    if (end < start - half)
      FatalErrorInFunction << "grainFoam: error: the run would end at t = " << text(end).c_str()
                           << " s, " << which.c_str()
                           << ", before it starts at t = " << text(start).c_str()
                           << " s (time folder " << runTime.timeName()
                           << ", system/controlDict's startFrom): nothing to run; raise "
                           << which.c_str() << exit(FatalError);
    if (nothing)
      Info << "grainFoam: nothing to run: the run starts at t = " << text(start).c_str()
           << " s, at its end, t = " << text(end).c_str() << " s, " << which.c_str()
           << " (the run ends at the earlier of system/controlDict's endTime, "
           << text(foamEnd).c_str() << " s, and the scene's time.end, " << text(sceneEnd).c_str()
           << " s); to run longer, raise " << which.c_str()
           << (std::max(sceneEnd, foamEnd) < start + half ? " and the other" : "") << endl;
  }
  RunTimeEdits edits(runTime, particles.sceneEndTime(), particles.sceneEndTimeSource());
  particles.checkStartingFlow();
  particles.writeSnapshotIfDue();
  readingTraps.reset();

  Info << "\nStarting time loop\n" << endl;
  while (runTime.run()) {
    if (edits.reachedEnd()) break;
    ++runTime;
    Info << "Time = " << runTime.timeName() << nl << endl;

    particles.evolve();
    const grainflow::foam::Stopwatch fluidClock;

    const surfaceScalarField epsf(fvc::interpolate(eps));
    // Coefficient of grad p (and of the viscous term); with dragVoidFraction sharpInterface
    // the void fraction of the layer that carries a two-layer cell's pressure drop.
    volScalarField c("c", particles.sharpInterface() ? particles.dragVoidFraction() : eps);
    surfaceScalarField cf("cf", epsf);
    if (particles.sharpInterface()) cf = fvc::interpolate(c);
    if (!modelA) {
      c = dimensionedScalar("one", dimless, 1);
      cf = dimensionedScalar("one", dimless, 1);
    }
    volScalarField ddtEps(IOobject("ddtEps", runTime.timeName(), mesh), mesh,
                          dimensionedScalar("zero", dimless / dimTime, 0));
    if (particles.ddtVoidFraction()) ddtEps = fvc::ddt(eps);

    while (pimple.loop()) {
      fvVectorMatrix UEqn(
          fvm::ddt(eps, U) + fvm::div(phi, U) - fvm::Sp(ddtEps + fvc::div(phi), U) -
              fvm::laplacian(c * nu, U) - fvc::div(c * nu * dev2(T(fvc::grad(U))))
          == -fvm::Sp(particles.Ksl() / rho, U) + particles.KslUs() / rho +
                 particles.fExplicit() / rho);
      UEqn.relax();
      // The uniform part G of the pressure gradient: a cell source (its volume integral is
      // exactly -c G V, so the mixture's net force stays zero); zero when off.
      if (meanGradP) UEqn -= -c * particles.meanPressureGradient() / rho;
      // facePressure dragSeries: the cell gradient with the face pressures of half cells in
      // series (ParticleCoupling::seriesGradient), in the predictor and the corrected U.
      const bool series = particles.dragSeriesPressure();
      if (pimple.momentumPredictor()) {
        const TrapsOff trapsOff;
        solve(UEqn == -c * (series ? particles.seriesGradient(p) : fvc::grad(p)));
        stopIfDiverged("the momentum predictor", U, p, particles);
      }

      while (pimple.correct()) {
        const volScalarField rAU(1.0 / UEqn.A());
        const surfaceScalarField rAUf(fvc::interpolate(rAU));
        volVectorField HbyA(constrainHbyA(rAU * UEqn.H(), U, p));
        surfaceScalarField phiHbyA("phiHbyA", epsf * fvc::flux(HbyA));
        if (p.needReference()) adjustPhi(phiHbyA, U, p);
        const surfaceScalarField Dp(epsf * cf * rAUf);
        // fixedFluxPressure patches: the normal pressure gradient that balances the
        // particles' drag on the fluid at the face, c dp/dn = (-Ksl U + Ksl Us + f)/rho . n
        // (steady momentum next to the wall or inlet). A zero gradient there would put
        // the face at the first cell's pressure and lose the drop across the half cell
        // of a bed resting on the inlet.
        forAll(p.boundaryField(), patch) {
          if (!isA<fixedFluxPressureFvPatchScalarField>(p.boundaryField()[patch])) continue;
          const fvPatch& fp = mesh.boundary()[patch];
          const vectorField force(-particles.Ksl().boundaryField()[patch] *
                                      U.boundaryField()[patch] +
                                  particles.KslUs().boundaryField()[patch] +
                                  particles.fExplicit().boundaryField()[patch]);
          const scalarField snGrad((fp.nf() & force) / (rho.value() * c.boundaryField()[patch]));
          refCast<fixedFluxPressureFvPatchScalarField>(p.boundaryFieldRef()[patch])
              .updateSnGrad(snGrad);
          // The boundary flux before the pressure correction, set so that the corrected one
          // is eps_b U_b.S (whatever HbyA holds there: fixedFluxExtrapolatedPressure, a
          // fixedFluxPressure type too, does not pin HbyA to the inlet velocity).
          const fixedFluxPressureFvPatchScalarField& pb =
              refCast<const fixedFluxPressureFvPatchScalarField>(p.boundaryField()[patch]);
          phiHbyA.boundaryFieldRef()[patch] =
              eps.boundaryField()[patch] * (fp.Sf() & U.boundaryField()[patch]) +
              Dp.boundaryField()[patch] * pb.gradient() * fp.magSf();
        }
        while (pimple.correctNonOrthogonal()) {
          fvScalarMatrix pEqn(fvm::laplacian(Dp, p) == fvc::div(phiHbyA) + ddtEps);
          pEqn.setReference(pRefCell, pRefValue);
          {
            const TrapsOff trapsOff;
            pEqn.solve(mesh.solver(p.select(pimple.finalInnerIter())));
            stopIfDiverged("the pressure equation", U, p, particles);
          }
          if (pimple.finalNonOrthogonalIter()) {
            const TrapsOff trapsOff;
            phi = phiHbyA - pEqn.flux();
            p.relax();
            if (series)
              U = HbyA - rAU * c * particles.seriesGradient(p);
            else
              U = HbyA - grainflow::foam::reconstructFlux(pEqn.flux() / epsf);
            U.correctBoundaryConditions();
          }
        }
        stopIfDiverged("the velocity correction", U, p, particles);
        // Continuity error of the volume-averaged equation.
        const volScalarField contErr(fvc::div(phi) + ddtEps);
        Info << "continuity error: sum local = "
             << runTime.deltaTValue() * mag(contErr)().weightedAverage(mesh.V()).value()
             << endl;
      }
    }
    // The fluid's energy equation, volume-averaged, divided by rho c_p, in conservative form:
    //   d(eps T)/dt + div(phi T) - div(eps alpha grad T) = -(KT (T - T0) + Q) / (rho c_p)
    // with the particles' exchange (ParticleCoupling::heatResponse, heatSource): Q the heat
    // they took in the DEM steps, KT their response to the change of T in this step, the
    // same amount they take after the solve (exchangeHeat), so that the fluid loses exactly
    // what the particles gain.
    std::unique_ptr<volScalarField> T0;  // T at the step's start (heat on)
    if (temperature) {
      volScalarField& T = *temperature;
      T0.reset(new volScalarField("T0", T));
      fvScalarMatrix TEqn(fvm::ddt(eps, T) + fvm::div(phi, T) - fvm::laplacian(epsf * alpha, T)
                          == -fvm::Sp(particles.heatResponse() / rhoCp, T) +
                                 (particles.heatResponse() * *T0 - particles.heatSource()) /
                                     rhoCp);
      // ddtVoidFraction off: continuity holds div(phi) = 0 without d(eps)/dt, so the
      // conservative d(eps T)/dt would turn each change of eps into a change of T (particles
      // arriving in a cell would heat its gas by eps_old / eps_new, particles leaving cool it:
      // the fluid went 73 K below every starting and inlet temperature in random coupled seed
      // 113). Consistent with
      // that continuity, the storage term is eps dT/dt: T moves only by the flux, diffusion and
      // the exchange.
      if (!particles.ddtVoidFraction()) TEqn -= fvm::Sp(fvc::ddt(eps), T);
      TEqn.relax();
      {
        const TrapsOff trapsOff;
        TEqn.solve(mesh.solver("T"));
      }
      stopIfTemperatureDiverged(T, particles, startTime);
    }
    particles.addFluidTime(fluidClock);
    if (temperature) particles.exchangeHeat(*temperature, *T0);

    runTime.write();
    if (runTime.writeTime()) {
      particles.write();
      recordWrittenFiles(runTime);
    }
    particles.writeSnapshotIfDue();
    runTime.printExecutionTime(Info);

    const int signal = grainflow::StopSignals::agreed(MPI_COMM_WORLD);
    if (signal != 0) {
      if (!runTime.writeTime()) {
        particles.completeWrittenFields();
        runTime.writeNow();
        particles.write();
        recordWrittenFiles(runTime);
      }
      Info << "grainFoam: received " << grainflow::StopSignals::name(signal)
           << "; stopped after time " << runTime.timeName() << " (time index "
           << runTime.timeIndex()
           << ") and wrote it with the DEM checkpoint; continue with startFrom latestTime in "
              "system/controlDict\n"
           << endl;
      return;
    }
  }
  const std::string last = edits.finalLine();
  if (!last.empty()) Info << last.c_str() << endl;
  Info << "End\n" << endl;
}

}  // namespace

int main(int argc, char* argv[]) {
  using namespace Foam;
  argList::addNote(
      "CFD-DEM solver: volume-averaged incompressible Navier-Stokes (PIMPLE) coupled to the "
      "grainflow DEM. Needs constant/couplingProperties and the DEM scene it names.");
  argList args(argc, argv);
  if (!args.checkRootCase()) FatalError.exit();
  // A serial run has no MPI from OpenFOAM; the DEM needs it.
  int mpiReady = 0;
  MPI_Initialized(&mpiReady);
  const bool ownMpi = !mpiReady;
  if (ownMpi) MPI_Init(&argc, &argv);
  // Started by mpirun on several ranks without -parallel, each rank would run the whole case
  // on its own (and the coupling would blame the decomposition).
  int ranks = 1, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (!Pstream::parRun() && ranks > 1) {
    if (rank == 0)
      std::cerr << "grainFoam: error: started on " << ranks
                << " MPI ranks without -parallel: each rank would run the whole case by "
                   "itself. Add -parallel (mpirun -np "
                << ranks
                << " grainFoam -parallel, on a case decomposed by decomposePar into as many "
                   "processor folders), or run grainFoam without mpirun for a serial run"
                << std::endl;
    MPI_Finalize();
    // Not through return or exit(): under mpirun the process then ended with status 0
    // (measured; something registered at exit by the OpenFOAM libraries), and mpirun with it.
    std::_Exit(1);
  }
  solve(args);
  if (ownMpi) MPI_Finalize();
  return 0;
}
