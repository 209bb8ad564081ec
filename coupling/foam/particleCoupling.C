#include <mpi.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <utility>

#include "IFstream.H"
#include "coupling/accuracy_table.hpp"
#include "coupling/floating_point_traps.hpp"
#include "coupling/foam/cellSearch.H"
#include "coupling/foam/gaussLinearGrad.H"
#include "coupling/foam/particleCoupling.H"
#include "coupling/shared_decomposition.hpp"
#include "coupling/written_files.hpp"
#include "dem/core/suggestion.hpp"
#include "dem/io/output_directory.hpp"
#include "extrapolatedCalculatedFvPatchField.H"
#include "processorFvPatch.H"
#include "stringOps.H"
#include "uniformDimensionedFields.H"
#include "volPointInterpolation.H"
#include "wallFvPatch.H"
#include "zeroGradientFvPatchFields.H"

namespace grainflow::foam {

namespace {

// The processor grid's inner cut planes, as the DEM takes them from the mesh decomposition:
// "; cuts along z at 0.039 m" (nothing for a single rank).
std::string cutsText(const coupling::ProcessorGrid& grid) {
  std::ostringstream text;
  for (int a = 0; a < 3; ++a) {
    if (grid.dims[a] < 2) continue;
    text << "; cuts along " << "xyz"[a] << " at";
    for (int k = 1; k < grid.dims[a]; ++k) text << (k > 1 ? ", " : " ") << grid.cuts[a][k];
    text << " m";
  }
  return text.str();
}

}  // namespace

namespace {

// The mesh axis a face's area vector is most aligned with (0, 1, 2: x, y, z).
int dominantAxis(const Foam::vector& s) {
  int a = 0;
  for (int b = 1; b < 3; ++b)
    if (std::abs(s[b]) > std::abs(s[a])) a = b;
  return a;
}

using Clock = std::chrono::steady_clock;

double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}
// locate(): a point more than this many cells from the domain's corner is outside (and
// its cell index would not fit an int).
constexpr double kFarOutside = 1e9;

// The viscous term's non-orthogonal correction is left out when every correction vector
// (dimensionless, |k| <= 1; OpenFOAM's nonOrthCorrectionVectors) is below this: a mesh
// orthogonal up to round-off (the correction changes the term by ~|k| relative).
constexpr double kOrthogonalCorrection = 1e-9;

// deltaT / time.step must be whole to this relative amount: the round-off of decimal inputs
// (1e-3 / 2e-5 is 50 to 1.4e-16) and of a value typed with 11 digits or more.
constexpr double kRatioTolerance = 1e-10;

// diffusionBandwidth: at most this many explicit steps (each a pass over the faces per
// averaged field and fluid step); a bandwidth beyond them averages over more than about 18
// of the smallest cells in every direction, wider than any closure asks for.
constexpr double kMaxSmoothingSteps = 1000;

// Patch types for a derived field: constraint patches (processor, cyclic, empty, ...)
// keep their type, every other patch is zeroGradient.
Foam::wordList derivedPatchTypes(const Foam::fvMesh& mesh) {
  const Foam::polyBoundaryMesh& patches = mesh.boundaryMesh();
  Foam::wordList types(patches.size());
  forAll(patches, i) {
    types[i] = Foam::polyPatch::constraintType(patches[i].type())
                   ? patches[i].type()
                   : Foam::word(Foam::zeroGradientFvPatchScalarField::typeName);
  }
  return types;
}

Foam::IOobject derivedField(const Foam::fvMesh& mesh, const Foam::word& name, bool write) {
  return Foam::IOobject(name, mesh.time().timeName(), mesh, Foam::IOobject::NO_READ,
                        write ? Foam::IOobject::AUTO_WRITE : Foam::IOobject::NO_WRITE);
}

std::array<double, 3> toArray(const Foam::vector& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

namespace {

// Collective: the FNV-1a checksum of a file that rank 0 reads (the DEM checkpoint, which rank
// 0 writes), as 16 hex digits, or the error on every rank.
std::string checkpointChecksum(const std::string& path) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  char text[64] = {};
  if (rank == 0) {
    try {
      std::snprintf(text, sizeof text, "%016llx",
                    static_cast<unsigned long long>(coupling::file_checksum(path)));
    } catch (const std::exception& e) {
      std::snprintf(text, sizeof text, "unreadable");
    }
  }
  MPI_Bcast(text, sizeof text, MPI_CHAR, 0, MPI_COMM_WORLD);
  return text;
}

// The DEM checkpoint a time folder's uniform/grainflowCheckpoint names ("" when none).
std::string namedCheckpoint(const Foam::fileName& timeDir) {
  std::ifstream in((timeDir / "uniform" / "grainflowCheckpoint").c_str());
  std::string key, value;
  while (in >> key) {
    if (key == "checkpoint" && in >> value) {
      if (!value.empty() && value.back() == ';') value.pop_back();
      return value;
    }
  }
  return std::string();
}

// The time folders (other than 0) in the case folder and in processor0/, each with the DEM
// checkpoint it names (an empty name when it names none).
std::vector<std::pair<std::string, std::string>> keptTimeFolders(const Foam::fileName& caseDir) {
  using namespace Foam;
  std::vector<std::pair<std::string, std::string>> found;
  for (const fileName& dir : {caseDir, caseDir / "processor0"}) {
    if (!isDir(dir)) continue;
    for (const instant& t : Time::findTimes(dir)) {
      if (t.value() == 0) continue;
      const std::string shown =
          dir == caseDir ? std::string(t.name()) : "processor0/" + std::string(t.name());
      found.emplace_back(shown, namedCheckpoint(dir / t.name()));
    }
  }
  return found;
}

}  // namespace

void Stopwatch::restart() {
  wall0_ = Clock::now();
  cpu0_ = processCpuSeconds();
}
double Stopwatch::wall() const { return std::chrono::duration<double>(Clock::now() - wall0_).count(); }
double Stopwatch::cpu() const { return processCpuSeconds() - cpu0_; }

namespace {
// The line of a couplingProperties key, for its error's "file: ... at line N" (OpenFOAM's
// FatalIOErrorInFunction(dict) names the dictionary's whole line range); the range when the
// key is not in the file (its default was taken).
std::pair<Foam::label, Foam::label> keyLines(const Foam::dictionary& dict, const char* key) {
  const Foam::entry* e = dict.findEntry(key, Foam::keyType::LITERAL);
  if (e) return {e->startLineNumber(), e->startLineNumber()};
  return {dict.startLineNumber(), dict.endLineNumber()};
}
// A value as typed (12 digits: 0.1, not the case's writePrecision 0.10000000000000001).
std::string typed(double x) {
  std::ostringstream s;
  s.precision(12);
  s << x;
  return s.str();
}
}  // namespace

// FatalIOErrorInFunction(dict) at the line of `key` (the dictionary's name is its file's path;
// an IOdictionary's own name() is the object's).
#define FatalKeyError(dict, key)                                                             \
  FatalIOError(FUNCTION_NAME, __FILE__, __LINE__,                                            \
               static_cast<const Foam::dictionary&>(dict).name(), keyLines(dict, key).first, \
               keyLines(dict, key).second)

ParticleCoupling::ParticleCoupling(const Foam::fvMesh& mesh, const Foam::volVectorField& U,
                                   const Foam::volScalarField& p, double rho, double nu)
    : mesh_(mesh),
      U_(U),
      p_(p),
      rho_(rho),
      nu_(nu),
      footprint_(coupling::VoidFractionMethod::centre),
      voidFraction_(derivedField(mesh, "voidfraction", true), mesh,
                    Foam::dimensionedScalar("one", Foam::dimless, 1), derivedPatchTypes(mesh)),
      Ksl_(derivedField(mesh, "Ksl", true), mesh,
           Foam::dimensionedScalar("zero", Foam::dimensionSet(1, -3, -1, 0, 0), 0),
           derivedPatchTypes(mesh)),
      KslUs_(derivedField(mesh, "KslUs", false), mesh,
             Foam::dimensionedVector("zero", Foam::dimensionSet(1, -2, -2, 0, 0), Foam::Zero),
             derivedPatchTypes(mesh)),
      fExplicit_(derivedField(mesh, "fParticles", false), mesh,
                 Foam::dimensionedVector("zero", Foam::dimensionSet(1, -2, -2, 0, 0), Foam::Zero),
                 derivedPatchTypes(mesh)),
      dragVoidFraction_(derivedField(mesh, "dragVoidFraction", false), mesh,
                        Foam::dimensionedScalar("one", Foam::dimless, 1), derivedPatchTypes(mesh)) {
  using namespace Foam;
  IOdictionary dict(IOobject("couplingProperties", mesh.time().constant(), mesh,
                             IOobject::MUST_READ_IF_MODIFIED, IOobject::NO_WRITE));

  // --- settings -------------------------------------------------------------------
  // OpenFOAM keeps the last of two entries with one key, silently: read the file once more,
  // with duplicates an error, and refuse a key given twice at both its lines.
  {
    const fileName file = dict.filePath();
    dictionary entries;
    const bool wasThrowing = FatalIOError.throwExceptions();
    try {
      IFstream is(file);
      entries.name() = is.name();
      while (!is.eof() && entry::New(entries, is, entry::inputMode::ERROR, 0)) {
      }
      FatalIOError.throwExceptions(wasThrowing);
    } catch (const IOerror& e) {
      FatalIOError.throwExceptions(wasThrowing);
      const std::string text = e.message();
      const std::string::size_type at = text.find("duplicate entry: ");
      if (at == std::string::npos) throw;
      std::string key = text.substr(at + 17);
      key.erase(key.find_last_not_of(" \n\t") + 1);
      const entry* first = entries.findEntry(key, keyType::LITERAL);
      const std::string message =
          "key '" + key + "' is given twice (at line " +
          (first ? std::to_string(first->startLineNumber()) + " and line " : std::string()) +
          std::to_string(e.ioStartLineNumber()) +
          "); OpenFOAM would silently take the last one: keep only the one you mean";
      FatalIOErrorInFunction(dict) << message.c_str() << exit(FatalIOError);
    }
  }
  // A misspelt key would silently fall back to its default: refuse unknown keys.
  {
    const wordList allowed{"scene",
                           "voidFraction",
                           "dividedResolution",
                           "smoothingFactor",
                           "sampling",
                           "minVoidFraction",
                           "ddtVoidFraction",
                           "undisturbedVelocity",
                           "meanPressureGradient",
                           "dragVoidFraction",
                           "facePressure",
                           "diffusionBandwidth",
                           "allowLargeTimeStep"};
    std::vector<std::string> names;
    for (const word& a : allowed) names.push_back(a);
    for (const word& key : dict.toc())
      if (!allowed.found(key)) {
        std::string list;
        for (const std::string& a : names) list += (list.empty() ? "" : ", ") + a;
        const entry* e = dict.findEntry(key, keyType::LITERAL);
        // Plain text (an OpenFOAM stream quotes a std::string).
        const std::string text =
            "unknown key '" + std::string(key) + "'" +
            (e ? " at line " + std::to_string(e->startLineNumber()) : std::string()) +
            grainflow::suggestion(key, names) + "; allowed: " + list;
        FatalKeyError(dict, key.c_str()) << text.c_str() << exit(FatalIOError);
      }
  }
  // The scene, relative to the case folder (not processorN/), expanded as OpenFOAM expands a
  // file name (stringOps::inplaceExpand: $VAR and ${VAR} from the environment, a leading
  // <case>/, <constant>/, <system>/ or ~/), except a leading "./", which OpenFOAM takes from
  // the working directory and grainFoam, as any relative path, from the case folder.
  const fileName caseDir = mesh.time().rootPath() / mesh.time().globalCaseName();
  const fileName scene = dict.get<fileName>("scene");
  std::string expanded = scene;
  std::string expandError;  // OpenFOAM's message for a variable it cannot expand
  if (expanded.rfind("./", 0) == 0) expanded.erase(0, 2);
  {
    const bool wasThrowing = FatalError.throwExceptions();
    try {
      stringOps::inplaceExpand(expanded, false);
    } catch (const error& e) {
      expandError = e.message();
      expandError.erase(expandError.find_last_not_of(" \n\t") + 1);
    }
    FatalError.throwExceptions(wasThrowing);
  }
  fileName sceneFile(expanded);
  if (!sceneFile.isAbsolute()) sceneFile = caseDir / sceneFile;

  const word method = dict.lookupOrDefault<word>("voidFraction", "divided");
  coupling::VoidFractionMethod vf = coupling::VoidFractionMethod::divided;
  try {
    vf = coupling::parse_void_fraction_method(method);
    voidFractionMethod_ = method;
  } catch (const std::invalid_argument& e) {
    FatalKeyError(dict, "voidFraction") << "voidFraction: " << e.what() << exit(FatalIOError);
  }
  const label resolution = dict.lookupOrDefault<label>("dividedResolution", 5);
  const scalar smoothing = dict.lookupOrDefault<scalar>("smoothingFactor", 2.0);
  if (resolution < 2 || resolution > 15)
    FatalKeyError(dict, "dividedResolution")
        << "dividedResolution " << resolution << " is outside [2, 15] (points across a diameter)"
        << exit(FatalIOError);
  if (smoothing < 1 || smoothing > 2)
    FatalKeyError(dict, "smoothingFactor")
        << "smoothingFactor " << typed(smoothing).c_str()
        << " is outside [1, 2] (kernel radius in particle radii; "
           "the ghost range covers at most 2 radii)"
        << exit(FatalIOError);
  // A key of another method is a setting with no effect: said (a sweep over the methods may
  // keep one case's keys).
  if (dict.found("dividedResolution") && vf != coupling::VoidFractionMethod::divided)
    Info << "grainFoam coupling: warning: dividedResolution (constant/couplingProperties line "
         << keyLines(dict, "dividedResolution").first
         << ") is a setting of voidFraction divided and has no effect with voidFraction " << method
         << endl;
  if (dict.found("smoothingFactor") && vf != coupling::VoidFractionMethod::smoothed)
    Info << "grainFoam coupling: warning: smoothingFactor (constant/couplingProperties line "
         << keyLines(dict, "smoothingFactor").first
         << ") is a setting of voidFraction smoothed and has no effect with voidFraction " << method
         << endl;
  footprint_ = coupling::Footprint(vf, static_cast<int>(resolution), smoothing);
  {
    // The footprint's spread per axis in particle radii: its points' standard deviation.
    double m2 = 0, w = 0;
    for (const coupling::FootprintPoint& q : footprint_.unit_points()) {
      for (int a = 0; a < 3; ++a) m2 += q.weight * q.offset[a] * q.offset[a];
      w += q.weight;
    }
    footprintSpread_ = w > 0 ? std::sqrt(m2 / (3 * w)) : 0;
  }

  const word sampling = dict.lookupOrDefault<word>("sampling", "cell");
  if (sampling == "cell")
    sampling_ = Sampling::cell;
  else if (sampling == "cellPoint")
    sampling_ = Sampling::cellPoint;
  else
    FatalKeyError(dict, "sampling") << "sampling " << sampling
                                    << " is not one of: cell (footprint-weighted cell values), "
                                       "cellPoint (interpolated at the particle centre; the "
                                       "exchange is balanced with either, docs/coupling.md)"
                                    << exit(FatalIOError);
  minVoidFraction_ = dict.lookupOrDefault<scalar>("minVoidFraction", 0.2);
  if (minVoidFraction_ < 0.2 || minVoidFraction_ >= 1)
    FatalKeyError(dict, "minVoidFraction")
        << "minVoidFraction " << typed(minVoidFraction_).c_str()
        << " is outside [0.2, 1) (the drag laws are tested down to "
           "0.2)"
        << exit(FatalIOError);
  ddtVoidFraction_ = dict.lookupOrDefault<Switch>("ddtVoidFraction", true);
  const word undisturbed = dict.lookupOrDefault<word>("undisturbedVelocity", "off");
  if (undisturbed == "oseenBrinkman")
    undisturbed_ = true;
  else if (undisturbed != "off")
    FatalKeyError(dict, "undisturbedVelocity")
        << "undisturbedVelocity " << undisturbed
        << " is not one of: off (drag on the sampled velocity), "
           "oseenBrinkman (drag on the sampled velocity minus the "
           "particle's own disturbance, docs/models/"
           "undisturbed-velocity.md)"
        << exit(FatalIOError);

  const word meanGradP = dict.lookupOrDefault<word>("meanPressureGradient", "off");
  if (meanGradP == "suspensionWeight")
    meanGradPOn_ = true;
  else if (meanGradP != "off")
    FatalKeyError(dict, "meanPressureGradient")
        << "meanPressureGradient " << meanGradP
        << " is not one of: off (the pressure gradient is the "
           "solved one), suspensionWeight (a uniform pressure "
           "gradient carries the particles' buoyant weight, for a "
           "domain periodic along gravity; docs/coupling.md)"
        << exit(FatalIOError);

  // A DEM step the time-step check refuses stops grainFoam at start-up, as `grain run`
  // without --allow-large-dt; `allowLargeTimeStep yes` starts it anyway.
  allowLargeTimeStep_ = dict.lookupOrDefault<Switch>("allowLargeTimeStep", false);

  const word dragEps = dict.lookupOrDefault<word>("dragVoidFraction", "cell");
  if (dragEps == "sharpInterface")
    sharpInterface_ = true;
  else if (dragEps != "cell")
    FatalKeyError(dict, "dragVoidFraction")
        << "dragVoidFraction " << dragEps
        << " is not one of: cell (the drag sees the cell's void "
           "fraction and velocity), sharpInterface (a cell between a "
           "denser and a more dilute neighbour is read as two layers "
           "of their states: the drag sees the layers' solid-weighted "
           "void fraction and the velocity at the cell's superficial "
           "velocity, docs/models/bed-surface.md)"
        << exit(FatalIOError);
  if (sharpInterface_ && sampling_ != Sampling::cell)
    FatalKeyError(dict, "dragVoidFraction")
        << "dragVoidFraction sharpInterface needs sampling cell (it "
           "scales the cells' velocities before the footprint-weighted "
           "average); set sampling cell or dragVoidFraction cell"
        << exit(FatalIOError);
  if (sharpInterface_ && undisturbed_)
    FatalKeyError(dict, "dragVoidFraction")
        << "dragVoidFraction sharpInterface and undisturbedVelocity "
           "oseenBrinkman are not combined (the disturbance model "
           "reads the cells' unscaled Ksl); switch one of them off"
        << exit(FatalIOError);

  const word facePressure = dict.lookupOrDefault<word>("facePressure", "linear");
  if (facePressure == "dragSeries")
    dragSeriesPressure_ = true;
  else if (facePressure != "linear")
    FatalKeyError(dict, "facePressure")
        << "facePressure " << facePressure
        << " is not one of: linear (the momentum equation's cell "
           "pressure gradient is Gauss linear), dragSeries (the face "
           "pressure between two cells crossed in series with their "
           "drag resistances, docs/models/bed-surface.md)"
        << exit(FatalIOError);

  const scalar bandwidth = dict.lookupOrDefault<scalar>("diffusionBandwidth", 0.0);
  if (bandwidth < 0)
    FatalKeyError(dict, "diffusionBandwidth")
        << "diffusionBandwidth " << typed(bandwidth).c_str()
        << " is negative; it is the bandwidth b [m] of the "
           "diffusion-based averaging (Gaussian exp(-r^2/b^2)), 0 "
           "for none"
        << exit(FatalIOError);
  if (bandwidth > 0) {
    if (sharpInterface_)
      FatalKeyError(dict, "diffusionBandwidth")
          << "diffusionBandwidth " << bandwidth
          << " is not combined with dragVoidFraction "
             "sharpInterface (the layers are read from the cells' own void fractions, which "
             "the averaging spreads); set diffusionBandwidth 0 or dragVoidFraction cell"
          << exit(FatalIOError);
    smoothing_ = std::make_unique<DiffusionSmoothing>(mesh, bandwidth, kMaxSmoothingSteps);
    if (!(smoothing_->neededSteps() <= kMaxSmoothingSteps)) {
      // The largest b to 4 significant digits, rounded down: typed back, it is allowed.
      const double largest = smoothing_->maxBandwidth();
      const double unit = std::pow(10.0, std::floor(std::log10(largest)) - 3);
      std::ostringstream m;
      m.precision(4);
      m << "diffusionBandwidth " << bandwidth << " m would take " << smoothing_->neededSteps()
        << " explicit diffusion steps per field and fluid step on this mesh; allowed: 0 "
           "(none) or 0 < b <= "
        << std::floor(largest / unit) * unit << " m (at most " << kMaxSmoothingSteps
        << " steps; b is a length in metres, typically a few particle diameters: 2.83 d is "
           "the tested value)";
      FatalKeyError(dict, "diffusionBandwidth") << m.str().c_str() << exit(FatalIOError);
    }
    Info << "grainFoam coupling: diffusionBandwidth b = " << bandwidth
         << " m: eps, Ksl, KslUs, fParticles and the fluid the particles read are averaged "
            "by diffusion to pseudo-time b^2/4 (Gaussian exp(-r^2/b^2), sigma = b/sqrt(2) = "
         << bandwidth / std::sqrt(2.0) << " m) in " << smoothing_->steps()
         << " explicit steps, each giving away at most " << smoothing_->stepRate()
         << " of a cell's value (Sun & Xiao 2015)" << endl;
    const auto work = [&mesh](const char* name) {
      return std::make_unique<volVectorField>(
          derivedField(mesh, name, false), mesh,
          dimensionedVector("zero", dimless, Zero), derivedPatchTypes(mesh));
    };
    smoothU_ = work("smoothedU");
    smoothGradP_ = work("smoothedGradP");
    smoothDivTau_ = work("smoothedDivTau");
    smoothCurlU_ = work("smoothedCurlU");
  }

  // The settings that shape the deposited eps and Ksl, recorded with each write time: a
  // restart's differing written fields can then be put down to the setting that changed.
  {
    std::ostringstream o;
    o.precision(17);
    o << "voidFraction " << method << "; dividedResolution " << resolution << "; smoothingFactor "
      << smoothing << "; minVoidFraction " << minVoidFraction_ << "; diffusionBandwidth "
      << bandwidth << "; dragVoidFraction " << dragEps << "; undisturbedVelocity " << undisturbed
      << "; sampling " << sampling << "; facePressure " << facePressure;
    depositSettings_ = o.str();
  }

  // --- the DEM ----------------------------------------------------------------------
  if (!sceneFile.isAbsolute()) sceneFile = cwd() / sceneFile;
  if (!expandError.empty() || !isFile(sceneFile)) {
    const entry* e = dict.findEntry("scene", keyType::LITERAL);
    std::string text = "scene \"" + std::string(scene) + "\"" +
                       (e ? " (line " + std::to_string(e->startLineNumber()) + ")" : std::string());
    const std::string expansion =
        "OpenFOAM's file-name expansion takes $NAME and ${NAME} from the environment, and a "
        "leading <case>/, <constant>/, <system>/ or ~/";
    if (!expandError.empty()) {
      // OpenFOAM's "Unknown variable 'NAME'": the name.
      const std::string::size_type a = expandError.find('\''), b = expandError.rfind('\'');
      text += ": cannot be expanded: " +
              (a != std::string::npos && b > a ? "variable " + expandError.substr(a, b - a + 1) +
                                                     " is not set in the environment"
                                               : expandError) +
              " (" + expansion + ")";
    } else {
      const std::string shown =
          std::string(sceneFile) + (expanded != std::string(scene)
                                        ? " (expanded from \"" + std::string(scene) + "\")"
                                        : std::string());
      if (isDir(sceneFile)) {
        std::string yaml;
        for (const fileName& f : readDir(sceneFile, fileName::FILE))
          if (f.ext() == "yaml" || f.ext() == "yml")
            yaml += (yaml.empty() ? "" : ", ") + std::string(f);
        text += ": " + shown + " is a directory, not a scene file; name the scene's YAML file " +
                (yaml.empty() ? std::string("(it holds no .yaml file)")
                              : "in it (it holds " + yaml + ")");
      } else {
        text += ": no such file " + shown;
        if (expanded.find('$') != std::string::npos)
          text += "; the path still holds a '$' after expansion (" + expansion +
                  "; a malformed name such as $(NAME) is left as it is)";
      }
    }
    text += "; a relative path is taken from the case folder (" + std::string(caseDir) + ")";
    FatalKeyError(dict, "scene") << text.c_str() << exit(FatalIOError);
  }
  try {
    dem_ = std::make_unique<coupling::DemLink>(sceneFile, rho_, rho_ * nu_, MPI_COMM_WORLD);
    dem_->correct_self_disturbance(undisturbed_);
  } catch (const std::exception& e) {
    FatalErrorInFunction << "\n" << e.what() << exit(FatalError);
  }
  if (smoothing_ && dem_->heat_on())
    FatalKeyError(dict, "diffusionBandwidth")
        << "diffusionBandwidth is not combined with the scene's heat: "
           "block (the heat exchange is deposited and sampled "
           "without the averaging); set diffusionBandwidth 0"
        << exit(FatalIOError);
  // OpenFOAM's own place for gravity: grainFoam takes it from the scene, so a constant/g that
  // says otherwise would be a setting with no effect.
  {
    IOobject gHeader("g", mesh.time().constant(), mesh, IOobject::READ_IF_PRESENT,
                     IOobject::NO_WRITE, false);
    if (gHeader.typeHeaderOk<uniformDimensionedVectorField>(true)) {
      const uniformDimensionedVectorField g(gHeader);
      const std::array<double, 3> sg = dem_->gravity();
      const double size = std::max({mag(g.value()), std::hypot(sg[0], sg[1], sg[2]), 1e-300});
      const auto text = [](double x, double y, double z) {
        std::ostringstream o;
        o << '(' << x << ' ' << y << ' ' << z << ')';
        return o.str();
      };
      if (mag(g.value() - vector(sg[0], sg[1], sg[2])) > 1e-12 * size)
        FatalErrorInFunction
            << "constant/g is " << text(g.value().x(), g.value().y(), g.value().z()).c_str()
            << " m/s^2 but the scene's gravity is " << text(sg[0], sg[1], sg[2]).c_str()
            << " m/s^2 (gravity: in " << sceneFile
            << "); grainFoam takes gravity from the scene and does not read "
               "constant/g. Set `gravity:` in the scene to the value you want, and remove "
               "constant/g (or make it equal)"
            << exit(FatalError);
    }
  }
  model_ = dem_->vans_model();
  domain_ = dem_->domain();
  periodic_ = dem_->periodic();
  domainVolume_ = (domain_.hi[0] - domain_.lo[0]) * (domain_.hi[1] - domain_.lo[1]) *
                  (domain_.hi[2] - domain_.lo[2]);
  if (meanGradPOn_) {
    // Only a box periodic along gravity needs (and can hold) the uniform part: elsewhere a
    // wall or an outlet carries the weight through the solved pressure.
    const std::array<double, 3> g = dem_->gravity();
    const double gMag = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    static const char* axis = "xyz";
    for (int a = 0; a < 3; ++a)
      if (g[a] != 0 && !periodic_[a])
        FatalKeyError(dict, "meanPressureGradient")
            << "meanPressureGradient suspensionWeight: gravity has a component along " << axis[a]
            << " but the scene's domain is not periodic along " << axis[a]
            << " (domain.periodic); there the walls carry the weight through the solved "
               "pressure. Set meanPressureGradient off, or make the domain and the mesh "
               "periodic along every axis gravity has a component on"
            << exit(FatalIOError);
    forAll(mesh.boundary(), patch) {
      const fvPatch& fp = mesh.boundary()[patch];
      if (fp.coupled() || fp.size() == 0 || gMag == 0) continue;
      const vectorField n(fp.nf());
      for (const vector& v : n)
        if (std::abs(v[0] * g[0] + v[1] * g[1] + v[2] * g[2]) > 1e-6 * gMag)
          FatalKeyError(dict, "meanPressureGradient")
              << "meanPressureGradient suspensionWeight: patch " << fp.name() << " (type "
              << fp.type()
              << ") has faces across gravity; the uniform pressure gradient "
                 "needs a mesh periodic (cyclic) along gravity. Set meanPressureGradient off, "
                 "or make that patch cyclic"
              << exit(FatalIOError);
    }
  }

  // --- the shared decomposition -----------------------------------------------------
  boundBox local(mesh.points(), false);
  coupling::Box mine{toArray(local.min()), toArray(local.max())};
  int ranks = 1, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  std::vector<double> flat(6 * static_cast<std::size_t>(ranks));
  double mine_flat[6] = {mine.lo[0], mine.lo[1], mine.lo[2], mine.hi[0], mine.hi[1], mine.hi[2]};
  MPI_Allgather(mine_flat, 6, MPI_DOUBLE, flat.data(), 6, MPI_DOUBLE, MPI_COMM_WORLD);
  std::vector<coupling::Box> boxes(static_cast<std::size_t>(ranks));
  for (int r = 0; r < ranks; ++r)
    for (int a = 0; a < 3; ++a) {
      boxes[r].lo[a] = flat[6 * r + a];
      boxes[r].hi[a] = flat[6 * r + 3 + a];
    }
  coupling::ProcessorGrid grid;
  try {
    grid = coupling::processor_grid_from_boxes(boxes, rank, domain_);
  } catch (const coupling::DecompositionMismatch& e) {
    FatalErrorInFunction << "shared decomposition: " << e.what() << exit(FatalError);
  }
  // The rank's cells must fill its box (no holes: a box-shaped mesh).
  const double boxVolume = (mine.hi[0] - mine.lo[0]) * (mine.hi[1] - mine.lo[1]) *
                           (mine.hi[2] - mine.lo[2]);
  const double localVolume = sum(mesh.V().field());
  if (std::abs(localVolume - boxVolume) > 1e-9 * boxVolume)
    FatalErrorInFunction << "shared decomposition: processor " << rank << "'s cells have volume "
                         << localVolume << " m^3 but their bounding box has " << boxVolume
                         << " m^3; the coupling needs a box-shaped mesh whose processor "
                            "meshes are boxes (decomposeParDict method simple or hierarchical)"
                         << exit(FatalError);
  checkPeriodicSides(mesh, sceneFile);
  dem_->use_processor_grid(grid);
  // The scene's output.directory, relative to the case folder (not processorN/), or
  // <case>/particles.
  {
    const fileName given(dem_->output_directory());
    snapshotDir_ = given.empty() ? caseDir / "particles" : given.isAbsolute() ? given : caseDir / given;
  }
  // Snapshots, checkpoints and diagnostics go there: a read-only or full disk fails now,
  // not at the first write time.
  try {
    grainflow::prepare_output_directory(snapshotDir_);
  } catch (const std::exception& e) {
    FatalErrorInFunction << "\n" << e.what() << exit(FatalError);
  }

  // --- restart: a time that grainFoam wrote names its DEM checkpoint ------------------
  restartIndex_ = mesh.time().timeIndex();
  // A time folder grainFoam did not write (a copy of 0, a folder whose uniform/ was lost)
  // has time index 0: the DEM would start afresh from the scene at t = 0 while the fluid
  // goes on from the folder's time.
  if (restartIndex_ == 0 && std::abs(mesh.time().value()) > 1e-6 * mesh.time().deltaTValue()) {
    const fileName uniform = mesh.time().timePath() / "uniform";
    std::string missing;
    for (const char* name : {"time", "grainflowCheckpoint"})
      if (!isFile(uniform / name))
        missing += std::string(missing.empty() ? "" : " and ") + "uniform/" + name;
    const word startFrom = mesh.time().controlDict().lookupOrDefault<word>("startFrom", "?");
    FatalErrorInFunction
        << "grainFoam: error: the run starts at time " << mesh.time().timeName()
        << " (system/controlDict: startFrom " << startFrom.c_str() << "), but time folder "
        << mesh.time().timeName() << " was not written by grainFoam: "
        << (missing.empty() ? std::string("its time index is 0")
                            : "it has no " + missing + " (in " + std::string(uniform) + ")")
               .c_str()
        << ". A restart continues the DEM from the checkpoint a written time names; without "
           "one the DEM would start afresh from the scene at t = 0 while the fluid goes on from "
        << mesh.time().timeName()
        << ". Restart from a time grainFoam wrote (startFrom startTime; startTime <that "
           "time>), or start afresh from time 0 (startFrom startTime; startTime 0; with "
           "startFrom latestTime, remove or rename folder "
        << mesh.time().timeName() << ")" << exit(FatalError);
  }
  if (restartIndex_ > 0) {
    const IOdictionary info(IOobject("grainflowCheckpoint", mesh.time().timeName(), "uniform",
                                     mesh.time(), IOobject::READ_IF_PRESENT,
                                     IOobject::NO_WRITE, false));
    if (!info.found("checkpoint"))
      FatalErrorInFunction
          << "starting at time " << mesh.time().timeName() << " (time index " << restartIndex_
          << "), but " << info.objectPath()
          << " is missing: grainFoam restarts from a time that it wrote itself (at every "
             "write time it writes the DEM checkpoint particles/checkpoint_<DEM step>.h5 and "
             "names it there). Start from time 0, or from a time written by grainFoam"
          << exit(FatalError);
    const fileName checkpoint = snapshotDir_ / info.get<word>("checkpoint");
    // The checkpoint must be the one written with this time: another run sharing the output
    // directory, or a particles/ folder copied from elsewhere, holds a valid checkpoint of the
    // same step with other particles.
    if (info.found("checkpointChecksum") && isFile(checkpoint)) {
      const word recorded = info.get<word>("checkpointChecksum");
      const std::string now = "fnv1a64_" + checkpointChecksum(checkpoint);
      if (now != recorded)
        FatalErrorInFunction
            << "restart from time " << mesh.time().timeName() << ": " << checkpoint.c_str()
            << " is not the DEM checkpoint grainFoam wrote with this time: its checksum is "
            << now.c_str() << ", " << info.objectPath().c_str() << " records " << recorded
            << ". Another run may have written over it (an output.directory shared by two "
               "cases), or it was copied from elsewhere. Put back the checkpoint of this run, "
               "or restart from another time. If you changed it on purpose, delete the line "
               "checkpointChecksum from that file"
            << (Pstream::parRun() ? " in every processor folder" : "")
            << ", and that file's line from " << mesh.time().timeName() << "/"
            << coupling::kWrittenFilesRecord << exit(FatalError);
    }
    try {
      dem_->restore(checkpoint);
    } catch (const std::exception& e) {
      FatalErrorInFunction << "restart from time " << mesh.time().timeName() << ":\n"
                           << e.what() << exit(FatalError);
    }
    Info << "grainFoam coupling: restart at time " << mesh.time().timeName() << " (time index "
         << restartIndex_ << ") from the DEM checkpoint " << checkpoint << endl;
  }
  try {
    dem_->initialise();
  } catch (const std::exception& e) {
    FatalErrorInFunction << "\n" << e.what() << exit(FatalError);
  }
  // Each fluid force's stability limit, as grain check prints it (fluid at rest: the DEM
  // starts before the first fluid sample); a step beyond an explicit force's limit stops here.
  for (const std::string& note : dem_->force_limit_notes()) {
    if (note.rfind("error:", 0) == 0) FatalErrorInFunction << "\n" << note << exit(FatalError);
    Info << "grainFoam coupling: " << note.c_str() << endl;
  }
  // The DEM's own start-up findings, as `grain check` prints them (time step and contacts,
  // meshes, insertions, settings without effect); a DEM step the check refuses stops here.
  const std::string refusal = dem_->time_step_refusal(mesh.time().deltaTValue());
  for (const std::string& note : dem_->startup_notes()) {
    if (!refusal.empty() && allowLargeTimeStep_ && note.rfind("error: ", 0) == 0)
      Info << "grainFoam DEM: warning: " << note.substr(7).c_str()
           << " (running anyway: allowLargeTimeStep yes)" << endl;
    else
      Info << "grainFoam DEM: " << note.c_str() << endl;
  }
  if (!refusal.empty() && !allowLargeTimeStep_)
    FatalErrorInFunction << "\n" << refusal.c_str() << exit(FatalError);

  if (meanGradPOn_) {
    updateMeanPressureGradient();
    Info << "grainFoam coupling: meanPressureGradient suspensionWeight: G = " << meanGradP_
         << " Pa/m, the particles' buoyant weight sum (m - rho_f V) g over the domain's "
         << domainVolume_ << " m^3 (the fluid gets -c G, the particles -V_p G)" << endl;
  }

  // --- the time-step ratio ----------------------------------------------------------
  const Time& time = mesh.time();
  if (time.controlDict().lookupOrDefault<Switch>("adjustTimeStep", false))
    FatalIOErrorInFunction(time.controlDict())
        << "adjustTimeStep yes: the coupling needs a fixed deltaT, an integer multiple of "
           "the DEM time step"
        << exit(FatalIOError);
  const double dtFluid = time.deltaTValue(), dtDem = dem_->time_step();
  const double ratio = dtFluid / dtDem;
  // As one types them back (typed: 12 digits, 3 x 1e-05 is 3e-05, not 3.0000000000000004e-05).
  if (!(dtFluid > 0))
    FatalIOErrorInFunction(time.controlDict())
        << "deltaT " << typed(dtFluid).c_str() << " s must be positive: a whole number of DEM "
        << "steps of " << typed(dtDem).c_str() << " s (the scene's time step), e.g. deltaT "
        << typed(dtDem).c_str() << exit(FatalIOError);
  // The ratio must be whole to round-off (kRatioTolerance): the DEM advances N x dt_DEM per
  // fluid step, so a ratio off by r puts it r dt_CFD behind the fluid at every step, and the
  // restart check below, which allows what start-up allowed, would otherwise refuse the run's
  // own restart after enough steps.
  subSteps_ = static_cast<int>(std::min(std::lround(ratio), long(INT_MAX)));
  if (subSteps_ < 1 || std::abs(ratio - subSteps_) > kRatioTolerance * ratio) {
    const long below = std::lround(std::floor(ratio)), above = std::lround(std::ceil(ratio));
    std::string use = "deltaT " + typed(above * dtDem);
    if (below >= 1) use = "deltaT " + typed(below * dtDem) + " or " + use;
    // The DEM step that divides deltaT exactly, with every digit it needs.
    std::ostringstream exact;
    exact.precision(17);
    const long nearest = std::max(1L, std::lround(ratio));
    exact << "time.step " << dtFluid / nearest << " (deltaT / " << nearest << ")";
    FatalIOErrorInFunction(time.controlDict())
        << "deltaT " << typed(dtFluid).c_str() << " s is " << typed(ratio).c_str()
        << " DEM steps of " << typed(dtDem).c_str()
        << " s (the scene's time step); dt_CFD / dt_DEM must be an integer to round-off "
           "(relative "
        << kRatioTolerance << "): use " << use.c_str() << ", or set the scene's "
        << exact.str().c_str() << exit(FatalIOError);
  }
  if (restartIndex_ > 0) {
    // What start-up allows, accumulated over the run's steps, plus the time's own round-off.
    const double allowed = 1e-6 * dtFluid + 2 * kRatioTolerance * dtFluid * restartIndex_;
    const double timeOff = std::abs(dem_->time() - time.value());
    const long steps = dem_->steps();
    if (steps != restartIndex_ * subSteps_ || timeOff > allowed) {
      std::ostringstream m;
      m.precision(17);
      m << "grainFoam: error: restart at time " << time.timeName() << " (time index "
        << restartIndex_ << "): the DEM checkpoint is at step " << steps << " (t = " << dem_->time()
        << " s), but " << restartIndex_ << " fluid steps of deltaT ";
      m.precision(12);
      m << dtFluid << " s (system/controlDict) are DEM step " << restartIndex_ * subSteps_ << " ("
        << subSteps_ << " DEM steps of " << dtDem << " s per fluid step). ";
      const long runSub = steps % restartIndex_ == 0 ? steps / restartIndex_ : 0;
      if (timeOff <= allowed && runSub > 0) {
        // Same time, other step count: deltaT (or time.step with it) changed.
        m << "This time was run with " << runSub << " DEM steps per fluid step, deltaT "
          << runSub * (dem_->time() / steps)
          << " s. A restart continues with the deltaT and "
             "the time.step its time was run with: set deltaT "
          << runSub * (dem_->time() / steps)
          << " in system/controlDict (and the scene's time.step as it was) to restart. To run "
             "on with another deltaT, start a new run from time 0 (startFrom startTime; "
             "startTime 0); to keep the particles, insert this run's snapshot of this time "
             "with `type: snapshot` (docs/scene-reference.md) and copy the fluid fields into 0/";
      } else {
        m << "The checkpoint belongs to another time: restart from a time whose checkpoint "
             "is this run's, or start from time 0";
      }
      FatalErrorInFunction << m.str().c_str() << exit(FatalError);
    }
  }
  // A fresh run writes its snapshots and checkpoints over those of an earlier run in the
  // same folder (under the same names): said, with the time folders that name them.
  if (restartIndex_ == 0 && Pstream::master()) {
    long snapshotFiles = 0, checkpointFiles = 0;
    std::error_code error;
    for (const auto& e : std::filesystem::directory_iterator(std::string(snapshotDir_), error)) {
      const std::string name = e.path().filename().string();
      const bool h5 = name.size() > 3 && name.compare(name.size() - 3, 3, ".h5") == 0;
      if (h5 && name.rfind("particles_", 0) == 0) ++snapshotFiles;
      if (h5 && name.rfind("checkpoint_", 0) == 0) ++checkpointFiles;
    }
    if (snapshotFiles + checkpointFiles > 0) {
      std::string naming;
      int listed = 0;
      for (const auto& [folder, name] :
           keptTimeFolders(mesh.time().rootPath() / mesh.time().globalCaseName()))
        if (!name.empty() && isFile(snapshotDir_ / name)) {
          naming += (listed ? ", " : "") + folder;
          ++listed;
        }
      Info << "grainFoam coupling: note: " << snapshotDir_.c_str() << " holds " << snapshotFiles
           << " snapshot(s) and " << checkpointFiles
           << " checkpoint(s) of an earlier run; this run starts at time 0 and writes its own "
              "over those of the same names (the snapshots from the first, the checkpoints "
              "at its write times)";
      if (listed > 0)
        Info << "; time folder(s) " << naming.c_str()
             << " name checkpoints there, and cannot be restarted from once theirs is "
                "written over. To keep them, give this run another output.directory in the "
                "scene, or copy the case first";
      Info << endl;
    }
  }

  // --- output.snapshot_interval: snapshots at fluid steps, the first at or after each
  // multiple of the interval (within half a fluid step, as grain does with its steps) ----
  snapshotInterval_ = dem_->snapshot_interval();
  if (snapshotInterval_ > 0 && snapshotInterval_ < dtFluid * (1 - 1e-9)) {
    std::ostringstream why;  // 6 digits, not the case's writePrecision
    why << dem_->snapshot_interval_source() << ": error: output.snapshot_interval "
        << snapshotInterval_ << " s is shorter than the fluid time step deltaT " << dtFluid
        << " s (system/controlDict): grainFoam writes snapshots after fluid steps; use an "
           "interval of at least deltaT";
    FatalErrorInFunction << "\n" << why.str().c_str() << exit(FatalError);
  }
  if (snapshotInterval_ > 0)
    snapshotIndex_ =
        static_cast<long>(std::floor((time.value() + 0.5 * dtFluid) / snapshotInterval_));

  // --- cell location: structured fast path when the local mesh is a uniform grid ----
  {
    const cellList& cells = mesh.cells();
    const label n = mesh.nCells();
    if (n > 0) {
      const boundBox first(mesh.points(), cells[0].labels(mesh.faces()), false);
      std::array<double, 3> h = toArray(first.max() - first.min());
      bool ok = true;
      for (int a = 0; a < 3; ++a) {
        gridLo_[a] = mine.lo[a];
        // One spacing for all ranks: the domain length over the global cell count.
        const double length = domain_.hi[a] - domain_.lo[a];
        gridH_[a] = length / static_cast<double>(std::max(1L, std::lround(length / h[a])));
        gridOffset_[a] = static_cast<int>(std::lround((mine.lo[a] - domain_.lo[a]) / gridH_[a]));
        gridN_[a] = static_cast<int>(std::lround((mine.hi[a] - mine.lo[a]) / h[a]));
        if (gridN_[a] < 1 || std::abs(gridN_[a] * h[a] - (mine.hi[a] - mine.lo[a])) >
                                 1e-9 * (mine.hi[a] - mine.lo[a]))
          ok = false;
      }
      if (ok && static_cast<long>(gridN_[0]) * gridN_[1] * gridN_[2] == n) {
        gridCell_.assign(static_cast<std::size_t>(n), -1);
        for (label c = 0; c < n && ok; ++c) {
          if (cells[c].size() != 6) ok = false;
          const boundBox bb(mesh.points(), cells[c].labels(mesh.faces()), false);
          std::array<int, 3> idx{};
          for (int a = 0; a < 3 && ok; ++a) {
            idx[a] = static_cast<int>(std::floor((bb.min()[a] - gridLo_[a]) / h[a] + 0.5));
            if (idx[a] < 0 || idx[a] >= gridN_[a] ||
                std::abs(bb.min()[a] - (gridLo_[a] + idx[a] * h[a])) > 1e-9 * h[a] ||
                std::abs(bb.max()[a] - bb.min()[a] - h[a]) > 1e-9 * h[a])
              ok = false;
          }
          if (!ok) break;
          const std::size_t k =
              (static_cast<std::size_t>(idx[2]) * gridN_[1] + idx[1]) * gridN_[0] + idx[0];
          if (gridCell_[k] != -1) ok = false;
          gridCell_[k] = c;
        }
      } else {
        ok = false;
      }
      structured_ = ok;
      if (!ok) gridCell_.clear();
    }
  }
  const label structuredRanks = returnReduce(label(structured_ ? 1 : 0), sumOp<label>());
  if (sampling_ == Sampling::cellPoint) {
    cellPointWeights_ = std::make_unique<CellPointWeights>(mesh);
    const label boxCells = returnReduce(cellPointWeights_->boxCells(), sumOp<label>());
    const double bytes = returnReduce(double(cellPointWeights_->bytes()), sumOp<double>());
    Info << "grainFoam coupling: cellPoint weights prepared for "
         << returnReduce(mesh.nCells(), sumOp<label>()) << " cells (" << boxCells
         << " boxes: closed form; the others: their tetrahedra), " << bytes / 1e6 << " MB" << endl;
    // The point values: all fields in one pass (pointInterpolation.H), bit for bit
    // volPointInterpolation's, unless the mesh has a patch type that class does not have.
    pointInterpolation_ = std::make_unique<PointInterpolation>(mesh);
    if (pointInterpolation_->unsupported().empty()) {
      Info << "grainFoam coupling: cellPoint point values of all fields in one pass ("
           << returnReduce(double(pointInterpolation_->bytes()), sumOp<double>()) / 1e6
           << " MB of weights)" << endl;
    } else {
      Info << "grainFoam coupling: cellPoint point values by volPointInterpolation, field by "
              "field ("
           << pointInterpolation_->unsupported().c_str() << ")" << endl;
      pointInterpolation_.reset();
    }
  }

  // --- the viscous term div(tau) = rho nu laplacian(U) at the particles ----------------
  // Its non-orthogonal correction (corrected snGrad: correction vectors . interpolated
  // grad U) needs grad U on the whole mesh, 30 % of the coupling's cost on the Goldschmidt
  // case. On a mesh whose correction vectors are round-off (every axis-aligned block mesh:
  // 6e-14 there) it changes the term by that relative amount only, so it is left out.
  double worstCorrection = 0;
  {
    const surfaceVectorField& k = mesh.nonOrthCorrectionVectors();
    for (const vector& v : k.primitiveField())
      worstCorrection = std::max(worstCorrection, double(mag(v)));
    for (const fvsPatchVectorField& patch : k.boundaryField())
      for (const vector& v : patch) worstCorrection = std::max(worstCorrection, double(mag(v)));
    reduce(worstCorrection, maxOp<double>());
  }
  const bool orthogonal = worstCorrection <= kOrthogonalCorrection;
  if (orthogonal)
    uncorrectedLaplacian_ =
        fv::laplacianScheme<vector, scalar>::New(mesh, IStringStream("Gauss linear uncorrected")());

  // --- grad p at the particles ---------------------------------------------------------
  // With the scheme Gauss linear (and grad(p) not cached) it is computed by
  // pressureGradient() in one pass into a kept field, OpenFOAM's operations in their order.
  {
    const word gradName("grad(" + p_.name() + ')');
    const ITstream& scheme = mesh.gradScheme(gradName);
    gaussLinearGrad_ = scheme.size() == 2 && scheme[0].isWord() &&
                       scheme[0].wordToken() == "Gauss" && scheme[1].isWord() &&
                       scheme[1].wordToken() == "linear" && !mesh.cache(gradName);
  }

  Info << "grainFoam coupling: scene " << sceneFile << "\n"
       << "  VANS model " << model_ << ", drag " << dem_->drag_law().c_str() << ", void fraction "
       << coupling::void_fraction_method_name(vf) << " (" << label(footprint_.size())
       << " points per particle), sampling " << sampling << ", minVoidFraction " << minVoidFraction_
       << ", ddt(voidfraction) " << (ddtVoidFraction_ ? "on" : "off") << ", dragVoidFraction "
       << (sharpInterface_ ? "sharpInterface" : "cell") << ", facePressure "
       << (dragSeriesPressure_ ? "dragSeries" : "linear") << "\n"
       << "  viscous term at the particles: "
       << (orthogonal ? "Gauss linear uncorrected (the mesh is orthogonal: largest "
                        "non-orthogonal correction vector "
                      : "the case's laplacian scheme (largest non-orthogonal correction "
                        "vector ")
       << worstCorrection << ")\n"
       << "  pressure gradient at the particles: "
       << (gaussLinearGrad_ ? "Gauss linear, in one pass" : "fvc::grad with the case's scheme")
       << "\n"
       << "  dt_CFD " << dtFluid << " s = " << subSteps_ << " x dt_DEM " << dtDem << " s\n"
       << "  processor grid " << grid.dims[0] << " x " << grid.dims[1] << " x " << grid.dims[2]
       << cutsText(grid).c_str() << "; cell location "
       << (structuredRanks == Pstream::nProcs() ? "uniform grid (direct)"
                                                : "octree search on some ranks")
       << endl;

  buildFootprints();
  deposit();
  if (restartIndex_ > 0) continueVoidFraction();

  // Where these settings sit on the measured curves: the regime (particle count, mean void
  // fraction in the particles' cells), the drag law, cell edge over mean diameter.
  {
    // diameters, particles, mesh volume, eps of the located particles' cells, located
    double sums[5] = {0, double(particles_.local()), 0, 0, 0};
    for (std::size_t i = 0; i < particles_.local(); ++i) {
      sums[0] += 2 * particles_.radius(i);
      if (centreCell_[i] < 0) continue;
      sums[3] += voidFraction_[centreCell_[i]];
      sums[4] += 1;
    }
    sums[2] = sum(mesh.V().field());
    MPI_Allreduce(MPI_IN_PLACE, sums, 5, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    const double cells = double(returnReduce(mesh.nCells(), sumOp<label>()));
    if (sums[1] > 0) {
      coupling::CoupledSettings settings;
      settings.mean_void_fraction = sums[4] > 0 ? sums[3] / sums[4] : 1;
      settings.regime = coupling::classify_regime(std::lround(sums[1]), settings.mean_void_fraction);
      settings.drag = dem_->drag_law();
      settings.method = method;
      settings.sampling = sampling;
      settings.cell_over_d = std::cbrt(sums[2] / cells) / (sums[0] / sums[1]);
      settings.steps_per_fluid = subSteps_;
      settings.drag_void_fraction = sharpInterface_ ? "sharpInterface" : "cell";
      if (smoothing_)
        settings.diffusion_bandwidth_over_d = smoothing_->bandwidth() / (sums[0] / sums[1]);
      Info << "  " << coupling::describe_coupled_accuracy(settings).c_str() << endl;
    }
    // Coarse-grained parcels against the cells (the rule of grain check; Radl et al. 2011).
    // Cell size: the cube root of a cell's volume, the smallest and that of the mean cell.
    const double smallest = std::cbrt(gMin(mesh.V().field()));
    for (const std::string& w : dem_->parcel_cell_warnings(smallest, std::cbrt(sums[2] / cells)))
      Info << "grainFoam coupling: " << w.c_str() << endl;
    for (const std::string& w : dem_->parcel_domain_warnings())
      Info << "grainFoam coupling: " << w.c_str() << endl;
    // voidFraction centre puts a particle's whole volume in the cell that holds its centre: a
    // particle wider than the cell would fill more than the cell, and the clamp at
    // minVoidFraction then removes the rest of its volume (and drag) from the fluid.
    if (voidFractionMethod_ == "centre") {
      double largest = 0;
      for (std::size_t i = 0; i < particles_.local(); ++i)
        largest = std::max(largest, 2 * particles_.radius(i));
      reduce(largest, maxOp<double>());
      const auto text = [](double x) {
        std::ostringstream o;
        o.precision(4);
        o << x;
        return o.str();
      };
      if (largest > smallest)
        Info << "grainFoam coupling: warning: particles up to " << text(largest).c_str()
             << " m across are wider than the smallest fluid cell (" << text(smallest).c_str()
             << " m, the cube root of its volume) and voidFraction is centre: each puts its "
                "whole volume into the one cell that holds its centre, where the clamp at "
                "minVoidFraction removes what does not fit (counted in the log, `void "
                "fraction clamped`). Use voidFraction divided (or smoothed), which spreads a "
                "particle over the cells it covers"
             << endl;
    }
  }

  voidFraction_.oldTime();  // keep old times for ddt(voidfraction)
}

void ParticleCoupling::continueVoidFraction() {
  // The uninterrupted run deposited eps at this time before writing the checkpoint, whose
  // rebuild reorders the particles: the deposit above sums the same volumes in another
  // order. Where the written field is that deposit to round-off, it is taken as it is, so
  // that d(eps)/dt of the next step (and everything after) is bit-identical.
  using namespace Foam;
  IOobject io("voidfraction", mesh_.time().timeName(), mesh_, IOobject::MUST_READ,
              IOobject::NO_WRITE, false);
  if (!io.typeHeaderOk<volScalarField>(true)) {
    Info << "grainFoam coupling: restart without a written voidfraction field; it is "
            "rebuilt from the particles (the restart is not bit-identical)"
         << endl;
    return;
  }
  const volScalarField written(io, mesh_);
  const scalar difference =
      gMax(mag(written.primitiveField() - voidFraction_.primitiveField())());
  if (difference <= 1e-9) {
    voidFraction_.primitiveFieldRef() = written.primitiveField();
    voidFraction_.correctBoundaryConditions();
    // dragVoidFraction sharpInterface: the layers (the drag's eps, the scales on U and grad p,
    // and the one on Ksl) were read off the deposit; read them again off the written eps, as
    // the uninterrupted run had them.
    if (sharpInterface_) {
      const scalarField before(velocityScale_);
      reconstructLayers();
      forAll(Ksl_, c) if (before[c] != 0) Ksl_[c] *= velocityScale_[c] / before[c];
    }
    Info << "grainFoam coupling: restart void fraction: the written field and the "
            "particles' deposit differ by "
         << difference << "; continuing with the written one, as the uninterrupted run does"
         << endl;
  } else {
    WarningInFunction << "the written voidfraction differs from the particles' deposit by "
                      << difference << " (" << restartCause().c_str()
                      << "): continuing from the deposit; the restart is not bit-identical" << endl;
  }

  // Ksl likewise: the first fluid samples after the restart read it (the face pressures of
  // facePressure dragSeries, the Brinkman term of undisturbedVelocity) before the next
  // deposit, so the uninterrupted run's sum order is taken where the written field is the
  // deposit to round-off.
  IOobject kslIo("Ksl", mesh_.time().timeName(), mesh_, IOobject::MUST_READ, IOobject::NO_WRITE,
                 false);
  if (!kslIo.typeHeaderOk<volScalarField>(true)) return;
  const volScalarField writtenKsl(kslIo, mesh_);
  const scalar kslScale = max(gMax(mag(Ksl_.primitiveField())()), VSMALL);
  const scalar kslDifference =
      gMax(mag(writtenKsl.primitiveField() - Ksl_.primitiveField())()) / kslScale;
  if (kslDifference <= 1e-9) {
    Ksl_.primitiveFieldRef() = writtenKsl.primitiveField();
    Info << "grainFoam coupling: restart Ksl: the written field and the particles' deposit "
            "differ by "
         << kslDifference << " of its largest value; continuing with the written one" << endl;
  } else {
    Info << "grainFoam coupling: restart Ksl: the written field differs from the particles' "
            "deposit by "
         << kslDifference << " of its largest value (" << restartCause().c_str()
         << "): continuing from the deposit" << endl;
  }
}

std::string ParticleCoupling::restartCause() const {
  using namespace Foam;
  // The settings of the written time (uniform/grainflowCheckpoint), key by key.
  const IOdictionary info(IOobject("grainflowCheckpoint", mesh_.time().timeName(), "uniform",
                                   mesh_.time(), IOobject::READ_IF_PRESENT, IOobject::NO_WRITE,
                                   false));
  const auto split = [](const std::string& text) {
    std::vector<std::pair<std::string, std::string>> out;
    std::istringstream in(text);
    std::string item;
    while (std::getline(in, item, ';')) {
      std::istringstream kv(item);
      std::string key, value;
      if (kv >> key >> value) out.emplace_back(key, value);
    }
    return out;
  };
  std::string changed;
  if (info.found("depositSettings")) {
    const auto then = split(info.get<string>("depositSettings"));
    for (const auto& [key, value] : split(depositSettings_))
      for (const auto& [oldKey, oldValue] : then)
        if (key == oldKey && value != oldValue)
          changed +=
              (changed.empty() ? "" : ", ") + key + " " + oldValue + " then, " + value + " now";
  }
  if (!changed.empty())
    return "constant/couplingProperties changed since this time was written: " + changed +
           "; the deposit follows the new setting";
  const dictionary& control = mesh_.time().controlDict();
  const bool exact = control.lookupOrDefault<word>("writeFormat", "ascii") == "binary" ||
                     control.lookupOrDefault<label>("writePrecision", 6) >= 17;
  if (!exact)
    return "the fields were written with fewer than 17 digits: use writeFormat binary (or "
           "writePrecision 17) in system/controlDict for exact restarts";
  return "the fields were written exactly and the coupling settings are the same: the "
         "particles or the fields are not those the run wrote at this time";
}

ParticleCoupling::~ParticleCoupling() = default;

int ParticleCoupling::gridIndex(int a, double x) const {
  // The global cell index, from the domain's corner and one spacing on every rank, so a
  // point on a cell face falls in the same cell whatever the rank layout; then local.
  const double s = (x - domain_.lo[a]) / gridH_[a];
  // Below the domain (or NaN), or far beyond it (and beyond int): outside.
  if (!(s >= 0) || s >= kFarOutside) return -1;
  int idx = static_cast<int>(s) - gridOffset_[a];  // s >= 0: truncation is floor
  // A point on the domain's upper face belongs to the last cell.
  if (idx == gridN_[a] && std::abs(x - domain_.hi[a]) <= 1e-12 * gridH_[a] * gridN_[a])
    idx = gridN_[a] - 1;
  if (idx < 0 || idx >= gridN_[a]) return -1;
  return idx;
}

Foam::label ParticleCoupling::locate(const Foam::point& x) const {
  if (structured_) {
    std::size_t k = 0;
    for (int a = 2; a >= 0; --a) {
      const int idx = gridIndex(a, x[a]);
      if (idx < 0) return -1;
      k = k * static_cast<std::size_t>(gridN_[a]) + static_cast<std::size_t>(idx);
    }
    return gridCell_[k];
  }
  return mesh_.findCell(x);
}

Foam::label ParticleCoupling::locateNear(const Foam::point& x, Foam::label near) const {
  if (structured_) return locate(x);
  return findCellNear(mesh_, x, near);  // findCell's cell, `near` and its neighbours first
}

void ParticleCoupling::buildFootprints() {
  dem_->view(particles_);  // the DEM's arrays, no copy
  const std::size_t n = particles_.size();
  first_.resize(n + 1);
  first_[0] = 0;
  points_.clear();  // keeps its capacity
  centreCell_.resize(particles_.local());
  const std::vector<coupling::FootprintPoint>& unit = footprint_.unit_points();
  // The `centre` footprint: one point at the centre, weight 1. For a centre inside the
  // domain (on a periodic axis in [lo, hi)) the general loop below gives that point itself
  // (offset 0, no reflection, no image), so it is taken directly.
  const bool centreOnly = unit.size() == 1 && unit[0].offset[0] == 0 && unit[0].offset[1] == 0 &&
                          unit[0].offset[2] == 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double* centre = particles_.x(i);
    const double r = particles_.radius(i);
    const Foam::label centreCell = locate(Foam::point(centre[0], centre[1], centre[2]));
    if (centreOnly) {
      bool inside = true;
      for (int a = 0; a < 3; ++a)
        inside = inside && centre[a] >= domain_.lo[a] &&
                 (periodic_[a] ? centre[a] < domain_.hi[a] : centre[a] <= domain_.hi[a]);
      if (inside) {
        if (centreCell >= 0) points_.push_back({centreCell, unit[0].weight});
        first_[i + 1] = points_.size();
        if (i < particles_.local()) centreCell_[i] = centreCell;
        continue;
      }
    }
    if (structured_) {
      structuredFootprint(i, centreCell);
      continue;
    }
    for (const coupling::FootprintPoint& q : unit) {
      Foam::point x;
      bool image = false;  // beyond a periodic side: the particle's image deposits it
      for (int a = 0; a < 3; ++a) {
        // Footprint::points(): the unit offset scaled by the radius.
        double s = centre[a] + q.offset[a] * r;
        // A bounded side reflects the part of a footprint that pokes through it.
        if (!periodic_[a]) {
          if (s < domain_.lo[a]) s = 2 * domain_.lo[a] - s;
          if (s > domain_.hi[a]) s = 2 * domain_.hi[a] - s;
        } else if (s < domain_.lo[a] || s >= domain_.hi[a]) {
          image = true;  // periodic axes are half-open, [lo, hi), as in the DEM
        }
        x[a] = s;
      }
      if (image) continue;
      // The centre itself (the `centre` footprint, or a centred part): its cell is known.
      const bool atCentre = x[0] == centre[0] && x[1] == centre[1] && x[2] == centre[2];
      const Foam::label c = atCentre ? centreCell : locateNear(x, centreCell);
      if (c >= 0) points_.push_back({c, q.weight});
    }
    mergeFootprintCells(first_[i]);
    first_[i + 1] = points_.size();
    if (i < particles_.local()) centreCell_[i] = centreCell;
  }
}

void ParticleCoupling::mergeFootprintCells(std::size_t begin) {
  std::size_t end = begin;  // points_[begin, end): the merged cells so far
  for (std::size_t j = begin; j < points_.size(); ++j) {
    std::size_t k = begin;
    while (k < end && points_[k].cell != points_[j].cell) ++k;
    if (k < end)
      points_[k].weight += points_[j].weight;
    else
      points_[end++] = points_[j];
  }
  points_.resize(end);
}

void ParticleCoupling::structuredFootprint(std::size_t i, Foam::label centreCell) {
  // buildFootprints()'s general loop on a uniform grid, with the same arithmetic: a
  // footprint's points share few distinct offsets per axis (7 of 27 with dividedResolution 3),
  // so the coordinate, its reflection or image and its grid index are found once per distinct
  // offset and axis, not once per point; a point's cell is then a table look-up.
  const std::vector<coupling::FootprintPoint>& unit = footprint_.unit_points();
  if (pointAxis_.size() != unit.size()) {  // once: the distinct offsets per axis
    pointAxis_.resize(unit.size());
    for (int a = 0; a < 3; ++a) {
      axisOffset_[a].clear();
      for (std::size_t q = 0; q < unit.size(); ++q) {
        const double o = unit[q].offset[a];
        const auto at = std::find(axisOffset_[a].begin(), axisOffset_[a].end(), o);
        pointAxis_[q][a] = static_cast<int>(at - axisOffset_[a].begin());
        if (at == axisOffset_[a].end()) axisOffset_[a].push_back(o);
      }
      axisCell_[a].resize(axisOffset_[a].size());
    }
  }
  const double* centre = particles_.x(i);
  const double r = particles_.radius(i);
  for (int a = 0; a < 3; ++a)
    for (std::size_t m = 0; m < axisOffset_[a].size(); ++m) {
      // Footprint::points(): the unit offset scaled by the radius.
      double s = centre[a] + axisOffset_[a][m] * r;
      int cell = 0;  // grid index along a; kImage: beyond a periodic side
      // A bounded side reflects the part of a footprint that pokes through it.
      if (!periodic_[a]) {
        if (s < domain_.lo[a]) s = 2 * domain_.lo[a] - s;
        if (s > domain_.hi[a]) s = 2 * domain_.hi[a] - s;
      } else if (s < domain_.lo[a] || s >= domain_.hi[a]) {
        cell = kImage;  // periodic axes are half-open, [lo, hi), as in the DEM
      }
      axisCell_[a][m] = cell == kImage ? kImage : gridIndex(a, s);
    }
  // Each axis's grid indices lie in [lo, lo + 3) for a footprint up to three cells across
  // (any particle up to one cell in diameter): the points' weights are summed per (x, y, z)
  // slot, then each occupied slot is one entry, located once. A wider footprint takes the
  // general route, point by point, merged afterwards. (A point at the centre itself falls in
  // the centre's cell either way: locate() uses the same grid indices.)
  int lo[3];
  bool narrow = true;
  for (int a = 0; a < 3; ++a) {
    int l = std::numeric_limits<int>::max(), h = std::numeric_limits<int>::min();
    for (const int c : axisCell_[a])
      if (c >= 0) {
        l = std::min(l, c);
        h = std::max(h, c);
      }
    lo[a] = l;
    narrow = narrow && (l > h || h - l < 3);  // l > h: no point on this rank's grid
  }
  if (narrow) {
    // The slots in the order of their first point, as mergeFootprintCells() leaves them, so
    // both routes give the same entries to the last bit.
    double slot[27] = {};
    bool used[27] = {};
    int order[27];
    int slots = 0;
    for (std::size_t q = 0; q < unit.size(); ++q) {
      const std::array<int, 3>& m = pointAxis_[q];
      const int ix = axisCell_[0][m[0]], iy = axisCell_[1][m[1]], iz = axisCell_[2][m[2]];
      // Beyond a periodic side (the particle's image deposits it) or outside this rank's grid.
      if (ix < 0 || iy < 0 || iz < 0) continue;
      const int k = (ix - lo[0]) + 3 * (iy - lo[1]) + 9 * (iz - lo[2]);
      if (!used[k]) {
        used[k] = true;
        order[slots++] = k;
      }
      slot[k] += unit[q].weight;
    }
    for (int n = 0; n < slots; ++n) {
      const int k = order[n];
      const double w = slot[k];
      const std::size_t ix = static_cast<std::size_t>(lo[0] + k % 3),
                        iy = static_cast<std::size_t>(lo[1] + (k / 3) % 3),
                        iz = static_cast<std::size_t>(lo[2] + k / 9);
      const Foam::label c = gridCell_[(iz * gridN_[1] + iy) * gridN_[0] + ix];
      if (c >= 0) points_.push_back({c, w});
    }
  } else {
    for (std::size_t q = 0; q < unit.size(); ++q) {
      const std::array<int, 3>& m = pointAxis_[q];
      const int ix = axisCell_[0][m[0]], iy = axisCell_[1][m[1]], iz = axisCell_[2][m[2]];
      if (ix < 0 || iy < 0 || iz < 0) continue;
      const Foam::label c =
          gridCell_[(static_cast<std::size_t>(iz) * gridN_[1] + static_cast<std::size_t>(iy)) *
                        gridN_[0] +
                    static_cast<std::size_t>(ix)];
      if (c >= 0) points_.push_back({c, unit[q].weight});
    }
    mergeFootprintCells(first_[i]);
  }
  first_[i + 1] = points_.size();
  if (i < particles_.local()) centreCell_[i] = centreCell;
}

void ParticleCoupling::deposit() {
  using namespace Foam;
  const scalarField& V = mesh_.V().field();
  // Sums per cell, kept from step to step (no allocation per step).
  scalarField& solid = solid_;
  scalarField& K = K_;
  vectorField& KU = KU_;
  vectorField& F = F_;
  solid.setSize(mesh_.nCells());
  K.setSize(mesh_.nCells());
  KU.setSize(mesh_.nCells());
  F.setSize(mesh_.nCells());
  solid = 0.0;
  K = 0.0;
  KU = Zero;
  F = Zero;
  double particleVolume = 0;  // of the local particles
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    const double r = particles_.radius(i);
    const double volume = 4.0 / 3.0 * constant::mathematical::pi * r * r * r;
    if (i < particles_.local()) particleVolume += volume;
    const double* vi = particles_.v(i);
    const vector v(vi[0], vi[1], vi[2]);
    const double k = particles_.drag_coefficient(i);
    const std::array<double, 3> fi = particles_.exchange_force(i);
    const vector f(fi[0], fi[1], fi[2]);
    for (std::size_t j = first_[i]; j < first_[i + 1]; ++j) {
      const label c = points_[j].cell;
      const double w = points_[j].weight;
      solid[c] += w * volume;
      K[c] += w * k;
      KU[c] += w * k * v;
      F[c] -= w * f;
    }
  }
  // One pass over the cells for eps and the exchange fields (the arithmetic of the field
  // expressions K / V, sum(solid), sum((1 - eps) V), without their temporaries).
  scalarField& eps = voidFraction_.primitiveFieldRef();
  scalarField& Ksl = Ksl_.primitiveFieldRef();
  vectorField& KslUs = KslUs_.primitiveFieldRef();
  vectorField& fExplicit = fExplicit_.primitiveFieldRef();
  double stepClamped = 0;  // this deposit's, on this rank
  double depositedVolume = 0, meshSolidVolume = 0;
  if (smoothing_) {
    // The averaging acts on the deposited fields before the clamp (it conserves their
    // volume integrals; a uniform eps stays uniform).
    // undisturbedVelocity: the other particles' drag per volume at a particle is read from
    // the deposit before the averaging (its own share, K W_c^2 / V_c, is taken off exactly).
    if (undisturbed_) rawKsl_.setSize(eps.size());
    forAll(eps, c) {
      eps[c] = 1 - solid[c] / V[c];
      Ksl[c] = K[c] / V[c];
      if (undisturbed_) rawKsl_[c] = Ksl[c];
      KslUs[c] = KU[c] / V[c];
      fExplicit[c] = F[c] / V[c];
    }
    smoothing_->apply(voidFraction_);
    smoothing_->apply(Ksl_);
    smoothing_->apply(KslUs_);
    smoothing_->apply(fExplicit_);
    forAll(eps, c) solid[c] = (1 - eps[c]) * V[c];
  }
  forAll(eps, c) {
    const double raw = 1 - solid[c] / V[c];
    if (raw < minVoidFraction_) {
      ++clampedCells_;
      clampedVolume_ += (minVoidFraction_ - raw) * V[c];
      stepClamped += (minVoidFraction_ - raw) * V[c];
      eps[c] = minVoidFraction_;
    } else {
      eps[c] = raw;
    }
    if (!smoothing_) {
      Ksl[c] = K[c] / V[c];
      KslUs[c] = KU[c] / V[c];
      fExplicit[c] = F[c] / V[c];
    }
    depositedVolume += solid[c];
    meshSolidVolume += (1 - eps[c]) * V[c];
  }
  voidFraction_.correctBoundaryConditions();
  if (sharpInterface_) {
    // The particles read velocityScale U (sample()): the fluid's implicit coefficient is
    // scaled alike, so that their forces and the exchange source still balance.
    reconstructLayers();
    forAll(Ksl, c) Ksl[c] *= velocityScale_[c];
  }
  // Ksl, KslUs and fParticles are read on a boundary only by grainFoam's fixedFluxPressure
  // patches (the drag balance there), which are never constraint patches: their
  // symmetry-plane, processor and cyclic values are left unevaluated (on the Goldschmidt bed,
  // two vector transforms over 5 400 symmetry faces per fluid step; on 2 ranks, Ksl's
  // processor-patch exchange). Ksl is written: at a write time (and before a write at another
  // time, completeWrittenFields()) every patch is evaluated.
  if (mesh_.time().writeTime()) {
    Ksl_.correctBoundaryConditions();
    kslEvaluated_ = true;
  } else {
    kslEvaluated_ = false;
  }
  const polyBoundaryMesh& patches = mesh_.boundaryMesh();
  forAll(patches, patch) {
    if (polyPatch::constraintType(patches[patch].type())) continue;
    if (!kslEvaluated_) Ksl_.boundaryFieldRef()[patch].evaluate();
    KslUs_.boundaryFieldRef()[patch].evaluate();
    fExplicit_.boundaryFieldRef()[patch].evaluate();
  }

  // The volume sums are reported at write times only (checkBalance(), write()): summed over
  // the ranks then (depositSums()), not after every deposit.
  localSums_[0] = particleVolume;
  localSums_[1] = depositedVolume;
  localSums_[2] = meshSolidVolume;
  localSums_[3] = stepClamped;
  sumsReduced_ = false;
}

void ParticleCoupling::depositSums() {
  if (sumsReduced_) return;
  // Volume not deposited anywhere (footprint points outside every rank's cells).
  double sums[4] = {localSums_[0], localSums_[1], localSums_[2], localSums_[3]};
  MPI_Allreduce(MPI_IN_PLACE, sums, 4, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  lostVolume_ = std::max(0.0, sums[0] - sums[1]);
  particleVolume_ = sums[0];
  meshSolidVolume_ = sums[2];
  stepClampedVolume_ = sums[3];
  sumsReduced_ = true;
}

void ParticleCoupling::completeWrittenFields() {
  if (kslEvaluated_) return;
  Ksl_.correctBoundaryConditions();
  kslEvaluated_ = true;
}

void ParticleCoupling::reconstructLayers() {
  // Along each axis a cell has a neighbour on either side (area-weighted over that side's
  // faces; across processor and cyclic patches the neighbour's value; particle-free fluid
  // beyond an inlet or outlet; none at a wall). A cell whose solid fraction phi lies strictly between its two neighbours' phi_L <
  // phi < phi_D is read as a sharp interface between their states (a one-dimensional VOF
  // reconstruction): a fraction f = (phi - phi_L)/(phi_D - phi_L) of it at phi_D, the rest at
  // phi_L. The drag sees the solid-weighted solid fraction of the two layers,
  //   phi_s = (f phi_D^2 + (1 - f) phi_L^2) / phi   (>= phi; = phi_D when phi_L = 0),
  // along the axis with the largest jump phi_D - phi_L, and the interstitial velocity of
  // the cell's superficial velocity in it, (eps / eps_s) U: the layers are crossed in series.
  // The pressure then drops across the dense layer alone: the particles read grad p / f =
  // (phi_s / phi) grad p, and model A's fluid carries eps_s grad p (grainFoam's c), so that
  // the cell's pressure drop is its drag over eps_s, as in a bed of eps_s, not over eps.
  // A cell without such an axis keeps its own eps, U and grad p.
  using namespace Foam;
  const label n = mesh_.nCells();
  const scalarField& eps = voidFraction_.primitiveField();
  sides_.assign(12 * static_cast<std::size_t>(n), 0.0);
  const auto add = [this](label c, const vector& outward, double phi) {
    const int a = dominantAxis(outward);
    const double area = mag(outward);
    double* s = &sides_[12 * static_cast<std::size_t>(c) + 4 * a + (outward[a] > 0 ? 2 : 0)];
    s[0] += area * phi;
    s[1] += area;
  };
  const vectorField& Sf = mesh_.Sf().primitiveField();
  const labelUList& owner = mesh_.owner();
  const labelUList& neighbour = mesh_.neighbour();
  forAll(neighbour, f) {
    add(owner[f], Sf[f], 1 - eps[neighbour[f]]);
    add(neighbour[f], -Sf[f], 1 - eps[owner[f]]);
  }
  // Beyond an inlet or outlet (a patch the fluid crosses) lies particle-free fluid: the
  // bed resting on a distributor is read like its surface. A wall or a constraint patch
  // that is not coupled (empty, symmetry, ...) is a side without a neighbour.
  forAll(voidFraction_.boundaryField(), patch) {
    const fvPatchScalarField& pe = voidFraction_.boundaryField()[patch];
    const fvPatch& fp = mesh_.boundary()[patch];
    const vectorField& S = mesh_.Sf().boundaryField()[patch];
    const labelUList& cells = fp.faceCells();
    if (pe.coupled()) {
      const tmp<scalarField> other = pe.patchNeighbourField();
      forAll(cells, i) add(cells[i], S[i], 1 - other()[i]);
    } else if (!isA<wallFvPatch>(fp) && !polyPatch::constraintType(fp.type())) {
      forAll(cells, i) add(cells[i], S[i], 0.0);
    }
  }
  scalarField& dragEps = dragVoidFraction_.primitiveFieldRef();
  velocityScale_.setSize(n);
  gradScale_.setSize(n);
  for (label c = 0; c < n; ++c) {
    const double phi = 1 - eps[c];
    double phiS = phi, jump = 0;
    const double* s = &sides_[12 * static_cast<std::size_t>(c)];
    for (int a = 0; a < 3; ++a) {
      const double* lo = s + 4 * a;
      const double* hi = lo + 2;
      if (!(lo[1] > 0 && hi[1] > 0)) continue;  // a bounded side: no neighbour
      const double p0 = lo[0] / lo[1], p1 = hi[0] / hi[1];
      const double dense = std::max(p0, p1), dilute = std::min(p0, p1);
      if (!(phi > dilute && phi < dense) || dense - dilute <= jump) continue;
      const double f = (phi - dilute) / (dense - dilute);
      phiS = (f * dense * dense + (1 - f) * dilute * dilute) / phi;
      jump = dense - dilute;
    }
    dragEps[c] = 1 - phiS;
    velocityScale_[c] = eps[c] / dragEps[c];
    gradScale_[c] = phi > 0 ? phiS / phi : 1.0;
  }
  dragVoidFraction_.correctBoundaryConditions();
}

Foam::tmp<Foam::volVectorField> ParticleCoupling::seriesGradient(
    const Foam::volScalarField& p) const {
  // Darcy across the two half cells of a face: c dp/dn = r q on either side, the same
  // superficial flux q through both; the face pressure where the two half-cell drops meet.
  // A bed's last full cell next to particle-free fluid then carries the bed's gradient
  // (p_f = p_N) instead of the mean of the bed's and the free fluid's (Gauss linear).
  using namespace Foam;
  const dimensionedScalar rho("rho", dimDensity, rho_);
  volScalarField r(IOobject("dragResistance", mesh_.time().timeName(), mesh_, IOobject::NO_READ,
                            IOobject::NO_WRITE, false),
                   Ksl_ / (rho * voidFraction_));
  if (model_ == 'A') r /= sharpInterface_ ? dragVoidFraction_ : voidFraction_;
  r.correctBoundaryConditions();  // the neighbours' r across coupled patches

  // The rule holds for layers crossed in series, so each half cell takes the resistance of its
  // layer: the cell and its neighbours across the face's axis (its faces along the other two
  // mesh axes), area-weighted, the cell weighted by its mean face area along the axis. In a
  // bed's bulk the cells' resistances differ by the sampling noise of one random packing,
  // which the drag law already averages over; read cell by cell, the series rule turns that
  // noise into a steeper mean gradient (layers in series at r +- dr resist more than one at
  // r). Across a planar surface the neighbours share the cell's resistance: unchanged there.
  const label n = mesh_.nCells();
  const vectorField& Sf = mesh_.Sf().primitiveField();
  const labelUList& owner = mesh_.owner();
  const labelUList& neighbour = mesh_.neighbour();
  // Per cell and axis b: the sum over its faces along b of |S| r beyond, of |S| with a
  // neighbour, and of |S| of every face (walls too).
  std::vector<double> around(9 * static_cast<std::size_t>(n), 0.0);
  const auto add = [&around](label c, int b, double area, double rOther, bool other) {
    double* s = &around[9 * static_cast<std::size_t>(c) + 3 * b];
    if (other) {
      s[0] += area * rOther;
      s[1] += area;
    }
    s[2] += area;
  };
  forAll(neighbour, f) {
    const int b = dominantAxis(Sf[f]);
    const double area = mag(Sf[f]);
    add(owner[f], b, area, r[neighbour[f]], true);
    add(neighbour[f], b, area, r[owner[f]], true);
  }
  forAll(mesh_.boundary(), patch) {
    const labelUList& cells = mesh_.boundary()[patch].faceCells();
    const vectorField& S = mesh_.Sf().boundaryField()[patch];
    if (r.boundaryField()[patch].coupled()) {
      const tmp<scalarField> rN = r.boundaryField()[patch].patchNeighbourField();
      forAll(cells, i) add(cells[i], dominantAxis(S[i]), mag(S[i]), rN()[i], true);
    } else {
      forAll(cells, i) add(cells[i], dominantAxis(S[i]), mag(S[i]), 0.0, false);
    }
  }
  // The layer's resistance per axis a, exchanged across coupled patches like r.
  PtrList<volScalarField> layer(3);
  for (int a = 0; a < 3; ++a) {
    layer.set(a, new volScalarField(IOobject("layerResistance", mesh_.time().timeName(), mesh_,
                                             IOobject::NO_READ, IOobject::NO_WRITE, false),
                                    r));
    scalarField& ra = layer[a].primitiveFieldRef();
    for (label c = 0; c < n; ++c) {
      const double* s = &around[9 * static_cast<std::size_t>(c)];
      double sum = 0.5 * s[3 * a + 2] * r[c], weight = 0.5 * s[3 * a + 2];
      for (int b = 0; b < 3; ++b) {
        if (b == a) continue;
        sum += s[3 * b];
        weight += s[3 * b + 1];
      }
      ra[c] = weight > 0 ? sum / weight : r[c];
    }
    layer[a].correctBoundaryConditions();
  }

  surfaceScalarField pf(fvc::interpolate(p));
  const scalarField& w = mesh_.weights().primitiveField();
  const auto series = [](double wP, double rP, double rN, double pP, double pN, double linear) {
    const double gP = wP * rN, gN = (1 - wP) * rP;
    return gP + gN > 0 ? (gP * pP + gN * pN) / (gP + gN) : linear;
  };
  forAll(owner, f) {
    const volScalarField& ra = layer[dominantAxis(Sf[f])];
    pf[f] = series(w[f], ra[owner[f]], ra[neighbour[f]], p[owner[f]], p[neighbour[f]], pf[f]);
  }
  forAll(pf.boundaryField(), patch) {
    const fvPatchScalarField& pb = p.boundaryField()[patch];
    if (!pb.coupled()) continue;
    const labelUList& cells = mesh_.boundary()[patch].faceCells();
    const vectorField& S = mesh_.Sf().boundaryField()[patch];
    const scalarField& wb = mesh_.weights().boundaryField()[patch];
    const tmp<scalarField> pN = pb.patchNeighbourField();
    tmp<scalarField> rN[3];
    for (int a = 0; a < 3; ++a) rN[a] = layer[a].boundaryField()[patch].patchNeighbourField();
    scalarField& pfb = pf.boundaryFieldRef()[patch];
    forAll(cells, i) {
      const int a = dominantAxis(S[i]);
      pfb[i] = series(wb[i], layer[a][cells[i]], rN[a]()[i], p[cells[i]], pN()[i], pfb[i]);
    }
  }
  tmp<volVectorField> grad(fvc::surfaceIntegrate(mesh_.Sf() * pf));
  grad.ref().rename("seriesGrad(" + p.name() + ')');
  return grad;
}

Foam::volVectorField& ParticleCoupling::pressureGradient() {
  using namespace Foam;
  if (dragSeriesPressure_) {
    // The gradient the fluid's momentum equation carries (grainFoam), at the particles too.
    gradPOther_ = seriesGradient(p_);
    if (sampling_ == Sampling::cellPoint) gradPOther_.ref().correctBoundaryConditions();
    return gradPOther_.ref();
  }
  if (!gaussLinearGrad_) {
    gradPOther_ = fvc::grad(p_);
    return gradPOther_.ref();
  }
  if (!gradP_) {
    gradP_.reset(new volVectorField(
        IOobject("grad(" + p_.name() + ')', p_.instance(), mesh_, IOobject::NO_READ,
                 IOobject::NO_WRITE, false),
        mesh_, dimensionedVector("zero", p_.dimensions() / dimLength, Zero),
        extrapolatedCalculatedFvPatchField<vector>::typeName));
  }
  gaussLinearGrad(p_, *gradP_, sampling_ == Sampling::cellPoint);
  return *gradP_;
}

Foam::volVectorField& ParticleCoupling::viscousLaplacian() {
  using namespace Foam;
  const dimensionedScalar nu("nu", dimViscosity, nu_);
  if (!uncorrectedLaplacian_.valid()) {
    divTau_.reset(fvc::laplacian(nu, U_).ptr());
    return *divTau_;
  }
  // fvc::laplacian(nu, U) with `Gauss linear uncorrected` (gaussLaplacianScheme::fvcLaplacian:
  // fvc::div(nu_f * snGrad(U) * |S_f|), snGrad = nonOrthDeltaCoeffs (U_N - U_P), the patches'
  // own snGrad on the boundary; fvc::div = surfaceIntegrate, then / V and the
  // extrapolatedCalculated boundary values), the same operations in the same order in one
  // pass, into a field kept from step to step: no face fields made per step.
  if (!divTau_) {  // a mesh is orthogonal or not for the whole run: this branch or the other
    divTau_.reset(new volVectorField(
        IOobject("laplacian(nu," + U_.name() + ')', U_.instance(), mesh_, IOobject::NO_READ,
                 IOobject::NO_WRITE, false),
        mesh_, dimensionedVector("zero", nu.dimensions() * U_.dimensions() / dimArea, Zero),
        extrapolatedCalculatedFvPatchField<vector>::typeName));
  }
  volVectorField& lap = *divTau_;
  vectorField& ivf = lap.primitiveFieldRef();
  ivf = Zero;
  const labelUList& owner = mesh_.owner();
  const labelUList& neighbour = mesh_.neighbour();
  const surfaceScalarField& deltaCoeffs = mesh_.nonOrthDeltaCoeffs();
  const scalarField& dc = deltaCoeffs.primitiveField();
  const scalarField& magSf = mesh_.magSf().primitiveField();
  const vectorField& U = U_.primitiveField();
  const double n = nu.value();
  forAll(owner, facei) {
    const vector flux = (n * (dc[facei] * (U[neighbour[facei]] - U[owner[facei]]))) * magSf[facei];
    ivf[owner[facei]] += flux;
    ivf[neighbour[facei]] -= flux;
  }
  forAll(mesh_.boundary(), patchi) {
    const fvPatchVectorField& pU = U_.boundaryField()[patchi];
    const tmp<vectorField> tsn =
        pU.coupled() ? pU.snGrad(deltaCoeffs.boundaryField()[patchi]) : pU.snGrad();
    const vectorField& sn = tsn();
    const scalarField& pMagSf = mesh_.magSf().boundaryField()[patchi];
    const labelUList& faceCells = mesh_.boundary()[patchi].faceCells();
    forAll(faceCells, facei) ivf[faceCells[facei]] += (n * sn[facei]) * pMagSf[facei];
  }
  ivf /= mesh_.Vsc();
  if (sampling_ == Sampling::cellPoint) lap.correctBoundaryConditions();
  return lap;
}

template <int width>
void ParticleCoupling::sampleCellPoint() {
  const CellPointWeights& weights = *cellPointWeights_;
  // Written straight into the DEM's sample records (no per-particle call or copy).
  const coupling::DemLink::SampleRecords at = dem_->fluid_samples();
  for (std::size_t i = 0; i < particles_.local(); ++i) {
    double* s = at.records + at.stride * i;
    const Foam::label c = centreCell_[i];
    double v[width];
    if (c < 0) {  // outside the mesh: fluid at rest, eps = 1
      for (int k = 0; k < width; ++k) v[k] = 0;
      v[9] = 1;
    } else {
      const CellPointWeight w =
          weights.at(Foam::point(particles_.x(i)[0], particles_.x(i)[1], particles_.x(i)[2]), c);
      // interpolationCellPoint<Type>::interpolate per component, in its order:
      // cell * w0, then + point_k * w_k for k = 1, 2, 3.
      const double* r[4] = {&cellRecords_[std::size_t{width} * c],
                            &pointRecords_[std::size_t{width} * w.point[0]],
                            &pointRecords_[std::size_t{width} * w.point[1]],
                            &pointRecords_[std::size_t{width} * w.point[2]]};
      for (int k = 0; k < width; ++k) v[k] = r[0][k] * w.w[0];
      for (int j = 1; j < 4; ++j)
        for (int k = 0; k < width; ++k) v[k] += r[j][k] * w.w[j];
      v[9] = std::max(minVoidFraction_, std::min(1.0, v[9]));
    }
    for (int d = 0; d < 3; ++d) {
      s[at.velocity + d] = v[d];
      s[at.pressure_gradient + d] = v[3 + d];
      s[at.viscous_stress_divergence + d] = v[6 + d];
      if constexpr (width == 13) at.vorticity[3 * i + d] = v[10 + d];
    }
    s[at.void_fraction] = v[9];
  }
}

void ParticleCoupling::sample() {
  using namespace Foam;
  // rho grad p and rho nu laplacian(U), scaled in place (no second field). Sampling `cell`
  // reads cell values only: their boundary values are neither evaluated (pressureGradient(),
  // viscousLaplacian(): no processor-patch exchange) nor scaled.
  const dimensionedScalar rho("rho", dimless, rho_);
  volVectorField& gradP = pressureGradient();
  volVectorField& divTau = viscousLaplacian();
  if (sampling_ == Sampling::cellPoint) {
    gradP *= rho;
    // rho grad p keeps p's kinematic dimensions (rho is dimensionless here): G [Pa/m] by value.
    if (meanGradPOn_) gradP += dimensionedVector("meanGradP", gradP.dimensions(), meanGradP_);
    divTau *= rho;
  } else {
    gradP.primitiveFieldRef() *= rho_;
    if (meanGradPOn_) gradP.primitiveFieldRef() += meanGradP_;
    divTau.primitiveFieldRef() *= rho_;
  }
  const bool curl = dem_->needs_vorticity();
  tmp<volVectorField> tCurlU;
  if (curl) tCurlU = fvc::curl(U_);
  const std::size_t local = particles_.local();
  if (sampling_ == Sampling::cellPoint) {
    // diffusionBandwidth: the fields are averaged before the interpolation, as the cell path
    // reads them (the deposit's adjoint); the non-coupled patches keep the field's own
    // boundary values (a wall's no-slip U), the coupled ones the averaged neighbours.
    const auto averaged = [this](volVectorField& work,
                                 const volVectorField& from) -> const volVectorField& {
      work.primitiveFieldRef() = from.primitiveField();
      smoothing_->apply(work);
      work.correctBoundaryConditions();
      forAll(work.boundaryField(), patch)
        if (!work.boundaryField()[patch].coupled())
          work.boundaryFieldRef()[patch] = from.boundaryField()[patch];
      return work;
    };
    const volVectorField& Uf = smoothing_ ? averaged(*smoothU_, U_) : U_;
    const volVectorField& Gf = smoothing_ ? averaged(*smoothGradP_, gradP) : gradP;
    const volVectorField& Tf = smoothing_ ? averaged(*smoothDivTau_, divTau) : divTau;
    const volVectorField* Cf = nullptr;
    if (curl) Cf = smoothing_ ? &averaged(*smoothCurlU_, tCurlU()) : &tCurlU();
    // OpenFOAM's cellPoint interpolation (interpolationCellPoint): the point values as
    // volPointInterpolation makes them (pointInterpolation.H: to the last bit, all fields in
    // one pass; or volPointInterpolation itself), the tetrahedron and its weights by
    // cellPointWeights_, once per particle for all the fields (cellPointWeights.H:
    // OpenFOAM's weights, to round-off in box cells).
    // The fields side by side, one record per cell and per point (U 0-2, grad p 3-5,
    // div tau 6-8, eps 9, curl U 10-12), so that a stencil reads four records.
    const int width = curl ? 13 : 10;
    const UList<vector>* cellCurl = curl ? &Cf->primitiveField() : nullptr;
    const auto pack = [width](double* records, label k, const vector& U, const vector& G,
                              const vector& T, scalar E, const vector* C) {
      double* r = records + static_cast<std::size_t>(width) * k;
      for (int d = 0; d < 3; ++d) {
        r[d] = U[d];
        r[3 + d] = G[d];
        r[6 + d] = T[d];
        if (C) r[10 + d] = (*C)[d];
      }
      r[9] = E;
    };
    const label nCells = mesh_.nCells();
    if (pointInterpolation_) {
      // The cells' records, then those of the boundary faces the point values read.
      const std::vector<PointInterpolation::Face>& faces = pointInterpolation_->faces();
      cellRecords_.resize(static_cast<std::size_t>(width) * (nCells + faces.size()));
      for (label k = 0; k < nCells; ++k)
        pack(cellRecords_.data(), k, Uf[k], Gf[k], Tf[k], voidFraction_[k],
             curl ? &(*cellCurl)[k] : nullptr);
      for (std::size_t i = 0; i < faces.size(); ++i) {
        const label patch = faces[i].patch, f = faces[i].face;
        pack(cellRecords_.data(), nCells + static_cast<label>(i), Uf.boundaryField()[patch][f],
             Gf.boundaryField()[patch][f], Tf.boundaryField()[patch][f],
             voidFraction_.boundaryField()[patch][f],
             curl ? &Cf->boundaryField()[patch][f] : nullptr);
      }
      pointRecords_.resize(static_cast<std::size_t>(width) * mesh_.nPoints());
      static const std::vector<int> vectors10 = {0, 3, 6}, vectors13 = {0, 3, 6, 10};
      if (curl)
        pointInterpolation_->interpolate<13>(cellRecords_.data(), vectors13, pointRecords_.data());
      else
        pointInterpolation_->interpolate<10>(cellRecords_.data(), vectors10, pointRecords_.data());
    } else {
      const volPointInterpolation& toPoints = volPointInterpolation::New(mesh_);
      const pointMesh& pMesh = pointMesh::New(mesh_);
      // interpolate(field) would make a new point field (calculated patches) each call and
      // fill it with interpolate(field, pointField); the same fields are kept and refilled.
      const auto points = [&](auto& store, const auto& field) -> const auto& {
        using PointField = typename std::remove_reference_t<decltype(store)>::element_type;
        if (!store)
          store.reset(new PointField(IOobject("volPointInterpolate(" + field.name() + ')',
                                              field.instance(), pMesh.thisDb(), IOobject::NO_READ,
                                              IOobject::NO_WRITE, false),
                                     pMesh, field.dimensions()));
        toPoints.interpolate(field, *store);
        return *store;
      };
      const pointVectorField& pU = points(pointU_, Uf);
      const pointVectorField& pG = points(pointGradP_, Gf);
      const pointVectorField& pT = points(pointDivTau_, Tf);
      const pointScalarField& pE = points(pointEps_, voidFraction_);
      const pointVectorField* pC = curl ? &points(pointCurlU_, *Cf) : nullptr;
      cellRecords_.resize(static_cast<std::size_t>(width) * nCells);
      for (label k = 0; k < nCells; ++k)
        pack(cellRecords_.data(), k, Uf[k], Gf[k], Tf[k], voidFraction_[k],
             curl ? &(*cellCurl)[k] : nullptr);
      pointRecords_.resize(static_cast<std::size_t>(width) * mesh_.nPoints());
      forAll(pU, k)
        pack(pointRecords_.data(), k, pU[k], pG[k], pT[k], pE[k], curl ? &(*pC)[k] : nullptr);
    }
    cellPointSamples_ += static_cast<long>(local);
    if (curl)
      sampleCellPoint<13>();
    else
      sampleCellPoint<10>();
    sampleFootprint();
    return;
  }
  // Footprint-weighted cell values; ghosts' shares go back to their owners. With
  // undisturbedVelocity, also the cells' size (V^(2/3)), the other particles' drag per volume
  // there, the particle's own share of it, and the footprint's weight marginal on each axis
  // over the cells at offsets -1, 0, 1 from the particle's own (17 + 3 a + 1 + offset): the
  // offset of a cell along a is round((C_a - x_a) / h_c), h_c = V^(1/3), from the particle's
  // (or its periodic image's) centre, the same on every rank.
  // diffusionBandwidth: the particles read the fields averaged by the same diffusion as
  // the deposit (its adjoint: sum V S(Ksl) U = sum V Ksl S(U), the balance stays exact).
  const UList<vector>* Uc = &U_.primitiveField();
  const UList<vector>* Gc = &gradP.primitiveField();
  const UList<vector>* Tc = &divTau.primitiveField();
  const UList<vector>* Cc = curl ? &tCurlU().primitiveField() : nullptr;
  if (smoothing_) {
    const auto smoothed = [this](volVectorField& work, const UList<vector>* from) {
      work.primitiveFieldRef() = *from;
      smoothing_->apply(work);
      return &work.primitiveField();
    };
    Uc = smoothed(*smoothU_, Uc);
    Gc = smoothed(*smoothGradP_, Gc);
    Tc = smoothed(*smoothDivTau_, Tc);
    if (curl) Cc = smoothed(*smoothCurlU_, Cc);
  }
  dem_->begin_fluid();
  const std::size_t W = undisturbed_ ? 26 : 14;
  std::vector<double> acc(W * particles_.size(), 0.0);
  std::vector<PointInCell> cellsOfParticle;  // a footprint's weight per cell
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    double* a = &acc[W * i];
    if (undisturbed_) cellsOfParticle.clear();
    for (std::size_t j = first_[i]; j < first_[i + 1]; ++j) {
      const label c = points_[j].cell;
      const double w = points_[j].weight;
      if (sharpInterface_) {
        const double wu = w * velocityScale_[c], wg = w * gradScale_[c];
        for (int d = 0; d < 3; ++d) {
          a[d] += wu * (*Uc)[c][d];
          a[4 + d] += wg * (*Gc)[c][d];
        }
        a[3] += w * dragVoidFraction_[c];
      } else {
        for (int d = 0; d < 3; ++d) {
          a[d] += w * (*Uc)[c][d];
          a[4 + d] += w * (*Gc)[c][d];
        }
        a[3] += w * voidFraction_[c];
      }
      for (int d = 0; d < 3; ++d) {
        a[7 + d] += w * (*Tc)[c][d];
        if (curl) a[10 + d] += w * (*Cc)[c][d];
      }
      a[13] += w;
      if (undisturbed_) addDisturbancePoint(i, c, w, a + 13, cellsOfParticle);
    }
    if (undisturbed_) addOwnShare(cellsOfParticle, a + 13);
  }
  const std::vector<double> sums = dem_->sum_onto_owners(acc, W);
  for (std::size_t i = 0; i < local; ++i) {
    const double* a = &sums[W * i];
    const double norm = a[13] > 0 ? 1 / a[13] : 0;
    coupling::FluidAtParticle f;
    for (int d = 0; d < 3; ++d) {
      f.velocity[d] = a[d] * norm;
      f.pressure_gradient[d] = a[4 + d] * norm;
      f.viscous_stress_divergence[d] = a[7 + d] * norm;
      f.vorticity[d] = a[10 + d] * norm;
    }
    f.void_fraction = a[13] > 0 ? a[3] * norm : 1.0;
    if (undisturbed_) setDisturbance(i, a + 13, f);
    dem_->add_fluid(f);
  }
}

// With undisturbedVelocity, per footprint point (cell c, weight w) of particle i: into b[0..12]
// (b[0] the weight sum, added by the caller) the other particles' drag per volume there
// (b[1]), the cells' size V^(2/3) (b[3]), and the footprint's weight marginal on each axis
// over the cells at offsets -1, 0, 1 from the particle's own (b[4 + 3 a + 1 + offset]): the
// offset of a cell along a is round((C_a - x_a) / h_c), h_c = V^(1/3), from the particle's
// (or its periodic image's) centre, the same on every rank. `cells` gathers the footprint's
// weight per cell for addOwnShare.
void ParticleCoupling::addDisturbancePoint(std::size_t i, Foam::label c, double w, double* b,
                                           std::vector<PointInCell>& cells) const {
  const double V = mesh_.V()[c];
  const Foam::vector& C = mesh_.C()[c];
  b[1] += w * (smoothing_ ? rawKsl_[c] : Ksl_[c]);
  const double hc = std::cbrt(V);
  b[3] += w * hc * hc;
  const double* centre = particles_.x(i);
  for (int d = 0; d < 3; ++d) {
    const double o = std::floor((C[d] - centre[d]) / hc + 0.5);
    if (o >= -1 && o <= 1) b[5 + 3 * d + static_cast<int>(o)] += w;
  }
  for (PointInCell& q : cells)
    if (q.cell == c) {
      q.weight += w;
      return;
    }
  cells.push_back({c, w});
}

// The particle's own share of the Ksl it read: K W_c^2 / V_c summed over its cells (b[2]).
void ParticleCoupling::addOwnShare(const std::vector<PointInCell>& cells, double* b) const {
  for (const PointInCell& q : cells) b[2] += q.weight * q.weight / mesh_.V()[q.cell];
}

// The disturbance of local particle i from its summed b[0..12] (addDisturbancePoint). The
// disturbance read is that of the mesh's lattice (self_disturbance.hpp,
// lattice_self_disturbance): cells of size h = <V^(2/3)>^(1/2) over the footprint, the
// footprint's own spread (its points' standard deviation per axis) and the other particles'
// drag per volume; the particle's place across its motion from its marginals, if they hold
// all its weight. With sampling cellPoint also its offset from the centre of the cell that
// holds it.
void ParticleCoupling::setDisturbance(std::size_t i, const double* b,
                                      coupling::FluidAtParticle& f) const {
  if (b[0] <= 0) return;
  const double norm = 1 / b[0];
  f.disturbance_cell = std::sqrt(b[3] * norm);
  f.disturbance_spread = footprintSpread_ * particles_.radius(i);
  if (smoothing_) f.disturbance_smoothing = smoothing_->bandwidth() / std::sqrt(2.0);
  f.disturbance_screening = std::max(0.0, (b[1] - particles_.drag_coefficient(i) * b[2]) * norm);
  f.disturbance_placed = true;
  for (int d = 0; d < 3; ++d) {
    const double* m = &b[4 + 3 * d];
    if (m[0] + m[1] + m[2] < b[0] * (1 - 1e-9)) f.disturbance_placed = false;
    for (int k = 0; k < 3; ++k) f.disturbance_weights[d][k] = m[k] * norm;
  }
  if (sampling_ == Sampling::cellPoint && centreCell_[i] >= 0) {
    const Foam::label c = centreCell_[i];
    const double hc = std::cbrt(mesh_.V()[c]);
    f.disturbance_cell_point = true;
    for (int d = 0; d < 3; ++d)
      f.disturbance_place[d] = (particles_.x(i)[d] - mesh_.C()[c][d]) / hc;
  }
}

// sample() with cellPoint: per particle over its footprint, the cell velocity U_fp as the
// implicit exchange takes it (the deposit's weights, as checkBalance reads it), for the DEM
// to return the drag's remainder K (u_f - U_fp) explicitly; with
// undisturbedVelocity also the disturbance's sums (as the cell path gathers them with its
// samples). One gather, onto the DEM's records.
void ParticleCoupling::sampleFootprint() {
  const std::size_t W = undisturbed_ ? 16 : 4;  // weight, [disturbance 1-12], U_fp sums
  const Foam::vectorField& Up = sampledU();
  std::vector<double> acc(W * particles_.size(), 0.0);
  std::vector<PointInCell> cellsOfParticle;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    double* b = &acc[W * i];
    cellsOfParticle.clear();
    for (std::size_t j = first_[i]; j < first_[i + 1]; ++j) {
      const Foam::label c = points_[j].cell;
      const double w = points_[j].weight;
      b[0] += w;
      for (int d = 0; d < 3; ++d) b[W - 3 + d] += w * Up[c][d];
      if (undisturbed_) addDisturbancePoint(i, c, w, b, cellsOfParticle);
    }
    if (undisturbed_) addOwnShare(cellsOfParticle, b);
  }
  const std::vector<double> sums = dem_->sum_onto_owners(acc, W);
  std::vector<std::array<double, 3>> cellVelocity(particles_.local());
  for (std::size_t i = 0; i < particles_.local(); ++i) {
    const double* b = &sums[W * i];
    const double norm = b[0] > 0 ? 1 / b[0] : 0;
    for (int d = 0; d < 3; ++d) cellVelocity[i][d] = b[W - 3 + d] * norm;
    if (undisturbed_) {
      coupling::FluidAtParticle f;
      setDisturbance(i, b, f);
      dem_->set_fluid_disturbance(i, f);
    }
  }
  dem_->set_fluid_cell_velocities(std::move(cellVelocity));
}

coupling::FluidAtParticle ParticleCoupling::sampleAt(const std::array<double, 3>& x) const {
  // A particle that reached this rank during the DEM sub-steps: the cell holding it.
  coupling::FluidAtParticle f;
  const Foam::label c = locate(Foam::point(x[0], x[1], x[2]));
  if (c < 0) return f;
  f.velocity = toArray(sampledU()[c]);
  f.void_fraction = voidFraction_[c];
  if (T_) f.temperature = (*T_)[c];
  if (meanGradPOn_) f.pressure_gradient = toArray(meanGradP_);
  if (sharpInterface_) {
    for (double& u : f.velocity) u *= velocityScale_[c];
    f.void_fraction = dragVoidFraction_[c];
  }
  return f;
}

void ParticleCoupling::checkBalance() {
  using namespace Foam;
  // Particle side: K (u_p - v) + F_exchange, with u_p the footprint-weighted U (smoothed
  // with diffusionBandwidth, as sample() read it).
  const vectorField& Up = sampledU();
  constexpr std::size_t W = 4;
  std::vector<double> acc(W * particles_.size(), 0.0);
  for (std::size_t i = 0; i < particles_.size(); ++i)
    for (std::size_t j = first_[i]; j < first_[i + 1]; ++j) {
      const label c = points_[j].cell;
      const double w = points_[j].weight;
      const double ws = sharpInterface_ ? w * velocityScale_[c] : w;
      for (int d = 0; d < 3; ++d) acc[W * i + d] += ws * Up[c][d];
      acc[W * i + 3] += w;
    }
  const std::vector<double> u = dem_->sum_onto_owners(acc, W);
  double totals[7] = {0, 0, 0, 0, 0, 0, 0};  // particle force, fluid source, magnitude
  for (std::size_t i = 0; i < particles_.local(); ++i)
    for (int d = 0; d < 3; ++d) {
      const double f = particles_.drag_coefficient(i) * (u[W * i + d] - particles_.v(i)[d]) +
                       particles_.exchange_force(i)[d];
      totals[d] += f;
      totals[6] += std::abs(f);
    }
  const scalarField& V = mesh_.V().field();
  forAll(V, c)
    for (int d = 0; d < 3; ++d)
      totals[3 + d] += V[c] * (-Ksl_[c] * U_[c][d] + KslUs_[c][d] + fExplicit_[c][d]);
  MPI_Allreduce(MPI_IN_PLACE, totals, 7, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  double worst = 0;
  for (int d = 0; d < 3; ++d) worst = std::max(worst, std::abs(totals[d] + totals[3 + d]));
  balanceError_ = totals[6] > 0 ? worst / totals[6] : 0.0;
  depositSums();
  const double volumeError =
      particleVolume_ > 0
          ? std::abs(meshSolidVolume_ + stepClampedVolume_ - particleVolume_) / particleVolume_
          : 0.0;
  Info << "grainFoam void fraction: sum (1-eps) V = " << meshSolidVolume_
       << " m^3, clamped away " << stepClampedVolume_ << " m^3, particles " << particleVolume_
       << " m^3, relative difference " << volumeError << endl;
  Info << "grainFoam exchange balance: particles (" << totals[0] << " " << totals[1] << " "
       << totals[2] << ") N, fluid (" << totals[3] << " " << totals[4] << " " << totals[5]
       << ") N, relative imbalance " << balanceError_ << endl;
}

void ParticleCoupling::setTemperature(const Foam::volScalarField& T, double rhoCp,
                                      double conductivity, const Foam::fileName& propertiesFile) {
  using namespace Foam;
  const auto differ = [](double a, double b) {
    return std::abs(a - b) > 1e-9 * std::max(std::abs(a), std::abs(b));
  };
  const double cp = rhoCp / rho_;
  std::ostringstream why;
  if (differ(cp, dem_->fluid_heat_capacity()))
    why << "\n" << dem_->fluid_source() << ": error: fluid.heat_capacity is "
        << dem_->fluid_heat_capacity() << " J/(kg K) but " << propertiesFile << " has Cp " << cp
        << " J/(kg K); make them equal";
  if (differ(conductivity, dem_->fluid_conductivity()))
    why << "\n" << dem_->fluid_source() << ": error: fluid.conductivity is "
        << dem_->fluid_conductivity() << " W/(m K) but " << propertiesFile << " has kappa "
        << conductivity << " W/(m K); make them equal";
  if (!why.str().empty()) FatalErrorInFunction << why.str().c_str() << exit(FatalError);
  T_ = &T;
  rhoCp_ = rhoCp;
  heatResponse_.reset(new volScalarField(
      derivedField(mesh_, "heatResponse", false), mesh_,
      dimensionedScalar("zero", dimensionSet(1, -1, -3, -1, 0), 0), derivedPatchTypes(mesh_)));
  heatSource_.reset(new volScalarField(derivedField(mesh_, "heatSource", false), mesh_,
                                       dimensionedScalar("zero", dimensionSet(1, -1, -3, 0, 0), 0),
                                       derivedPatchTypes(mesh_)));
  Info << "grainFoam heat: fluid energy equation on, rho c_p " << rhoCp << " J/(m^3 K), k_f "
       << conductivity << " W/(m K) (" << propertiesFile << "); convection law of "
       << dem_->fluid_source().c_str() << endl;
}

void ParticleCoupling::sampleTemperature() {
  using namespace Foam;
  const volScalarField& T = *T_;
  // The footprint weights of the deposit (as `cell` sampling), ghosts' shares to owners.
  constexpr std::size_t W = 2;
  std::vector<double> acc(W * particles_.size(), 0.0);
  for (std::size_t i = 0; i < particles_.size(); ++i)
    for (std::size_t j = first_[i]; j < first_[i + 1]; ++j) {
      acc[W * i] += points_[j].weight * T[points_[j].cell];
      acc[W * i + 1] += points_[j].weight;
    }
  const std::vector<double> sums = dem_->sum_onto_owners(acc, W);
  const double fallback = gAverage(T.primitiveField());
  std::vector<double> t(particles_.local());
  for (std::size_t i = 0; i < t.size(); ++i)
    t[i] = sums[W * i + 1] > 0 ? sums[W * i] / sums[W * i + 1]
                               : (centreCell_[i] >= 0 ? T[centreCell_[i]] : fallback);
  dem_->set_fluid_temperatures(std::move(t));
}

void ParticleCoupling::depositHeat() {
  using namespace Foam;
  dem_->heat_exchange(subSteps_, heatExchange_);
  const label n = mesh_.nCells();
  heatCell_.setSize(n);
  responseCell_.setSize(n);
  heatCell_ = 0.0;
  responseCell_ = 0.0;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    const double e = heatExchange_.heat[i], g = heatExchange_.response[i];
    for (std::size_t j = first_[i]; j < first_[i + 1]; ++j) {
      heatCell_[points_[j].cell] += points_[j].weight * e;
      responseCell_[points_[j].cell] += points_[j].weight * g;
    }
  }
  // Particles that left this rank during the advance: their heat where they last took it,
  // or, when that position already lies beyond this rank's cells (the step that took them
  // across a processor plane or a periodic face), in this rank's nearest cell.
  for (std::size_t k = 0; k < heatExchange_.orphan_heat.size(); ++k) {
    const std::array<double, 3>& x = heatExchange_.orphan_position[k];
    label c = locate(point(x[0], x[1], x[2]));
    if (c < 0 && n > 0) c = mesh_.findNearestCell(point(x[0], x[1], x[2]));
    if (c >= 0)
      heatCell_[c] += heatExchange_.orphan_heat[k];
    else
      lostHeat_ += heatExchange_.orphan_heat[k];
  }
  const scalarField& V = mesh_.V().field();
  const double dt = mesh_.time().deltaTValue();
  scalarField& KT = heatResponse_->primitiveFieldRef();
  scalarField& Q = heatSource_->primitiveFieldRef();
  forAll(V, c) {
    KT[c] = responseCell_[c] / (V[c] * dt);
    Q[c] = heatCell_[c] / (V[c] * dt);
  }
}

void ParticleCoupling::exchangeHeat(const Foam::volScalarField& T, const Foam::volScalarField& T0) {
  using namespace Foam;
  const Stopwatch clock;
  std::vector<double> acc(particles_.size(), 0.0);
  for (std::size_t i = 0; i < particles_.size(); ++i)
    for (std::size_t j = first_[i]; j < first_[i + 1]; ++j)
      acc[i] += points_[j].weight * (T[points_[j].cell] - T0[points_[j].cell]);
  const std::vector<double> change = dem_->sum_onto_owners(acc, 1);
  std::vector<double> joules(particles_.local());
  // particle side, fluid side, scale, heat lost (orphans outside every cell)
  double sums[4] = {0, 0, 0, lostHeat_};
  for (std::size_t i = 0; i < joules.size(); ++i) {
    joules[i] = heatExchange_.response[i] * change[i];
    sums[0] += heatExchange_.heat[i] + joules[i];
    sums[2] += std::abs(heatExchange_.heat[i]) + std::abs(joules[i]);
  }
  for (const double e : heatExchange_.orphan_heat) {
    sums[0] += e;
    sums[2] += std::abs(e);
  }
  try {
    dem_->add_heat(joules);
  } catch (const std::exception& e) {
    FatalErrorInFunction << "\n" << e.what() << exit(FatalError);
  }
  forAll(heatCell_, c) sums[1] -= heatCell_[c] + responseCell_[c] * (T[c] - T0[c]);
  MPI_Allreduce(MPI_IN_PLACE, sums, 4, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  particleHeatTotal_ += sums[0];
  fluidHeatTotal_ += sums[1];
  add(kCoupling, clock);
  const Time& time = mesh_.time();
  if (!time.writeTime() && time.timeIndex() != restartIndex_ + 1) return;
  const double imbalance = sums[2] > 0 ? std::abs(sums[0] + sums[1]) / sums[2] : 0.0;
  const std::array<double, 2> particles = dem_->thermal_energy();
  const scalarField epsV(voidFraction_.primitiveField() * mesh_.V().field());
  const double fluidEnergy = rhoCp_ * gSum(epsV * T.primitiveField());
  const double fluidCapacity = rhoCp_ * gSum(epsV);
  Info << "grainFoam heat exchange: particles took " << sums[0] << " J from the fluid in the "
       << "last step, the fluid " << sums[1] << " J from the particles, relative imbalance "
       << imbalance << "; since the run's start: particles " << particleHeatTotal_ << " J, fluid "
       << fluidHeatTotal_ << " J; lost (outside the mesh) " << sums[3] << " J" << endl;
  Info << "grainFoam thermal energy: particles " << particles[0] << " J (m c " << particles[1]
       << " J/K), fluid " << fluidEnergy << " J (eps rho c_p V " << fluidCapacity
       << " J/K), sum " << particles[0] + fluidEnergy << " J" << endl;
}

void ParticleCoupling::updateMeanPressureGradient() {
  const std::array<double, 3> w = dem_->buoyant_weight();
  for (int d = 0; d < 3; ++d) meanGradP_[d] = w[d] / domainVolume_;
}

void ParticleCoupling::reportMixtureMomentum() {
  using namespace Foam;
  // The mixture's momentum: with G carrying the buoyant weight the net force on it is zero,
  // so it stays what it was (zero from rest) up to the discretisation's lag.
  vector fluid = rho_ * gSum(voidFraction_.primitiveField() * mesh_.V().field() *
                             U_.primitiveField());
  const std::array<double, 3> particles = dem_->momentum();
  Info << "grainFoam mean pressure gradient: G = " << meanGradP_ << " Pa/m; momentum: fluid ("
       << fluid[0] << " " << fluid[1] << " " << fluid[2] << ") kg m/s, particles ("
       << particles[0] << " " << particles[1] << " " << particles[2] << ") kg m/s" << endl;
}

ParticleCoupling::FluidState ParticleCoupling::fluidState(bool collective) const {
  using namespace Foam;
  // Called when something diverged: the speeds may overflow when squared.
  const FloatingPointTrapsOff trapsOff;
  const scalarField& now = voidFraction_.primitiveField();
  const scalarField& before = voidFraction_.oldTime().primitiveField();
  const vectorField& u = U_.oldTime().primitiveField();
  const scalar dt = mesh_.time().deltaTValue();
  const label me = collective ? Pstream::myProcNo() : 0, none = Pstream::nProcs();
  scalar jump = -1, speed = 0, courant = 0;
  label at = -1;
  forAll(now, i) {
    if (mag(now[i] - before[i]) > jump) {
      jump = mag(now[i] - before[i]);
      at = i;
    }
    const scalar s = std::hypot(u[i].x(), u[i].y(), u[i].z());
    if (!std::isfinite(s)) continue;
    speed = max(speed, s);
    courant = max(courant, s * dt / std::cbrt(mesh_.V()[i]));
  }
  scalar maxJump = jump, from = at >= 0 ? before[at] : 0, to = at >= 0 ? now[at] : 0;
  vector where = at >= 0 ? mesh_.C()[at] : vector::zero;
  if (collective) {
    maxJump = returnReduce(jump, maxOp<scalar>());
    const label owner = returnReduce(jump == maxJump ? me : none, minOp<label>());
    const bool mine = me == owner && at >= 0;
    from = returnReduce(mine ? from : 0.0, sumOp<scalar>());
    to = returnReduce(mine ? to : 0.0, sumOp<scalar>());
    where = returnReduce(mine ? where : vector::zero, sumOp<vector>());
    speed = returnReduce(speed, maxOp<scalar>());
    courant = returnReduce(courant, maxOp<scalar>());
  }
  FluidState state;
  state.jump = collective ? max(maxJump, 0.0) : 0.0;
  state.speed = speed;
  state.courant = courant;
  std::ostringstream m;
  m.precision(4);
  if (!collective) {
    // Between the fluid steps eps and its old time are one field: no jump to report.
    m << "The fluid the particles moved in (this rank's cells) ran at up to " << speed
      << " m/s, a Courant number of " << courant << " (voidFraction " << voidFractionMethod_
      << ", ddtVoidFraction " << (ddtVoidFraction_ ? "on" : "off") << ", minVoidFraction "
      << minVoidFraction_ << ").";
  } else {
    m << "In this fluid step the void fraction changed by up to " << state.jump
      << " in one cell (from " << from << " to " << to << " at (" << where.x() << " " << where.y()
      << " " << where.z() << ") m; minVoidFraction " << minVoidFraction_ << ", voidFraction "
      << voidFractionMethod_ << ", ddtVoidFraction " << (ddtVoidFraction_ ? "on" : "off")
      << "); before it the fluid "
      << "moved at up to " << speed << " m/s, a Courant number of " << courant << ".";
  }
  state.text = m.str();
  return state;
}

void ParticleCoupling::checkStartingFlow() {
  using namespace Foam;
  const FloatingPointTrapsOff trapsOff;  // a typo's 1e200 m/s must not overflow here
  const scalar dt = mesh_.time().deltaTValue();
  const scalarField& V = mesh_.V();
  scalar courant = 0, speed = 0;
  vector where = Zero;
  label part = -1;  // the patch, or -1: the internal field
  const auto consider = [&](const vector& u, label cell, const vector& at, label in) {
    const scalar s = std::hypot(u.x(), u.y(), u.z());
    const scalar co = s * dt / std::cbrt(V[cell]);
    if (!(co <= courant)) {  // also takes a non-finite value
      courant = co;
      speed = s;
      where = at;
      part = in;
    }
  };
  forAll(U_, i) consider(U_[i], i, mesh_.C()[i], -1);
  forAll(U_.boundaryField(), patch) {
    const fvPatch& fp = mesh_.boundary()[patch];
    if (fp.coupled()) continue;  // cyclic and processor faces repeat cells' values
    const labelUList& cells = fp.faceCells();
    forAll(cells, f) consider(U_.boundaryField()[patch][f], cells[f], fp.Cf()[f], patch);
  }
  const scalar worst = returnReduce(courant, maxOp<scalar>());
  startCourant_ = worst;
  if (!(worst > 1)) return;
  const label me = Pstream::myProcNo(), none = Pstream::nProcs();
  const bool mine = me == returnReduce(courant == worst ? me : none, minOp<label>());
  speed = returnReduce(mine ? speed : 0.0, sumOp<scalar>());
  where = returnReduce(mine ? where : vector::zero, sumOp<vector>());
  part = returnReduce(mine ? part : labelMin, maxOp<label>());  // the physical patches'
  const word in = part >= 0 ? "patch " + mesh_.boundary()[part].name() : "internalField";
  std::ostringstream m;
  m.precision(4);
  m << U_.time().timeName() << "/U starts the fluid at up to " << speed << " m/s (its " << in
    << ", at (" << where.x() << " " << where.y() << " " << where.z() << ") m), a Courant number "
    << "of " << worst << " at deltaT " << dt << " s";
  startFlow_ = m.str();
  Info << "grainFoam coupling: warning: " << startFlow_.c_str()
       << "; a fluid step carries a Courant number up to about 1, so the run may diverge: "
          "check that field for a speed the case does not mean, or lower deltaT "
          "(system/controlDict)"
       << endl;
}

std::string ParticleCoupling::remedies(const FluidState& state) const {
  const Foam::Time& time = mesh_.time();
  std::ostringstream m;
  m.precision(4);
  if (state.courant > 1) {
    // One fluid step moves the fastest fluid further than a cell: more than the PISO/PIMPLE
    // step carries.
    if (startCourant_ > 1) {
      m << "the run started above 1 (" << startFlow_.c_str()
        << "): check that field for a speed the case does not mean; a fluid step carries a "
           "Courant number up to about 1";
    } else {
      m << "a smaller deltaT in system/controlDict (now " << time.deltaTValue() << " s, "
        << subSteps_ << " DEM step" << (subSteps_ == 1 ? "" : "s")
        << "; the Courant number above should stay below 1";
      if (subSteps_ == 1)
        m << "; deltaT is a whole number of DEM steps, so lower the scene's time step with it "
             "(time.step, or time.rayleigh_fraction)";
      // A restart keeps the deltaT its time was run with (the restart check says so).
      if (restartIndex_ > 0 || time.timeIndex() > 1)
        m << "; a restart continues with the deltaT its time was run with, so a new deltaT "
             "means a new run from time 0 (to keep the particles, insert a snapshot with "
             "`type: snapshot`)";
      m << ")";
    }
    if (state.jump > 0.25) m << "; or, for the void fraction's jump, " << jumpRemedies();
    return m.str();
  }
  return jumpRemedies();
}

std::string ParticleCoupling::jumpRemedies() const {
  std::string m;
  if (voidFractionMethod_ == "centre")
    m += "voidFraction divided in constant/couplingProperties (each particle's volume spread "
         "over the cells it overlaps, so eps changes as it crosses); ";
  if (ddtVoidFraction_)
    m += "ddtVoidFraction off in constant/couplingProperties (knowingly: continuity then "
         "leaves out d(eps)/dt); ";
  m += (m.empty() ? "" : "or ");
  m += "cells several particle diameters wide (docs/coupling.md, \"Known limits\"); a "
       "smaller deltaT only helps when the Courant number above is near 1 or more";
  return m;
}

void ParticleCoupling::evolve() {
  Stopwatch clock;
  sample();  // straight into the DEM (DemLink::fluid_samples or add_fluid)
  if (T_) sampleTemperature();
  if (lateSamplerSet_) {
    dem_->end_fluid();  // the sampler of late arrivals stays sampleAt
  } else {
    dem_->end_fluid([this](const std::array<double, 3>& x) { return sampleAt(x); });
    lateSamplerSet_ = true;
  }
  add(kCoupling, clock);
  clock.restart();
  try {
    dem_->advance(subSteps_, snapshotDir_);
  } catch (const std::exception& e) {
    // The fluid the particles moved in, from this rank's cells (no collective here: the
    // other ranks need not be in this branch). When its void fraction jumped or it ran fast,
    // the particles' speeds in the message may be the fluid's doing.
    const FluidState state = fluidState(false);
    std::string fluid = state.text;
    bool jumpy = state.jumpy();
    // Faster than the scene says particles move (time.expected_max_speed): a fluid that
    // fast throws them about.
    const double expected = dem_->expected_max_speed();
    scalar fastest = 0;
    for (const vector& u : U_.primitiveField()) {
      const scalar s = std::hypot(u.x(), u.y(), u.z());  // no overflow for |u| < 1e308
      if (std::isfinite(s)) fastest = max(fastest, s);
    }
    if (fastest > expected) {
      std::ostringstream t;
      t.precision(4);
      t << " That is faster than the scene's time.expected_max_speed, " << expected << " m/s.";
      fluid += t.str();
      jumpy = true;
    }
    if (jumpy)
      fluid +=
          " The fluid may be what drove the particles: if their speeds above are "
          "unphysical, what changes it: " +
          remedies(state);
    FatalErrorInFunction << "\n"
                         << e.what() << "\ngrainFoam: " << fluid.c_str()
                         << Foam::exit(Foam::FatalError);
  }
  add(kDem, clock);
  clock.restart();
  buildFootprints();
  deposit();
  if (T_) depositHeat();
  if (meanGradPOn_) updateMeanPressureGradient();
  if (mesh_.time().writeTime() || mesh_.time().timeIndex() == 1) {
    checkBalance();
    if (meanGradPOn_) reportMixtureMomentum();
  }
  add(kCoupling, clock);
}

void ParticleCoupling::writeSnapshot() {
  const Foam::Time& time = mesh_.time();
  for (const std::string& note :
       dem_->write_snapshot(snapshotDir_, time.timeIndex(), restartIndex_ > 0 ? restartIndex_ : -1))
    Foam::Info << "grainFoam: note: " << note.c_str() << Foam::endl;
}

void ParticleCoupling::writeSnapshotIfDue() {
  using namespace Foam;
  if (snapshotInterval_ <= 0) return;
  const Time& time = mesh_.time();
  const double t = time.value(), dt = time.deltaTValue();
  const bool first = time.timeIndex() == 0 && restartIndex_ == 0;
  const bool last = t >= time.endTime().value() - 0.5 * dt;
  if (!first && !last && t < (snapshotIndex_ + 1) * snapshotInterval_ - 0.5 * dt) return;
  if (last && lastSnapshotIndex_ == time.timeIndex()) return;
  const Stopwatch clock;
  try {
    writeSnapshot();
  } catch (const std::exception& e) {
    FatalErrorInFunction << "\n" << e.what() << exit(FatalError);
  }
  add(kOutput, clock);
  snapshotIndex_ = static_cast<long>(std::floor(t / snapshotInterval_ + 0.5));
  lastSnapshotIndex_ = time.timeIndex();
}

void ParticleCoupling::purgeCheckpoints(const std::string& newest) {
  using namespace Foam;
  // OpenFOAM's purgeWrite deletes the time folders this run wrote beyond the newest N (its
  // list holds only this run's times: the folders of the run a restart continues stay). A
  // checkpoint is deleted when this run wrote it and no time folder names it any more, so
  // every time folder that exists keeps its checkpoint. Called after runTime.write(), which
  // purges the folders first.
  const Time& time = mesh_.time();
  if (std::find(ownCheckpoints_.begin(), ownCheckpoints_.end(), newest) == ownCheckpoints_.end())
    ownCheckpoints_.push_back(newest);
  if (time.controlDict().lookupOrDefault<label>("purgeWrite", 0) <= 0 || !Pstream::master()) return;
  std::set<std::string> named{newest};
  for (const auto& folder : keptTimeFolders(time.rootPath() / time.globalCaseName()))
    named.insert(folder.second);
  std::vector<std::string> kept;
  for (const std::string& name : ownCheckpoints_) {
    if (named.count(name)) {
      kept.push_back(name);
      continue;
    }
    std::error_code error;
    std::filesystem::remove(std::string(snapshotDir_ / name), error);
    if (error)
      Info << "grainFoam coupling: warning: could not delete the old checkpoint "
           << (snapshotDir_ / name).c_str() << ": " << error.message().c_str() << endl;
  }
  ownCheckpoints_.swap(kept);
}

void ParticleCoupling::write() {
  using namespace Foam;
  Stopwatch clock;
  const Time& time = mesh_.time();
  // output.wall_loads: taken before the checkpoint, which then starts the next interval
  // (a restart from it reports the same loads as the uninterrupted run).
  const std::string wallLoads = wallLoadLine();
  std::string checkpoint;
  try {
    if (snapshotInterval_ <= 0) writeSnapshot();
    // Old checkpoints are deleted here (purgeCheckpoints), not by the DEM's series.
    checkpoint = dem_->write_checkpoint(snapshotDir_, INT_MAX);
  } catch (const std::exception& e) {
    FatalErrorInFunction << "\n" << e.what() << exit(FatalError);
  }
  // The time directory names its checkpoint (a restart from this time reads it).
  IOdictionary info(IOobject("grainflowCheckpoint", time.timeName(), "uniform", time,
                             IOobject::NO_READ, IOobject::NO_WRITE, false));
  info.add("checkpoint", word(checkpoint));
  info.add("checkpointChecksum",
           word("fnv1a64_" + checkpointChecksum(std::string(snapshotDir_ / checkpoint))));
  info.add("demStep", label(dem_->steps()));
  info.add("demTime", dem_->time());
  info.add("depositSettings", string(depositSettings_));
  info.regIOobject::write();
  purgeCheckpoints(checkpoint);
  // The particle output is timed apart: like the fluid's field output (runTime.write()),
  // it is not part of the DEM / coupling / fluid split.
  add(kOutput, clock);
  clock.restart();
  // Writing the checkpoint rebuilt the DEM's lists and reordered its particles: the next
  // fluid samples must follow the new order.
  buildFootprints();
  add(kCoupling, clock);
  depositSums();
  const coupling::DemSummary s = dem_->summary();
  double counts[3] = {double(clampedCells_), clampedVolume_, 0};
  MPI_Allreduce(MPI_IN_PLACE, counts, 2, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  double times[8];
  std::copy(seconds_, seconds_ + 8, times);
  MPI_Allreduce(MPI_IN_PLACE, times, 8, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  double interval[8];
  for (int k = 0; k < 8; ++k) {
    interval[k] = times[k] - reportedSeconds_[k];
    reportedSeconds_[k] = times[k];
  }
  const auto split = [](const double* t) {
    const double total = t[0] + t[1] + t[2];
    const auto share = [total](double x) { return total > 0 ? 100 * x / total : 0.0; };
    std::ostringstream text;
    text.precision(3);
    text << "DEM " << t[0] << " s (" << share(t[0]) << " %), coupling " << t[1] << " s ("
         << share(t[1]) << " %), fluid " << t[2] << " s (" << share(t[2]) << " %); particle output "
         << t[3] << " s (snapshots, checkpoints; not in the shares)";
    return text.str();
  };
  const std::string cellPoint = cellPointLine();
  // Per rank (parallel runs): the particles it owns and its own wall-clock split since the
  // last write, the DEM's part split into work and waiting for the other ranks, which
  // shows how evenly the shared decomposition spreads the work (docs/parallel.md).
  std::string perRank;
  if (Pstream::parRun()) {
    const double now[5] = {double(s.local_particles), seconds_[kDem] - s.collective_wait_seconds,
                           s.collective_wait_seconds, seconds_[kCoupling], seconds_[kFluid]};
    double mine[5] = {now[0], 0, 0, 0, 0};
    for (int k = 1; k < 5; ++k) {
      mine[k] = now[k] - reportedRank_[k];
      reportedRank_[k] = now[k];
    }
    int ranks = 1, rank = 0;
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    std::vector<double> all(rank == 0 ? 5 * ranks : 0);
    MPI_Gather(mine, 5, MPI_DOUBLE, all.data(), 5, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    std::ostringstream text;
    text.precision(3);
    for (int r = 0; r < (rank == 0 ? ranks : 0); ++r) {
      const double* v = &all[5 * r];
      text << "\ngrainFoam rank " << r << " since the last write: " << long(v[0])
           << " particles; DEM " << v[1] << " s working + " << v[2]
           << " s waiting for other ranks, coupling " << v[3] << " s, fluid " << v[4] << " s";
    }
    perRank = text.str();
  }
  Foam::Info << "grainFoam particles: " << s.particles << " particles, " << s.contacts
             << " contacts, max overlap " << s.max_overlap_ratio << " r, removed " << s.removed
             << ", sampled on arrival " << s.late_samples << "; void fraction clamped "
             << Foam::label(counts[0]) << " cell-steps (" << counts[1]
             << " m^3 solid volume removed), volume not deposited " << lostVolume_ << " m^3\n"
             << cellPoint.c_str()
             << "grainFoam time split since the last write: " << split(interval).c_str() << "\n"
             << "grainFoam time split: " << split(times).c_str() << "\n"
             << "grainFoam CPU time split since the last write: " << split(interval + 4).c_str()
             << "\n"
             << "grainFoam CPU time split: " << split(times + 4).c_str() << perRank.c_str()
             << wallLoads.c_str() << Foam::endl;
  // reports() is collective (the drag's beyond-range count is summed over the ranks).
  for (const std::string& report : dem_->reports()) {
    std::istringstream lines(report);
    for (std::string line; std::getline(lines, line);) {
      if (undisturbed_ && line.rfind("undisturbed velocity", 0) == 0)
        Foam::Info << "grainFoam " << line.c_str()
                   << (Pstream::parRun() ? " (particles of rank 0)" : "") << Foam::endl;
      if (line.find(": warning: fluid.drag: ") != std::string::npos)
        Foam::Info << "grainFoam coupling: " << line.c_str() << Foam::endl;
    }
  }
}

void ParticleCoupling::checkPeriodicSides(const fvMesh& mesh, const fileName& sceneFile) const {
  // Per axis and side: the first patch (by index; the patches are the same on every rank)
  // with faces on that side of the box, periodic (cyclic, not processor) or not. A particle
  // crosses a side where the scene's domain is periodic, and stays where it is not: the
  // fluid must do the same, or the particles' volume and drag land where the fluid cannot
  // follow (and a particle passes through the fluid's wall).
  static const char* axis = "xyz";
  const label none = labelMax;
  label walled[3] = {none, none, none}, cyclic[3] = {none, none, none};
  forAll(mesh.boundary(), patch) {
    const fvPatch& fp = mesh.boundary()[patch];
    if (fp.size() == 0 || isA<processorFvPatch>(fp)) continue;
    const vectorField n(fp.nf());
    const vectorField c(fp.Cf());
    forAll(n, f) for (int a = 0; a < 3; ++a) {
      if (std::abs(n[f][a]) < 0.999) continue;
      const double tol = 1e-9 * (domain_.hi[a] - domain_.lo[a]);
      if (std::abs(c[f][a] - domain_.lo[a]) > tol && std::abs(c[f][a] - domain_.hi[a]) > tol)
        continue;
      label& first = fp.coupled() ? cyclic[a] : walled[a];
      first = std::min(first, label(patch));
    }
  }
  for (int a = 0; a < 3; ++a) {
    reduce(walled[a], minOp<label>());
    reduce(cyclic[a], minOp<label>());
    const label patch = periodic_[a] ? walled[a] : cyclic[a];
    if (patch == none) continue;
    const fvPatch& fp = mesh.boundary()[patch];
    if (periodic_[a])
      FatalErrorInFunction
          << "the scene's domain is periodic along " << axis[a] << " (domain.periodic in "
          << sceneFile << ") but the mesh closes the " << axis[a] << " sides with patch '"
          << fp.name() << "' (type " << fp.type() << "): a particle would pass through the "
          << "fluid's boundary and come back on the other side, with its volume and drag on "
             "the wrong side. Make the mesh periodic along "
          << axis[a]
          << " (a cyclic patch pair in system/blockMeshDict), or make the scene "
             "bounded along "
          << axis[a] << " (domain.periodic false, with wall planes where the mesh has walls)"
          << exit(FatalError);
    FatalErrorInFunction
        << "the mesh is periodic along " << axis[a] << " (patch '" << fp.name() << "', type "
        << fp.type() << ") but the scene's domain is not (domain.periodic in " << sceneFile
        << "): the fluid would leave through one side and come back through the other while "
           "the particles stop at the side or are removed there. Make the scene periodic "
           "along "
        << axis[a] << " (domain.periodic), or give the mesh walls or an outlet on the " << axis[a]
        << " sides" << exit(FatalError);
  }
}

std::string ParticleCoupling::wallLoadLine() {
  double interval = 0;
  const std::vector<coupling::WallLoad> loads = dem_->take_wall_loads(interval);
  if (loads.empty()) return {};
  const std::array<double, 3> w = dem_->buoyant_weight();
  const double weight2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
  std::ostringstream text;
  text.precision(8);
  text << "\ngrainFoam wall loads over the last " << interval
       << " s (mean force of the particles on each wall, N):";
  std::array<double, 3> total{0, 0, 0};
  for (const coupling::WallLoad& l : loads) {
    text << " " << l.name << " (" << l.force[0] << " " << l.force[1] << " " << l.force[2] << ")";
    for (int a = 0; a < 3; ++a) total[a] += l.force[a];
  }
  // The walls' share of the particles' buoyant weight: with the fluid's share (the pressure
  // drop times the cross-section in a column) it closes the bed's momentum balance.
  if (weight2 > 0)
    text << "; all walls carry " << (total[0] * w[0] + total[1] * w[1] + total[2] * w[2]) / weight2
         << " of the particles' buoyant weight";
  return text.str();
}

std::string ParticleCoupling::cellPointLine() const {
  if (!cellPointWeights_) return {};
  // Collective: every rank has the table when sampling is cellPoint.
  double counts[2] = {double(cellPointSamples_), double(cellPointWeights_->outside())};
  MPI_Allreduce(MPI_IN_PLACE, counts, 2, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  std::ostringstream text;
  text << "grainFoam cellPoint: " << static_cast<long>(counts[0]) << " particle samples, "
       << static_cast<long>(counts[1]) << " outside their cell (OpenFOAM's nearest tetrahedron)\n";
  return text.str();
}

void ParticleCoupling::report(Foam::Ostream&) const {}

}  // namespace grainflow::foam
