#include "dem/engine/run.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <filesystem>
#include <limits>
#include <numbers>
#include <optional>
#include <ostream>
#include <sstream>
#include <string_view>
#include <vector>

#include "dem/core/number_format.hpp"
#include "dem/engine/checkpoint_series.hpp"
#include "dem/engine/finite_guard.hpp"
#include "dem/engine/insertion_record.hpp"
#include "dem/engine/parcel_limits.hpp"
#include "dem/engine/restored_state.hpp"
#include "dem/engine/simulation.hpp"
#include "dem/engine/stop_signals.hpp"
#include "dem/fluid/fluid_forces.hpp"
#include "dem/fluid/void_fraction_grid.hpp"
#include "dem/insert/insertion.hpp"
#include "dem/io/direct_write_driver.hpp"
#include "dem/io/log_table.hpp"
#include "dem/io/output_directory.hpp"
#include "dem/io/progress_line.hpp"
#include "dem/io/snapshot_writer.hpp"

namespace grainflow {
namespace {

// Rank 0 speaks for the run; the other ranks write into this sink.
std::ostream& speaker(MPI_Comm comm, std::ostream& out) {
  static std::ostream silent(nullptr);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  return rank == 0 ? out : silent;
}

// `run_anyway`: the user passed --allow-large-dt, so a refusal of the time step is a warning
// (the run goes on) and is printed as one.
void print_report(const Simulation& sim, MPI_Comm comm, std::ostream& out,
                  bool run_anyway = false) {
  const Particles& p = sim.particles();
  double range[2] = {std::numeric_limits<double>::infinity(), 0};
  for (double r : p.radius) {
    range[0] = std::min(range[0], r);
    range[1] = std::max(range[1], r);
  }
  range[0] = -range[0];
  MPI_Allreduce(MPI_IN_PLACE, range, 2, MPI_DOUBLE, MPI_MAX, comm);
  const GlobalState g = sim.global_state();
  const Decomposition& d = sim.decomposition();
  std::ostream& o = speaker(comm, out);
  o << "scene: " << sim.scene().file << "\n"
    << "particles: " << g.particles;
  if (g.particles > 0)
    o << " (radius " << -range[0] << " .. " << range[1] << " m)\n";
  else if (sim.streams().size() > 0)
    o << " (none at the start; the stream insertions add them during the run)\n";
  else
    o << " (the scene has no particles: no insertion entry placed any)\n";
  if (sim.scene().contacts_possible)
    o << "contact law: " << sim.contact_law_name() << "\n";
  else
    o << "contact law: none needed (no walls, one particle: nothing can touch)\n";
  if (d.size() > 1) {
    o << "MPI ranks: " << d.size() << " as a " << d.dims()[0] << " x " << d.dims()[1] << " x "
      << d.dims()[2] << " grid";
    for (int a = 0; a < 3; ++a) {
      if (d.dims()[a] == 1) continue;
      o << "; cuts along "
        << "xyz"[a] << " at";
      for (int k = 1; k < d.dims()[a]; ++k) o << (k > 1 ? ", " : " ") << d.cuts(a)[k];
      o << " m";
    }
    switch (sim.grid_choice()) {
      case Simulation::GridChoice::given: o << " (parallel.grid)"; break;
      case Simulation::GridChoice::imposed: o << " (imposed planes)"; break;
      case Simulation::GridChoice::checkpoint: o << " (default: the checkpoint's)"; break;
      case Simulation::GridChoice::given_checkpoint:
        o << " (parallel.grid, planes of the checkpoint)";
        break;
      case Simulation::GridChoice::particles: o << " (default: for the particles)"; break;
      case Simulation::GridChoice::domain: o << " (default: for the domain)"; break;
    }
    o << "\n";
  }
  if (sim.scene().parallel.reproducible)
    o << "force sums: canonical order (parallel.reproducible): results bit-identical on any "
         "number of ranks\n";
  for (const std::string& note : sim.time_step_report().notes) {
    if (run_anyway && note.starts_with("error: "))
      o << "warning: " << note.substr(7) << " (running anyway: --allow-large-dt)\n";
    else
      o << note << "\n";
  }
  for (const std::string& note : sim.walls().notes()) o << note << "\n";  // meshes read
  for (const std::string& note : sim.insertion_notes()) o << note << "\n";
  for (const std::string& note : sim.scene().notes) o << note << "\n";  // settings unused
}

// The interval of a series written at the steps (of dt) nearest to the multiples of it after
// times[0]: the value with the fewest significant digits within dt / k of (t_k - t_0) / k for
// every k, i.e. the one the scene wrote (0.002, where one gap of the series was 272 steps of
// 7.345e-6 s = 0.00199794 s). 0 for fewer than two times.
double series_interval(const std::vector<double>& times, double dt) {
  if (times.size() < 2) return 0;
  double lo = 0, hi = std::numeric_limits<double>::infinity();
  for (std::size_t k = 1; k < times.size(); ++k) {
    const double n = static_cast<double>(k), span = times[k] - times[0];
    lo = std::max(lo, (span - dt) / n);
    hi = std::min(hi, (span + dt) / n);
  }
  const double mean = (times.back() - times.front()) / static_cast<double>(times.size() - 1);
  if (!(lo <= hi)) return mean;  // not a series of one interval
  for (int digits = 1; digits <= 17; ++digits) {
    char text[40];
    std::snprintf(text, sizeof text, "%.*g", digits, 0.5 * (lo + hi));
    const double v = std::strtod(text, nullptr);
    if (v >= lo && v <= hi) return v;
  }
  return mean;
}

// `word` as one word of a POSIX shell command: as it is when it holds only characters no
// shell treats specially, otherwise in single quotes.
std::string shell_word(const std::string& word) {
  const bool plain = !word.empty() && word.find_first_not_of(
                                          "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                          "0123456789_-+=.,:/@%") == std::string::npos;
  if (plain) return word;
  std::string out = "'";
  for (char c : word) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// Grids sized from the scene, checked against their memory limit before anything is
// allocated. The neighbour bins and the mesh search grids bound themselves (by the count of
// particles and of triangles); the one-way void-fraction grid covers the whole domain.
void check_grids(const Scene& scene) {
  if (scene.fluid && scene.fluid->computed_void_fraction)
    if (const std::string why =
            void_fraction_grid_too_large(scene.domain, *scene.fluid->computed_void_fraction);
        !why.empty())
      throw SetupError(scene.fluid->source + ": error: fluid.void_fraction: " + why);
}

// Every particle, real ones (k = 1) included: how many are computed, the real particles they
// stand for (k^3 each) and their mass. Collective over comm.
struct ParticleTotals {
  long long computed = 0;
  double real = 0, mass = 0;
};
ParticleTotals particle_totals(const Scene& scene, const Particles& p, MPI_Comm comm) {
  const std::vector<double> k = scene.coarse_grain_table();
  double sum[3] = {0, 0, 0};
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double ki = k.empty() ? 1.0 : k[static_cast<std::size_t>(p.material[i])];
    sum[0] += 1;
    sum[1] += ki * ki * ki;
    sum[2] += p.mass[i];
  }
  MPI_Allreduce(MPI_IN_PLACE, sum, 3, MPI_DOUBLE, MPI_SUM, comm);
  return {static_cast<long long>(sum[0]), sum[1], sum[2]};
}

// Coarse graining (docs/models/coarse-graining.md): per parcel class the parcels, the real
// particles they stand for and their mass, and warnings where the literature says parcels
// stop standing for the real particles (dem/engine/parcel_limits.hpp, the rules grainFoam
// applies to its mesh too). Collective over comm; nothing without parcels.
void print_coarse_grain_report(const Scene& scene, const Particles& p, const WallSet& walls,
                               MPI_Comm comm, std::ostream& out) {
  if (scene.coarse_grain_table().empty()) return;
  const std::vector<ParcelClass> classes = parcel_classes(scene, p, comm);
  const ParticleTotals totals = particle_totals(scene, p, comm);
  const long long parcels = totals.computed;
  const double real = totals.real, mass = totals.mass;
  std::ostream& o = speaker(comm, out);
  o << "coarse graining (docs/models/coarse-graining.md):\n";
  for (const ParcelClass& c : classes)
    o << "  '" << c.name << "': " << c.parcels << " parcels of k = " << c.k << " stand for "
      << significant(c.real, 12) << " real particles, " << c.mass
      << " kg in all (real radius up to " << c.largest_diameter / (2 * c.k)
      << " m, parcel radius up to " << c.largest_diameter / 2 << " m)"
      << (c.parcels == 0 ? "; none yet: a stream inserts them" : "") << "\n";
  o << "  all particles: " << parcels << " computed, " << significant(real, 12) << " real, mass "
    << mass << " kg\n";
  const Vec3 extent = scene.domain.hi - scene.domain.lo;
  for (const std::string& w : parcel_domain_warnings(classes, extent, scene.domain.periodic))
    o << "  " << w << "\n";
  for (const std::string& w : parcel_opening_warnings(classes, walls, scene.domain))
    o << "  " << w << "\n";
  if (scene.fluid && scene.fluid->computed_void_fraction) {
    const double h = scene.fluid->computed_void_fraction->cell_size;
    for (const std::string& w : parcel_cell_warnings(classes, h, h, "the void-fraction cell"))
      o << "  " << w << "\n";
  }
}

// A one-way computed void fraction (centre method) puts a particle's whole volume in the
// cell of its centre: a particle that fills more than 1 - minimum of a cell clamps it at the
// minimum even alone, so its drag is a packed bed's (a 0.6 mm bead in 0.3 mm cells settled
// 23x too slowly, with only the clamp count at the end to say so). Collective (the radius).
void print_void_fraction_cell_report(const Scene& scene, const Simulation& sim, MPI_Comm comm,
                                     std::ostream& out) {
  if (!scene.fluid || !scene.fluid->computed_void_fraction) return;
  const VoidFractionGridSettings& grid = *scene.fluid->computed_void_fraction;
  const std::array<double, 3> n = void_fraction_grid_cells(scene.domain, grid);
  const Vec3 length = scene.domain.hi - scene.domain.lo;
  const Vec3 h(length[0] / n[0], length[1] / n[1], length[2] / n[2]);
  const double cell = h.prod();
  const double r = sim.largest_radius();
  const double particle = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  if (!(particle > (1 - grid.minimum) * cell)) return;
  speaker(comm, out) << scene.fluid->source
                     << ": warning: fluid.void_fraction: the largest particle (diameter "
                     << significant(2 * r)
                     << " m) fills more than 1 - minimum = " << significant(1 - grid.minimum)
                     << " of a void-fraction cell (" << significant(h[0]) << " x "
                     << significant(h[1]) << " x " << significant(h[2])
                     << " m): alone in its cell it leaves eps = "
                     << significant(1 - particle / cell) << ", so eps is clamped at "
                     << significant(grid.minimum)
                     << " there and its drag is a packed bed's (the clamps are counted at the "
                        "end of the run). Use a cell_size of at least 3 particle diameters ("
                     << significant(6 * r) << " m)\n";
}

// A drag law used outside the void fractions it was fitted on (docs/models/fluid-forces.md,
// "Validity"): for a fixed eps, the range is known before the run. Schiller-Naumann is a
// single sphere's law and does not use eps at all. (A computed eps spans [minimum, 1] by
// construction: only Schiller-Naumann's is said.)
void print_drag_range_report(const Scene& scene, MPI_Comm comm, std::ostream& out) {
  if (!scene.fluid) return;
  const FluidSettings& f = *scene.fluid;
  const std::string law = f.drag_law;
  std::ostream& o = speaker(comm, out);
  const std::string where = f.source + ": warning: fluid.drag: ";
  if (law == "schiller_naumann") {
    if (f.computed_void_fraction)
      o << where
        << "schiller_naumann is a single sphere's law and ignores the computed void "
           "fraction; a law for beds (di_felice, rong, wen_yu, gidaspow, koch_hill, "
           "beetstra, tenneti_garg_subramaniam) uses it\n";
    else if (f.field.void_fraction < 1)
      o << where << "schiller_naumann is a single sphere's law and ignores void_fraction "
        << significant(f.field.void_fraction)
        << "; a law for beds (di_felice, rong, wen_yu, gidaspow, koch_hill, beetstra, "
           "tenneti_garg_subramaniam) uses it\n";
    return;
  }
  if (f.computed_void_fraction) return;
  const double eps = f.field.void_fraction;
  struct Fitted {
    const char* law;
    double lo, hi;
    const char* what;
  };
  // Ergun: below Gidaspow's switch at 0.8 (it has no viscous part at eps -> 1); the others
  // as their papers fitted them.
  for (const Fitted& r :
       {Fitted{"ergun", 0, 0.8,
               "a packed-bed law, used below 0.8 (Gidaspow); without a viscous "
               "part at eps -> 1; gidaspow or wen_yu cover dilute flow"},
        Fitted{"koch_hill", 0.4, 1, "fitted for solid fractions up to 0.6"},
        Fitted{"beetstra", 0.4, 1, "fitted for solid fractions up to 0.6"},
        Fitted{"tenneti_garg_subramaniam", 0.5, 0.9, "fitted for solid fractions 0.1 to 0.5"},
        Fitted{"di_felice", 0.4, 1, "fitted on fluidised beds, eps >= ~0.4"},
        Fitted{"rong", 0.4, 1, "fitted on fluidised beds, eps >= ~0.4"}})
    if (law == r.law && (eps < r.lo || eps > r.hi))
      o << where << law << " at void_fraction " << significant(eps) << ", outside "
        << significant(r.lo) << " to " << significant(r.hi) << ": " << r.what
        << " (docs/models/fluid-forces.md, \"Validity\")\n";
}

}  // namespace

namespace {

// Whether `name` is a file a run writes into its output folder: log.csv, particles.xdmf,
// particles_<digits>.h5, checkpoint_<digits>.h5 (and their .part/.tmp while written).
bool written_by_a_run(std::string name) {
  for (const char* suffix : {".part", ".tmp"})
    if (name.ends_with(suffix)) name.resize(name.size() - std::string_view(suffix).size());
  if (name == "log.csv" || name == "particles.xdmf") return true;
  for (std::string_view prefix : {"particles_", "checkpoint_"}) {
    if (!name.starts_with(prefix) || !name.ends_with(".h5")) continue;
    const std::string_view digits =
        std::string_view(name).substr(prefix.size(), name.size() - prefix.size() - 3);
    if (!digits.empty() && std::all_of(digits.begin(), digits.end(), [](char c) {
          return std::isdigit(static_cast<unsigned char>(c)) != 0;
        }))
      return true;
  }
  return false;
}

void refuse_inputs_the_run_overwrites(const Scene& scene, const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path out = fs::weakly_canonical(fs::absolute(dir, ec), ec);
  if (ec) return;
  // The folder's entries under names the run writes in place: one that is a symbolic or hard
  // link to an input would be written through, over the input. (Snapshots and checkpoints
  // are written as .part files renamed over their names, which replaces a link; a fresh
  // log.csv is made anew, LogTable; particles.xdmf is renamed into place before its appends.)
  std::vector<fs::path> written_here;
  for (const auto& entry : fs::directory_iterator(out, ec)) {
    const std::string name = entry.path().filename().string();
    if (written_by_a_run(name) && (name == "log.csv" || name == "particles.xdmf" ||
                                   name.ends_with(".part") || name.ends_with(".tmp")))
      written_here.push_back(entry.path());
  }
  const auto check = [&](const std::string& file, const std::string& where, const char* what) {
    if (file.empty()) return;
    std::error_code e;
    const bool scene_file = file == scene.file;
    for (const fs::path& w : written_here)
      if (std::error_code same; (fs::is_symlink(w, same) || fs::hard_link_count(w, same) > 1) &&
                                fs::equivalent(w, file, same) && !same)
        throw SetupError(where + ": error: the " + what + " '" + file + "' is " +
                         (fs::absolute(file, e).lexically_normal() == w
                              ? std::string("a link")
                              : "linked as '" + w.string() + "'") +
                         " in the output folder '" + dir +
                         "' under a name the run writes there: the run would write over it. "
                         "Remove that link, or write the output elsewhere (output.directory, "
                         "or --output)");
    const fs::path in = fs::weakly_canonical(fs::absolute(file, e), e);
    if (e || in.parent_path() != out || !written_by_a_run(in.filename().string())) return;
    throw SetupError(where + ": error: the " + what + " '" + file + "' is in the output folder '" +
                     dir +
                     "' under a name the run writes there: the run would overwrite it. "
                     "Move or copy it out of that folder" +
                     (scene_file ? std::string(" under another name")
                                 : std::string(" (and point the scene at the copy)")) +
                     ", or write the output elsewhere (output.directory, or --output)");
  };
  check(scene.file, scene.file, "scene file");
  for (const Insertion& ins : scene.insertions) {
    check(ins.csv_file, ins.source, "CSV file");
    check(ins.snapshot_file, ins.source, "snapshot file");
  }
  for (const Wall& w : scene.walls)
    if (w.kind == Wall::Kind::mesh) check(w.mesh.file, w.mesh.file_source, "STL file");
}

// The environment variables grain reads, checked before anything is made: a value it would
// not take is refused by name at start-up (GRAINFLOW_BUFFERED_WRITES had failed only at the
// first snapshot, GRAINFLOW_SNAPSHOT_MPIIO=yes was taken for 0).
void refuse_bad_environment() {
  if (const std::string error = buffered_writes_error(); !error.empty()) throw OutputError(error);
  const char* mpiio = std::getenv("GRAINFLOW_SNAPSHOT_MPIIO");
  if (mpiio && *mpiio && std::string_view(mpiio) != "0" && std::string_view(mpiio) != "1")
    throw OutputError(std::string("the environment variable GRAINFLOW_SNAPSHOT_MPIIO is '") +
                      mpiio +
                      "'; allowed values: 0 (ranks on one node hand their slices to rank 0, "
                      "the default) or 1 (collective MPI-IO on one node too)");
}

// The output folders a run makes for itself (the folder and any missing parents), removed
// again, innermost first and only while empty, when the run stops with an error before it
// writes anything there: an insertion that cannot place its particles, a refused time step
// or checkpoint leave the file system as they found it (README, "a mistake in a scene stops
// the program before any output is written"). Rank 0 removes them, after the output lock.
class FoldersMadeForTheRun {
 public:
  FoldersMadeForTheRun(MPI_Comm comm, const std::string& dir)
      : exceptions_(std::uncaught_exceptions()) {
    namespace fs = std::filesystem;
    int rank = 0;
    MPI_Comm_rank(comm, &rank);
    if (rank == 0) {
      // Each folder along the path as written, for the folders made on the way ("x/../y"
      // makes x too), each taken as the kernel will resolve it once the folders before it
      // exist: weakly_canonical resolves the part that exists (symbolic links included) and
      // the rest lexically, as folders made here hold no links. A folder is taken as made
      // only if it is not there now (symlink_status: a link, even to nowhere, is the user's).
      std::error_code ec;
      const fs::path whole = fs::absolute(dir, ec);
      fs::path p;
      for (const fs::path& part : whole) {
        p /= part;
        if (ec || part.empty() || part == "." || part == ".." || p == p.root_path()) continue;
        std::error_code missing;  // set for a path that is not there: not an error here
        const fs::path resolved = fs::weakly_canonical(p, missing);
        if (missing || fs::exists(fs::symlink_status(resolved, missing))) continue;
        if (std::find(made_.begin(), made_.end(), resolved) == made_.end())
          made_.push_back(resolved);
      }
      std::reverse(made_.begin(), made_.end());  // the deepest first
    }
    MPI_Barrier(comm);  // seen before any rank makes the folder
  }
  // The folders made, the deepest first (on rank 0; empty on the others).
  std::vector<std::string> paths() const {
    std::vector<std::string> out;
    for (const std::filesystem::path& p : made_) out.push_back(p.string());
    return out;
  }
  FoldersMadeForTheRun(const FoldersMadeForTheRun&) = delete;
  FoldersMadeForTheRun& operator=(const FoldersMadeForTheRun&) = delete;
  ~FoldersMadeForTheRun() {
    if (std::uncaught_exceptions() <= exceptions_) return;
    // Each only if it is still an empty folder (a file or link put there is not touched); one
    // that is not empty keeps its parents, whose removal then fails too.
    for (const std::filesystem::path& p : made_) {
      std::error_code ec;
      if (std::filesystem::is_directory(std::filesystem::symlink_status(p, ec)))
        std::filesystem::remove(p, ec);
    }
  }

 private:
  int exceptions_;
  std::vector<std::filesystem::path> made_;
};

// The particle files the insertions read, as absolute paths with their modification time
// (UTC): a scene run from another folder reads the files beside the scene, which may be an
// earlier stage's (docs/scene-reference.md, "Files").
void print_input_files(const Scene& scene, MPI_Comm comm, std::ostream& out) {
  namespace fs = std::filesystem;
  // A missing CSV file (the parser leaves it to the insertion, which a restart skips).
  for (const Insertion& ins : scene.insertions)
    if (!ins.csv_missing.empty()) throw InsertionError(ins.csv_missing);
  std::ostream& say = speaker(comm, out);
  for (const Insertion& ins : scene.insertions) {
    const std::string& file = ins.csv_file.empty() ? ins.snapshot_file : ins.csv_file;
    if (file.empty()) continue;
    std::error_code ec;
    const fs::path path = fs::absolute(file, ec).lexically_normal();
    say << "input: " << ins.source << " reads " << path.string();
    const fs::file_time_type written = fs::last_write_time(path, ec);
    if (!ec) {
      const std::time_t t = std::chrono::system_clock::to_time_t(
          std::chrono::time_point_cast<std::chrono::system_clock::duration>(
              std::chrono::file_clock::to_sys(written)));
      std::tm utc{};
      gmtime_r(&t, &utc);
      char text[32];
      std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S", &utc);
      say << " (modified " << text << " UTC)";
    }
    say << "\n";
  }
}

}  // namespace

std::string continue_command(const std::string& scene_file, const RunOptions& options, int ranks,
                             const std::string& checkpoint) {
  std::string cmd = ranks > 1 ? "mpirun -np " + std::to_string(ranks) + " " : std::string();
  cmd += shell_word(options.program) + " run " + shell_word(scene_file);
  if (options.output_directory) cmd += " --output " + shell_word(*options.output_directory);
  if (!options.progress) cmd += " --no-progress";
  if (options.allow_large_time_step) cmd += " --allow-large-dt";
  return cmd + " --restart " + shell_word(checkpoint);
}

namespace {

// The steps a run takes: the whole number nearest to end / dt, at least one, so that it ends
// within half a step of time.end (`grain check` prints the same count).
// When the last step's time misses time.end by more than this share of it, `grain check` and
// `grain run` say at which time the run ends.
constexpr double kEndTolerance = 1e-3;
// The run's whole number of steps to time.end; more than a run can count (9e15, where a
// double still holds every whole number) is refused: it had wrapped to one step, "the
// nearest whole number".
long steps_to_end(const Scene& scene, double dt) {
  const double steps = std::ceil(scene.time.end / dt - 0.5 - 1e-9);
  if (!(steps <= 9e15)) {
    std::ostringstream o;
    o.precision(4);
    o << scene.time.end_source << ": error: time.end " << scene.time.end << " s is "
      << scene.time.end / dt << " steps of dt = " << dt << " s (" << scene.time.step_source
      << "), more than the 9e15 steps a run can count; give a time.end of at most "
      << round_down_3(9e15 * dt) << " s (a run can be stopped at any time with SIGTERM or "
      << "Ctrl-C, and continued from its checkpoint)";
    throw SetupError(o.str());
  }
  return std::max(1L, static_cast<long>(steps));
}

}  // namespace

// The advice of a refused step: the smallest step the refusing checks propose, which every
// one of them allows (following the first error alone may meet the next one).
std::string refusal_remedy(const TimeStepReport& rep) {
  if (!std::isfinite(rep.refusal_step) || !(rep.refusal_step > 0))
    return "lower time.step / time.rayleigh_fraction";
  std::ostringstream o;
  o.precision(4);
  o << "use dt <= " << round_down_3(rep.refusal_step) << " s (time.step";
  if (rep.rayleigh_time > 0 && std::isfinite(rep.rayleigh_time))
    o << ", or time.rayleigh_fraction <= " << round_down_3(rep.refusal_step / rep.rayleigh_time);
  o << "), the smallest step proposed above, which every limit above allows";
  return o.str();
}

namespace {
// What a --restart path must not be, told from its name and kind alone: before anything is
// read, made or changed.
void refuse_unusable_restart(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw OutputError(
        "cannot restart from '" + path +
        "': " + (std::filesystem::exists(path, ec) ? "it is not a regular file" : "no such file") +
        " (nothing was created or changed); give the path of a "
        "checkpoint_<step>.h5 that a run wrote (see output.checkpoint_interval)");
  if (path.ends_with(".part"))
    throw OutputError("cannot restart from '" + path +
                      "': a .part file is a checkpoint that was being written when its run "
                      "was killed, possibly incomplete; restart from a complete "
                      "checkpoint_<step>.h5");
  if (is_particle_snapshot(path))  // by its contents: a snapshot renamed is still one
    throw OutputError("cannot restart from '" + path +
                      "': it is a snapshot, not a checkpoint (nothing was created or changed); a "
                      "restart needs a checkpoint_<step>.h5 (output.checkpoint_interval), and a "
                      "new run starts from a snapshot with the insertion `type: snapshot`");
}

// Reads the checkpoint at `path` (its checksums), checks it against the scene (step,
// insertions, model: check_restart_step, Simulation::restore) and restores it into `sim`.
// Returns the log table it keeps.
std::optional<std::string> restore_checkpoint(Simulation& sim, const Scene& scene,
                                              const std::string& path, MPI_Comm comm,
                                              std::ostream& out) {
  for (const Insertion& ins : scene.insertions)
    if (!ins.csv_missing.empty())
      speaker(comm, out) << "note: " << ins.source << ": the particle file '" << ins.csv_file
                         << "' is missing; a restart takes its particles from the checkpoint "
                            "and does not read it\n";
  const CheckpointData checkpoint = read_checkpoint(path);
  // A checkpoint renamed to another step: said, as "restart from the newest name" would
  // then go back in time.
  long named = -1;
  int used = 0;
  const std::string name = std::filesystem::path(path).filename().string();
  if (std::sscanf(name.c_str(), "checkpoint_%ld.h5%n", &named, &used) == 1 &&
      used == static_cast<int>(name.size()) && named != checkpoint.step)
    speaker(comm, out) << "note: " << path << " holds step " << checkpoint.step
                       << " (t = " << checkpoint.time << " s), not the step " << named
                       << " its name says: it was renamed or copied over\n";
  check_restart_step(scene, checkpoint);
  sim.restore(checkpoint);
  return checkpoint.log;
}

// A restart's scene must end after its checkpoint: the error, for `run` and `check`.
std::string ends_before_checkpoint(const Scene& scene, const Simulation& sim,
                                   const std::string& checkpoint) {
  std::ostringstream m;
  m << scene.time.end_source << ": error: time.end = " << scene.time.end
    << " s is before the checkpoint's time, t = " << sim.time() << " s (step "
    << sim.counters().steps << ", '" << checkpoint
    << "'): the restart would run no step; raise time.end, or restart from an earlier "
       "checkpoint (nothing was changed or deleted)";
  return m.str();
}
}  // namespace

int check_scene(const Scene& scene, std::ostream& out, const std::optional<std::string>& restart) {
  refuse_bad_environment();
  check_grids(scene);
  if (restart)
    refuse_unusable_restart(*restart);
  else
    print_input_files(scene, MPI_COMM_WORLD, out);
  // The output folder `grain run` would write (without --output): not an input's, not a file.
  refuse_inputs_the_run_overwrites(scene, scene.output.directory);
  if (std::error_code ec; std::filesystem::exists(scene.output.directory, ec) &&
                          !std::filesystem::is_directory(scene.output.directory, ec))
    throw OutputError("output.directory '" + scene.output.directory +
                      "' exists but is not a directory: `grain run` could not write there; "
                      "give another output.directory (or --output to grain run)");
  // A restart: the checkpoint is read, verified and checked against the scene as `grain run
  // --restart` does, and its state is what the report below judges; nothing is written.
  Simulation sim(scene, !restart);
  if (restart) restore_checkpoint(sim, scene, *restart, MPI_COMM_WORLD, out);
  // The fluid forces too, so that their stability limits are checked as at start-up.
  if (scene.fluid)
    sim.add_force_term(
        make_fluid_forces(*scene.fluid, scene.gravity, scene.domain, MPI_COMM_WORLD));
  sim.initialise();  // lists and first forces only: no time step is taken
  print_report(sim, MPI_COMM_WORLD, out);
  print_coarse_grain_report(scene, sim.particles(), sim.walls(), MPI_COMM_WORLD, out);
  print_void_fraction_cell_report(scene, sim, MPI_COMM_WORLD, out);
  print_drag_range_report(scene, MPI_COMM_WORLD, out);
  const TimeStepReport& rep = sim.time_step_report();
  if (restart) {
    const long first = sim.counters().steps, end = steps_to_end(scene, sim.dt());
    if (end < first) {
      speaker(MPI_COMM_WORLD, out) << ends_before_checkpoint(scene, sim, *restart) << "\n";
      return 1;
    }
    std::ostream& say = speaker(MPI_COMM_WORLD, out);
    say << "restart: " << *restart << " holds step " << first << " (t = " << sim.time() << " s), "
        << sim.global_state().particles << " particles, and matches the scene; ";
    if (end == first)
      say << "it is at time.end already: nothing to run; to run longer, raise time.end ("
          << scene.time.end_source << ")\n";
    else
      say << "the restart runs " << end - first << " steps of dt = " << sim.dt()
          << " s to t = " << significant(static_cast<double>(end) * sim.dt(), 9) << " s\n";
  } else if (rep.dt > 0 && std::isfinite(rep.dt)) {
    const long steps = steps_to_end(scene, rep.dt);
    const double last = static_cast<double>(steps) * rep.dt;
    std::ostream& say = speaker(MPI_COMM_WORLD, out);
    say << "steps to reach t_end = " << scene.time.end << " s: " << steps;
    if (std::abs(last - scene.time.end) > kEndTolerance * scene.time.end)
      say << " (end / step = " << significant(scene.time.end / rep.dt, 6)
          << " is not whole: the run takes the nearest whole number of steps, at least one, "
             "and ends at t = "
          << significant(last, 9) << " s)";
    say << "\n";
  }
  if (rep.verdict != TimeStepReport::Verdict::refuse) return 0;
  speaker(MPI_COMM_WORLD, out) << scene.file << ": error: `grain run` would refuse this time step; "
                               << refusal_remedy(rep) << "\n";
  return 1;
}

RunSummary run_scene(const Scene& scene, const RunOptions& options, MPI_Comm comm,
                     std::ostream& out) {
  const auto entered = std::chrono::steady_clock::now();
  const auto since = [](std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  refuse_bad_environment();
  check_grids(scene);
  const std::string dir = options.output_directory.value_or(scene.output.directory);
  // Before the output folder is made: a mistyped name changes nothing.
  if (options.restart) refuse_unusable_restart(*options.restart);
  refuse_inputs_the_run_overwrites(scene, dir);  // before the folder is made or touched
  const FoldersMadeForTheRun made(comm, dir);    // removed if the start fails
  prepare_output_directory(dir);  // before any work: an unwritable directory fails now
  const OutputLock lock(comm, dir);  // one run per folder: a second is refused, naming this one
  std::ostream& say = speaker(comm, out);
  if (!options.restart) print_input_files(scene, comm, out);

  // A signal while the particles are placed (a large fill takes minutes) or the checkpoint is
  // read: said, and the lock and the folders made go, as after a failed start.
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::optional<StartupSignals> startup_signals;
  startup_signals.emplace(
      options.handle_stop_signals, rank == 0,
      options.restart ? "reading the checkpoint, preparing the first step"
                      : "placing the particles, preparing the first step",
      rank == 0 ? std::vector<std::string>{(std::filesystem::path(dir) / ".grain.lock").string()}
                : std::vector<std::string>{},
      made.paths());
  // A restart takes its particles from the checkpoint instead of inserting them.
  Simulation sim(scene, !options.restart, comm);
  std::optional<std::string> checkpoint_log;  // the log table the checkpoint keeps
  if (options.restart) checkpoint_log = restore_checkpoint(sim, scene, *options.restart, comm, out);
  // fluid_force needs the force terms' share kept, at the steps that write a snapshot.
  const bool wants_fluid_force = (scene.output.fields & snapshot_field_bit("fluid_force")) != 0;
  sim.record_fluid_force(wants_fluid_force);  // the first forces (snapshot of step 0)
  // output.contacts: the contact network of the force evaluations that end with a snapshot.
  const bool wants_contacts = scene.output.contacts;
  sim.record_contacts(wants_contacts);
  const long first_step = sim.counters().steps;  // 0, or the checkpoint's step
  if (scene.fluid)
    sim.add_force_term(make_fluid_forces(*scene.fluid, scene.gravity, scene.domain, comm));
  sim.initialise();
  print_report(sim, comm, out, options.allow_large_time_step);
  print_coarse_grain_report(scene, sim.particles(), sim.walls(), comm, out);
  print_void_fraction_cell_report(scene, sim, comm, out);
  print_drag_range_report(scene, comm, out);
  if (sim.time_step_report().verdict == TimeStepReport::Verdict::refuse &&
      !options.allow_large_time_step)
    throw SetupError(scene.file + ": error: refusing to run with this time step (see above); " +
                     refusal_remedy(sim.time_step_report()) +
                     ", or pass --allow-large-dt to start anyway (the run-time guards still "
                     "stop it at the first contact this step does not resolve, keys "
                     "time.min_steps_per_contact and time.max_overlap, or the first particle "
                     "that moves too far in a step, time.max_step_travel; 0 turns "
                     "min_steps_per_contact or max_step_travel off)");
  guard_finite(sim, has_non_finite(sim.particles(), sim.heat() != nullptr), dir, comm);
  // A restart whose scene ends before the checkpoint would run no step, and would first cut
  // the snapshot series and log back to the checkpoint: refused before anything is touched.
  const long end_step = steps_to_end(scene, sim.dt());
  if (options.restart && end_step < first_step)
    throw SetupError(ends_before_checkpoint(scene, sim, *options.restart));
  // At exactly the checkpoint's step: nothing to run, and nothing in the folder is touched
  // (continuing the series and the log would cut them back to the checkpoint).
  if (options.restart && end_step == first_step) {
    say << "restart: the checkpoint is at the scene's time.end already (step " << first_step
        << "): nothing to run, nothing in " << dir << " changed; to run longer, raise time.end ("
        << scene.time.end_source << ")\n";
    RunSummary nothing;
    nothing.particles_start = nothing.particles_end = sim.global_state().particles;
    return nothing;
  }
  if (const double last = static_cast<double>(end_step) * sim.dt();
      std::abs(last - scene.time.end) > kEndTolerance * scene.time.end)
    say << "note: time.end / step = " << significant(scene.time.end / sim.dt(), 6)
        << " is not whole: the run takes " << end_step << (end_step == 1 ? " step" : " steps")
        << ", the nearest whole number"
        << (scene.time.end / sim.dt() < 0.5 ? " of at least one" : "")
        << ", and ends at t = " << significant(last, 9) << " s\n";

  SnapshotWriter snapshots(comm, dir, "particles", scene.output.fields);
  snapshots.set_coarse_grain(scene.coarse_grain_table(), scene.real_material_table());
  snapshots.set_material_names(scene.material_names());
  snapshots.set_scene_fingerprint(scene_fingerprint(scene));
  const std::string log_path = (std::filesystem::path(dir) / "log.csv").string();
  // output.wall_loads: each wall's mean load since the previous row, and that time span; with
  // heat, the particles' thermal energy.
  std::vector<std::string> wall_columns;
  if (scene.output.wall_loads) {
    for (const WallSet::Entry& w : sim.walls().walls())
      for (const char* axis : {"x", "y", "z"})
        wall_columns.push_back(w.name + "_load_" + axis + "_N");
    wall_columns.emplace_back("wall_load_interval_s");
  }
  if (sim.heat() != nullptr) wall_columns.emplace_back("thermal_J");
  std::optional<LogTable> log_table;
  if (options.restart) {
    const std::size_t kept = snapshots.continue_series(first_step, sim.time() + 0.5 * sim.dt());
    log_table.emplace(comm, log_path, first_step, wall_columns, checkpoint_log);
    say << "restart: from " << *options.restart << " at step " << first_step
        << " (t = " << sim.time() << " s); continuing " << dir
        << "/log.csv and the snapshot series after " << kept << " earlier snapshot(s)\n";
    // Into a folder other than the checkpoint's (its run's): said, with where the run is.
    std::error_code ec;
    const auto here = std::filesystem::weakly_canonical(std::filesystem::absolute(dir, ec), ec);
    const auto there = std::filesystem::weakly_canonical(
        std::filesystem::absolute(*options.restart, ec).parent_path(), ec);
    std::string folder = std::filesystem::path(*options.restart).parent_path().string();
    if (folder.empty()) folder = ".";
    if (kept == 0 && here != there)
      say << "note: the checkpoint is in " << folder << ", this restart writes into " << dir
          << ", which holds none of its run's snapshots: the snapshots this restart writes "
          << "after t = " << sim.time() << " s start the series here at particles_000000.h5 "
          << "(to continue the run's own series, restart with --output " << folder << ")\n";
    for (const std::string& gap : snapshots.missing())
      say << "note: " << dir << "/" << gap
          << " is a gap in the snapshot series (deleted or damaged since it was written): "
             "particles.xdmf lists the snapshots around it\n";
    for (const std::string& again : snapshots.reused())
      say << "note: " << dir << "/" << again
          << " comes after the last snapshot this restart takes over, and particles.xdmf does "
             "not say when it was written: the restart writes its next snapshot under that "
             "number (if it held a state before the checkpoint, the numbers after it now differ "
             "from the uninterrupted run's)\n";
    // Intervals left to their defaults follow time.end: a restart that extends the run (as
    // the summary advises) would space its snapshots and log rows otherwise than the run it
    // continues, unsaid. The earlier spacing is read off the snapshots and rows taken over.
    const auto spacing_note = [&](const char* key, const char* rule, double now,
                                  const std::vector<double>& times) {
      const double before = series_interval(times, sim.dt());
      if (before > 0 && std::abs(now - before) > 1e-6 * before)
        say << "note: output." << key << " is left to its default, " << rule << " = " << now
            << " s, and the run this restart continues wrote every " << before
            << " s (another time.end); set output." << key << ": " << before
            << " to keep its spacing\n";
    };
    if (!scene.output.snapshot_interval && kept >= 2) {
      std::vector<double> times;
      for (std::size_t k = 0; k < kept; ++k) times.push_back(snapshots.entries()[k].time);
      spacing_note("snapshot_interval", "time.end / 20", scene.time.end / 20, times);
    }
    if (!scene.output.log_interval && checkpoint_log) {
      // The last two rows' times (first column) of the log the checkpoint keeps.
      std::vector<double> times;
      std::istringstream rows(*checkpoint_log);
      for (std::string row; std::getline(rows, row);)
        if (!row.empty() && (std::isdigit(static_cast<unsigned char>(row[0])) || row[0] == '-'))
          times.push_back(std::strtod(row.c_str(), nullptr));
      if (times.size() >= 2)
        spacing_note("log_interval", "time.end / 200", scene.time.end / 200, times);
    }
    if (!snapshots.foreign_file().empty())
      say << "note: " << dir << "/" << snapshots.foreign_file()
          << " was written by another scene's run (its scene_fingerprint differs): the series "
             "is continued before it, particles.xdmf lists only this run's snapshots, and this "
             "run writes its own over that file's number and the ones after it\n";
  } else {
    log_table.emplace(comm, log_path, wall_columns);
    // An earlier run's files in the folder: this run overwrites the snapshots it writes under
    // the same numbers; the others stay beside them (a script taking the newest file takes
    // theirs), and so do its checkpoints. Said, not deleted.
    if (rank == 0) {
      long earlier_snapshots = 0, earlier_checkpoints = 0;
      std::error_code ec;
      for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
        const std::string name = e.path().filename().string();
        const bool h5 = name.ends_with(".h5");
        if (h5 && name.starts_with("particles_")) ++earlier_snapshots;
        if (h5 && name.starts_with("checkpoint_")) ++earlier_checkpoints;
      }
      if (earlier_snapshots + earlier_checkpoints > 0)
        say << "note: " << dir << " holds " << earlier_snapshots << " snapshot(s) and "
            << earlier_checkpoints
            << " checkpoint(s) of an earlier run; this run overwrites the snapshots it writes "
               "under the same numbers and leaves the others (particles.xdmf lists only this "
               "run's): remove them, or give another --output, to keep one run per folder\n";
    }
  }
  LogTable& log = *log_table;
  if (!log.note().empty()) say << "note: " << log.note() << "\n";
  sim.set_log_record(&log.record());  // each checkpoint keeps the log up to its step
  // Against the time the last step reaches (time.end within half a step): a finished run shows
  // 100 %.
  ProgressLine progress(comm, static_cast<double>(end_step) * sim.dt(),
                        options.progress && scene.output.progress, out);
  CheckpointSeries checkpoints(comm, dir, scene.output.checkpoint_keep,
                               options.restart ? first_step : -1, insertion_record(scene),
                               scene.model_record);
  for (const std::string& other : checkpoints.foreign())
    say << "note: " << other
        << " was written by another scene's run (its record of insertions or model differs): "
           "not part "
           "of this run's checkpoints, never deleted by it\n";
  for (const std::string& partial : checkpoints.removed_partial())
    say << "note: deleted the partial checkpoint " << partial
        << " (left by a run killed while writing it; never a complete checkpoint)\n";
  if (!checkpoints.warning().empty()) say << checkpoints.warning() << "\n";
  // From here on, the run loop's handler (a checkpoint at a step); the start-up one held
  // through the first lists and forces and the output's opening.
  startup_signals.reset();
  const StopSignals signals(options.handle_stop_signals);

  const double dt = sim.dt();
  const double snap_every = scene.output.snapshot_interval.value_or(scene.time.end / 20);
  const double log_every = scene.output.log_interval.value_or(scene.time.end / 200);
  const double check_every = scene.output.checkpoint_interval.value_or(0);
  const auto start = std::chrono::steady_clock::now();
  // Start-up: the particles in place (insertion or checkpoint), the first neighbour lists and
  // forces, and the output opened; the first snapshot is timed with the others.
  const double setup_seconds = since(entered);
  auto wall = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  long removed_reported = 0;
  // A failed output write (full disk, lost mount) stops the run on every rank; the message
  // names the checkpoint to continue from and the command that does.
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  auto resumable = [&](const OutputError& e) {
    std::string message = e.what();
    if (!message.ends_with('.')) message += '.';
    const std::string& newest = checkpoints.newest();
    return OutputError(message + " " +
                       (newest.empty() ? checkpoints.resume_hint("")
                                       : checkpoints.resume_hint(continue_command(
                                             scene.file, options, ranks, newest))));
  };
  // `recorded` false: a row that the uninterrupted run does not write (the stop signal's); it
  // leaves the wall-load sums running and stays out of the checkpoints' copy of the log.
  auto write_log = [&](bool recorded = true) {
    const GlobalState g = sim.global_state();
    std::vector<double> loads;
    if (scene.output.wall_loads) {
      const Simulation::WallLoads w = sim.take_wall_loads(/*reset=*/recorded);
      for (const Vec3& f : w.force) loads.insert(loads.end(), {f[0], f[1], f[2]});
      loads.push_back(w.interval);
    }
    if (sim.heat() != nullptr) {  // sum m c T of every particle (parcels: their k^3 real ones)
      double thermal = sim.heat()->thermal_energy(sim.particles());
      MPI_Allreduce(MPI_IN_PLACE, &thermal, 1, MPI_DOUBLE, MPI_SUM, comm);
      loads.push_back(thermal);
    }
    try {
      log.write({sim.time(), sim.counters().steps, g.particles, g.kinetic_translational,
                 g.kinetic_rotational, g.max_overlap_ratio, g.contacts, sim.counters().rebuilds,
                 g.removed, wall(), std::move(loads)},
                recorded);
    } catch (const OutputError& e) {
      throw resumable(e);
    }
    // Removals are reported once per log interval, not per particle.
    if (g.removed > removed_reported) {
      say << "warning: t = " << sim.time() << " s: " << g.removed - removed_reported
          << " particle(s) left the domain through a bounded side and were removed (total "
          << g.removed << "; see column 'removed' of log.csv)\n";
      removed_reported = g.removed;
    }
    return g;
  };
  auto write_checkpoint = [&] {
    try {
      const std::string path = checkpoints.write(sim);
      if (!checkpoints.warning().empty()) say << checkpoints.warning() << "\n";
      return path;
    } catch (const OutputError& e) {
      throw resumable(e);
    }
  };
  // Snapshot output is timed (all ranks wait for the collective write) and its bytes counted
  // on disk, for the throughput in the run summary.
  double snapshot_seconds = 0, first_snapshot_seconds = 0, snapshot_bytes = 0;
  long snapshot_files = 0;
  auto write_snapshot = [&](double t, long k) {
    const auto t0 = std::chrono::steady_clock::now();
    std::string path;
    try {
      path = snapshots.write(sim.particles(), t, k, sim.snapshot_extras(snapshots.fields()),
                             wants_contacts ? &sim.contact_network() : nullptr);
    } catch (const OutputError& e) {
      throw resumable(e);
    }
    const double seconds = since(t0);
    if (k == first_step && !options.restart) first_snapshot_seconds = seconds;
    snapshot_seconds += seconds;
    ++snapshot_files;
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    if (!ec) snapshot_bytes += static_cast<double>(size);
  };

  RunSummary sum;
  // Output counters as the uninterrupted run has them at this step: the index of the last
  // target origin + i * every written, so a restart writes the same steps as the uninterrupted
  // run. Decided by the loop's own test below (t >= origin + i * every - dt/2, the same
  // floating-point expression): the quotient (t0 + dt/2) / every rounds otherwise when the
  // checkpoint sits half a step before a target, and a restart had then skipped or repeated
  // that snapshot and log row.
  const double t0 = sim.time();
  const auto due = [dt](double t, double origin, long i, double every) {
    return t >= origin + static_cast<double>(i) * every - 0.5 * dt;
  };
  auto written = [&](double every, double origin) {
    if (every <= 0) return 0L;
    long i = static_cast<long>(std::floor((t0 - origin + 0.5 * dt) / every));
    while (due(t0, origin, i + 1, every)) ++i;
    while (i > 0 && !due(t0, origin, i, every)) --i;
    return i;
  };
  long log_index = written(log_every, 0.0);
  // Snapshots at origin + i * snap_every inside the window [output.start, output.stop]
  // (within half a step), and at the last step when it is inside; snap_index is the last i
  // written (-1: the window has not begun).
  const double snap_origin = scene.output.start.value_or(0.0);
  const double snap_end = scene.output.stop.value_or(std::numeric_limits<double>::infinity());
  const auto in_window = [&](double t) {
    return t >= snap_origin - 0.5 * dt && t <= snap_end + 0.5 * dt;
  };
  long snap_index = t0 < snap_origin - 0.5 * dt ? -1L : written(snap_every, snap_origin);
  long check_index = written(check_every, 0.0);
  long snap_step = first_step, log_step = first_step;  // last step written
  if (!options.restart) {
    if (in_window(sim.time())) write_snapshot(sim.time(), 0);
    sum.particles_start = write_log().particles;
  } else {
    sum.particles_start = sim.global_state().particles;
  }
  long global_particles = sum.particles_start;
  // The run ends at the step nearest to t_end (within half a step).
  const long total_steps = end_step;
  double particle_steps = 0;  // this rank's
  std::ostringstream stop_message;
  const auto snapshot_due = [&](double t, long k) {
    return in_window(t) && (due(t, snap_origin, snap_index + 1, snap_every) ||
                            (k == total_steps && snap_step != k));
  };
  for (long k = first_step + 1; k <= total_steps; ++k) {
    // The step adds dt to the time exactly so: whether it ends with a snapshot is known now.
    if (wants_fluid_force) sim.record_fluid_force(snapshot_due(sim.time() + dt, k));
    if (wants_contacts) sim.record_contacts(snapshot_due(sim.time() + dt, k));
    sim.step();
    guard_finite_after_step(sim, dir, comm);
    particle_steps += static_cast<double>(sim.particles().size());
    const double t = sim.time();
    const bool last = k == total_steps;
    if (due(t, 0.0, log_index + 1, log_every) || (last && log_step != k)) {
      log_step = k;
      log_index = static_cast<long>(std::floor(t / log_every + 0.5));
      global_particles = write_log().particles;
      // The fluid forces' limits at the flow reached (collective; --allow-large-dt: not held).
      if (!options.allow_large_time_step) sim.recheck_force_limits();
    }
    if (snapshot_due(t, k)) {
      snap_step = k;
      snap_index = static_cast<long>(std::floor((t - snap_origin) / snap_every + 0.5));
      write_snapshot(t, k);
    }
    if (check_every > 0 && !last && due(t, 0.0, check_index + 1, check_every)) {
      check_index = static_cast<long>(std::floor(t / check_every + 0.5));
      write_checkpoint();
    }
    if ((k & 255) == 0 || last) progress.update(t, k, global_particles);
    // Stop signals are agreed on every 100 steps: one small reduction, so all ranks stop at
    // the same step.
    if (k % 100 == 0 && !last) {
      const int signal = StopSignals::agreed(comm);
      if (signal != 0) {
        if (log_step != k) write_log(/*recorded=*/false);
        sum.stop_checkpoint = write_checkpoint();
        stop_message << "grain: received " << StopSignals::name(signal) << "; stopped after step "
                     << k << " (t = " << t << " s) and wrote the checkpoint " << sum.stop_checkpoint
                     << "; continue with: "
                     << continue_command(scene.file, options, ranks, sum.stop_checkpoint) << "\n";
        break;
      }
    }
  }
  progress.finish();
  say << stop_message.str();
  // After a restart, the stopped run's snapshots after its checkpoint that this run did not
  // write over (another snapshot_interval, an earlier end): said, not deleted, as for a fresh
  // run in a used folder. (A script taking the last file by name would take theirs.)
  if (options.restart) {
    if (rank == 0)
      if (const std::vector<std::string> left = snapshots.files_after_series(); !left.empty())
        say << "note: " << dir << " still holds " << left.size() << " snapshot(s) numbered after "
            << "this run's last (" << left.front()
            << (left.size() > 1 ? " to " + left.back() : std::string()) << "), written before "
            << "the restart and not written over by it; particles.xdmf does not list them. "
               "Remove them, so that the files in number order are this run's series\n";
  }

  MPI_Allreduce(MPI_IN_PLACE, &particle_steps, 1, MPI_DOUBLE, MPI_SUM, comm);
  const GlobalState g = sim.global_state();
  sum.steps = sim.counters().steps;
  sum.particles_end = g.particles;
  sum.removed = g.removed;
  sum.rebuilds = sim.counters().rebuilds;
  sum.wall_seconds = wall();
  sum.particle_steps_per_second = sum.wall_seconds > 0 ? particle_steps / sum.wall_seconds : 0;
  say << (sum.stop_checkpoint.empty() ? "done: " : "stopped: ") << sum.steps << " steps, "
      << sum.particles_end << " particles (" << sum.removed << " removed), " << sum.rebuilds
      << " neighbour rebuilds, " << sum.wall_seconds << " s wall, " << sum.particle_steps_per_second
      << " particle-steps/s";
  // The counts above are the run's since t = 0; a restart ran only those after its checkpoint.
  if (options.restart)
    say << " (steps and rebuilds counted from t = 0; this restart ran " << sum.steps - first_step
        << (sum.steps - first_step == 1 ? " step" : " steps") << ", after the checkpoint's step "
        << first_step << ")";
  say << "\n"
      << "output: " << dir << "/particles.xdmf (open in ParaView), " << dir << "/log.csv\n";
  // None is written at the end: the newest, and how to extend the run exactly from it.
  if (sum.stop_checkpoint.empty() && !checkpoints.newest().empty())
    say << "checkpoint: the newest is " << checkpoints.newest()
        << " (none is written at time.end); to run longer, raise time.end and continue with: "
        << continue_command(scene.file, options, ranks, checkpoints.newest()) << "\n";
  if (!scene.coarse_grain_table().empty()) {
    const ParticleTotals end = particle_totals(scene, sim.particles(), comm);
    say << "coarse graining: the " << end.computed << " particles stand for "
        << significant(end.real, 12) << " real particles (" << end.mass
        << " kg); each parcel counts as one particle in the "
        << "counts above, in the removed ones and in log.csv\n";
  }
  sum.startup_seconds = setup_seconds + first_snapshot_seconds;
  sum.snapshot_seconds = snapshot_seconds;
  sum.snapshot_bytes = snapshot_bytes;
  sum.snapshot_files = snapshot_files;
  say << "time: start-up " << significant(sum.startup_seconds, 3) << " s (particles, first lists and forces "
      << significant(setup_seconds, 3) << " s";
  if (first_snapshot_seconds > 0)
    say << ", first snapshot " << significant(first_snapshot_seconds, 3) << " s";
  say << "); " << snapshot_files << " snapshot(s), " << significant(snapshot_bytes / 1e6, 3)
      << " MB in " << significant(snapshot_seconds, 3) << " s";
  if (snapshot_seconds > 0)
    say << " (" << significant(snapshot_bytes / 1e6 / snapshot_seconds, 3) << " MB/s)";
  say << "\n";
  const StreamInsertion& streams = sim.streams();
  for (std::size_t k = 0; k < streams.size(); ++k) {
    sum.streams.push_back({streams.count_inserted(k), streams.mass_inserted(k), streams.lag(k)});
    const double kc = streams.coarse_grain(k);
    say << "stream " << streams.source(k) << ": " << streams.count_inserted(k) << " particles"
        << (kc != 1 ? " (parcels of k = " + significant(kc, 6) + ": " +
                          significant(static_cast<double>(streams.count_inserted(k)) * kc * kc * kc,
                                      12) +
                          " real particles)"
                    : std::string())
        << ", " << streams.mass_inserted(k) << " kg delivered since t = 0";
    if (streams.lag(k) > 0) {
      say << ", ";
      if (streams.lag_mass(k) > 0) say << streams.lag_mass(k) << " kg (";
      say << (streams.lag_is_lower_bound(k) ? "at least " : "") << streams.lag(k)
          << (streams.lag_mass(k) > 0 ? " particles)" : "") << " behind (face blocked)";
    }
    say << "\n";
  }
  for (const std::string& line : sim.force_term_reports())
    if (!line.empty()) say << line << "\n";
  return sum;
}

}  // namespace grainflow
