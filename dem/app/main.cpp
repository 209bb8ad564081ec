// grain: the standalone DEM executable.
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dem/core/fnv1a.hpp"
#include "dem/engine/restored_state.hpp"
#include "dem/engine/run.hpp"
#include "dem/engine/simulation.hpp"
#include "dem/insert/insertion.hpp"
#include "dem/io/output_directory.hpp"
#include "dem/scene/scene_error.hpp"
#include "dem/scene/scene_parser.hpp"
#include "dem/walls/stl_reader.hpp"
#include "grainflow_version.hpp"

namespace {

constexpr const char* kUsage = R"(usage: grain <command> [options]

commands:
  run SCENE.yaml [--output DIR] [--no-progress] [--allow-large-dt]
                 [--restart CHECKPOINT.h5]
                      run a DEM scene: HDF5 snapshots + XDMF index (ParaView) and a
                      CSV log in the scene's output directory; --restart continues
                      from a checkpoint. SIGTERM/SIGINT write a checkpoint and stop.
                      Options go before or after the scene, as --key value or
                      --key=value, each at most once. One run per output folder
  check SCENE.yaml [--restart CHECKPOINT.h5]
                      parse and validate the scene, insert its particles, and print
                      the Rayleigh time, the contact time at the expected impact
                      speed and the time step as a fraction of both; --restart
                      verifies the checkpoint against the scene, as run --restart
                      would, and judges its particles instead; writes nothing
  --version           print the version
  --help              print this help

exit codes: 0 success; 1 refused (the time step; a checkpoint, also a missing one) or the
            run failed; 2 bad input (the scene or a file it names) or usage
docs: README.md (quick start, running a scene), docs/scene-reference.md (every scene key)
)";

// What parsing the command line and reading the scene came to on one rank.
struct Start {
  int code = 0;         // the exit code when `done`
  bool done = false;    // nothing more to do: help, version, or an error
  std::string message;  // what to print (standard output when code is 0, else standard error)
  std::string cmd;      // "run" or "check" when not done
  std::string scene_file;
  grainflow::RunOptions options;
  std::string scene_text;  // the scene file's bytes
  std::optional<grainflow::Scene> scene;  // parsed, when not done
};

Start finished(int code, std::string message) {
  Start s;
  s.code = code;
  s.done = true;
  s.message = std::move(message);
  return s;
}

Start usage_error(const std::string& what) {
  return finished(2, "grain: " + what + "\n\n" + kUsage);
}

// The command line, on this rank alone.
Start parse_command(const std::string& program, const std::vector<std::string>& args) {
  using namespace grainflow;
  if (args.empty()) return usage_error("no command given");
  const std::string& cmd = args[0];
  if (cmd == "--help" || cmd == "-h" || cmd == "help") return finished(0, kUsage);
  if (cmd == "--version") {
    if (args.size() > 1)
      return usage_error("'--version' takes nothing more, got '" + args[1] + "'");
    return finished(0, std::string("grain (grainflow) ") + GRAINFLOW_VERSION + "\n");
  }
  if (cmd != "run" && cmd != "check")
    return usage_error("unknown command '" + cmd +
                       "'; allowed: run, check, help (or --help), --version");
  // Options before or after the scene file, `--key value` or `--key=value`; each at most once.
  // After `--` every word is the scene file (a file named `--x.yaml`).
  Start s;
  s.cmd = cmd;
  s.options.program = program;
  std::vector<std::string> given;
  bool options_end = false;
  for (std::size_t k = 1; k < args.size(); ++k) {
    const std::string& a = args[k];
    if (!options_end && a == "--") {
      options_end = true;
      continue;
    }
    if (!options_end && (a == "--help" || a == "-h"))  // `grain run --help`: the usage
      return finished(0, kUsage);
    if (options_end || !a.starts_with("-") || a == "-") {
      if (!s.scene_file.empty())
        return usage_error("'" + cmd + "' takes one scene file, got '" + s.scene_file + "' and '" +
                           a + "'");
      s.scene_file = a;
      continue;
    }
    if (!a.starts_with("--"))  // -o x: no short options but -h
      return usage_error("unknown option '" + a + "' for '" + cmd +
                         "'; options are long: --output, --restart, --no-progress, "
                         "--allow-large-dt (a file whose name starts with '-': ./" +
                         a + ")");
    const std::size_t eq = a.find('=');
    const std::string key = a.substr(0, eq);
    const bool takes_value = key == "--output" || key == "--restart";
    const bool known = takes_value || key == "--no-progress" || key == "--allow-large-dt";
    if (!known) return usage_error("unknown option '" + a + "' for '" + cmd + "'");
    if (cmd != "run" && key != "--restart")
      return usage_error("option '" + key +
                         "' is for 'run'; 'check' takes the scene file and --restart");
    if (std::find(given.begin(), given.end(), key) != given.end())
      return usage_error("option '" + key + "' is given twice; give it once");
    given.push_back(key);
    std::string value;
    if (takes_value) {
      if (eq != std::string::npos) {
        value = a.substr(eq + 1);
      } else if (k + 1 < args.size() && !args[k + 1].starts_with("--")) {
        value = args[++k];
      }
      if (value.empty())
        return usage_error("option '" + key + "' needs a value: " + key +
                           (key == "--output" ? " DIR" : " CHECKPOINT.h5"));
    } else if (eq != std::string::npos) {
      return usage_error("option '" + key + "' takes no value, got '" + a + "'");
    }
    if (value.starts_with("~"))  // --output=~/x: the shell leaves it as it is
      return usage_error("option '" + key + "': '~' in '" + value +
                         "' is not expanded (the shell expands it only at the start of a "
                         "word); write the full path");
    if (key == "--output") s.options.output_directory = value;
    if (key == "--restart") s.options.restart = value;
    if (key == "--no-progress") s.options.progress = false;
    if (key == "--allow-large-dt") s.options.allow_large_time_step = true;
  }
  if (s.scene_file.empty()) return usage_error("'" + cmd + "' needs a scene file");
  try {  // parsed here: a file the scene names that is missing on one rank stops all ranks
    s.scene_text = read_scene_file(s.scene_file);
    s.scene = parse_scene(s.scene_text, s.scene_file);
  } catch (const SceneError& e) {
    return finished(2, std::string(e.what()) + "\n");
  }
  // A checkpoint grainFoam wrote (a time folder of the case its folder is in, or the one
  // above, names it in uniform/grainflowCheckpoint): `grain run` would run the coupled scene
  // without its fluid and write over the case's particle output. A checkpoint of a DEM run
  // kept in a grainFoam case (a pour before the fluid) is named by no time folder.
  if (s.options.restart && cmd == "run") {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path checkpoint = fs::weakly_canonical(fs::absolute(*s.options.restart, ec), ec);
    const std::string name = checkpoint.filename().string();
    const auto names_it = [&](const fs::path& record) {
      std::ifstream in(record);
      for (std::string line; std::getline(in, line);)
        if (line.find("checkpoint") != std::string::npos && line.find(name) != std::string::npos)
          return true;
      return false;
    };
    const auto written_by_grainfoam = [&](const fs::path& case_dir) {
      if (!fs::is_regular_file(case_dir / "system" / "controlDict", ec)) return false;
      std::vector<fs::path> folders{case_dir};
      for (const auto& e : fs::directory_iterator(case_dir, ec))
        if (e.path().filename().string().starts_with("processor")) folders.push_back(e.path());
      for (const fs::path& folder : folders)
        for (const auto& e : fs::directory_iterator(folder, ec))
          if (fs::is_regular_file(e.path() / "uniform" / "grainflowCheckpoint", ec) &&
              names_it(e.path() / "uniform" / "grainflowCheckpoint"))
            return true;
      return false;
    };
    fs::path up = checkpoint.parent_path();
    for (int level = 0; level < 2 && !up.empty(); ++level, up = up.parent_path())
      if (written_by_grainfoam(up))
        return usage_error("--restart " + *s.options.restart +
                           " is a checkpoint grainFoam wrote in the case " + up.string() +
                           " (a time folder's uniform/grainflowCheckpoint names it): restart it "
                           "with grainFoam (startFrom latestTime in system/controlDict); "
                           "grain run would run its scene without the fluid and write over the "
                           "case's particle output");
  }
  return s;
}

// What every rank must have alike, in four parts compared apart so that the message can say
// which differs: the command line (paths made absolute: the same folder named two ways is the
// same, another working directory is not), the scene file's bytes, the files the scene and
// --restart name (their absolute paths and contents), and the environment variables grain reads.
std::array<std::uint64_t, 4> start_fingerprints(const Start& s) {
  namespace fs = std::filesystem;
  using grainflow::fnv1a64;
  const auto absolute = [](const std::string& path) {
    std::error_code ec;
    const fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
    return (ec ? fs::path(path) : p).string();
  };
  const auto file = [&](const std::string& path) {
    std::error_code ec;
    const auto bytes = fs::file_size(path, ec);
    std::string text = absolute(path);
    text += ' ';
    text += ec ? std::string("missing") : std::to_string(bytes);
    return text;
  };
  std::array<std::uint64_t, 4> h{};
  h.fill(grainflow::kFnv1a64Start);
  const grainflow::Scene& scene = *s.scene;
  for (const std::string& part :
       {s.cmd, absolute(s.scene_file),
        absolute(s.options.output_directory.value_or(scene.output.directory)),
        s.options.restart ? absolute(*s.options.restart) : std::string(),
        std::string(s.options.progress ? "progress" : "quiet"),
        std::string(s.options.allow_large_time_step ? "large" : "guarded")})
    h[0] = fnv1a64(part + '\0', h[0]);
  h[1] = fnv1a64(s.scene_text, h[1]);
  const auto contents = [&](const std::string& path) {
    h[2] = fnv1a64(file(path) + '\0', h[2]);
    std::ifstream in(path, std::ios::binary);
    std::array<char, 1 << 16> buffer;
    while (in.read(buffer.data(), buffer.size()) || in.gcount() > 0)
      h[2] = fnv1a64(std::string_view(buffer.data(), static_cast<std::size_t>(in.gcount())), h[2]);
  };
  // The particle files and the checkpoint by their contents (every rank reads each of them
  // whole anyway; a file of the same size but other particles had hung the ranks or, for a
  // checkpoint, restored other states on different ranks), the STL files by the model
  // record's digests of them.
  for (const grainflow::Insertion& ins : scene.insertions)
    for (const std::string* f : {&ins.csv_file, &ins.snapshot_file})
      if (!f->empty()) contents(*f);
  for (const grainflow::Wall& w : scene.walls)
    if (!w.mesh.file.empty()) h[2] = fnv1a64(file(w.mesh.file) + '\0', h[2]);
  h[2] = fnv1a64(scene.model_record, h[2]);
  if (s.options.restart) contents(*s.options.restart);
  for (const char* name : {"GRAINFLOW_BUFFERED_WRITES", "GRAINFLOW_SNAPSHOT_MPIIO"}) {
    const char* value = std::getenv(name);
    h[3] = fnv1a64(name, h[3]);
    h[3] = fnv1a64(value ? std::string_view(value) : std::string_view("\0(unset)", 8), h[3]);
  }
  return h;
}

// Every rank reads its own command line and scene file. Before anything collective the ranks
// agree on what they got: a rank that failed (a scene only rank 0 can read, such as
// /dev/stdin under mpirun, which feeds standard input to rank 0 alone; a file missing on one
// node; an option given to one rank of a mixed launch) stops them all with its own message
// and exit code, instead of leaving the others waiting for it. Returns the exit code when
// the ranks stop here, or -1 when every rank goes on with the same command and scene.
int agree_on_start(const Start& s, int rank, int size) {
  const int failed = s.done && s.code != 0;
  int first_failed = failed ? rank : size;
  MPI_Allreduce(MPI_IN_PLACE, &first_failed, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  int code = s.code;
  MPI_Allreduce(MPI_IN_PLACE, &code, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (first_failed < size) {
    if (rank == first_failed) {
      std::cerr << (rank == 0 ? ""
                              : "grain (rank " + std::to_string(rank) + " of " +
                                    std::to_string(size) + "): ")
                << s.message;
      if (rank != 0)
        std::cerr << "grain: rank 0 got past this; under mpirun every rank reads the command "
                     "line and the scene file itself: give them all the same arguments and a "
                     "file each can read (not standard input, which mpirun gives to rank 0 "
                     "only)\n";
    }
    return code;
  }
  int done[2] = {s.done ? 1 : 0, s.done ? 1 : 0};  // min, max
  MPI_Allreduce(MPI_IN_PLACE, &done[0], 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &done[1], 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (done[0] == 1) {  // help or version on every rank
    if (rank == 0) std::cout << s.message;
    return 0;
  }
  // The same command line, scene, files and environment on every rank.
  std::array<std::uint64_t, 4> lo{}, hi{};
  if (!s.done) lo = hi = start_fingerprints(s);  // a rank with --help differs in the first
  MPI_Allreduce(MPI_IN_PLACE, lo.data(), 4, MPI_UINT64_T, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, hi.data(), 4, MPI_UINT64_T, MPI_MAX, MPI_COMM_WORLD);
  std::string differ;
  if (done[1] == 1) {  // --help or --version on some ranks only: their command lines differ
    lo = hi = std::array<std::uint64_t, 4>{};
    lo[0] = 1;
  }
  const char* parts[4] = {"command lines (or working directories)", "scene files' bytes",
                          "files the scene or --restart names (missing, or other contents)",
                          "GRAINFLOW_* environment variables"};
  for (int k = 0; k < 4; ++k)
    if (lo[k] != hi[k]) {
      if (!differ.empty()) differ += ", ";
      differ += parts[k];
    }
  if (!differ.empty()) {
    if (rank == 0)
      std::cerr << "grain: error: the ranks differ in their " << differ << " (rank 0: '"
                << (s.done ? std::string("--help/--version") : s.cmd + " " + s.scene_file)
                << "'); under mpirun every rank reads the command line, the scene and its "
                   "files itself: give them all the same arguments, working directory and "
                   "environment, and files on a folder every rank sees (not standard input, "
                   "/dev/stdin, which mpirun gives to rank 0 only)\n";
    return 2;
  }
  return -1;
}

int dispatch(const std::string& program, const std::vector<std::string>& args, int rank, int size) {
  using namespace grainflow;
  Start start = parse_command(program, args);
  if (const int code = agree_on_start(start, rank, size); code >= 0) return code;
  const std::string& cmd = start.cmd;
  const RunOptions& options = start.options;
  try {
    const Scene& scene = *start.scene;
    if (cmd == "check") return check_scene(scene, std::cout, options.restart);
    run_scene(scene, options, MPI_COMM_WORLD, std::cout);
    return 0;
  } catch (const SceneError& e) {
    if (rank == 0) std::cerr << e.what() << "\n";
    return 2;
  } catch (const InsertionError& e) {
    if (rank == 0) std::cerr << e.what() << "\n";
    return 2;
  } catch (const GeometryError& e) {  // a mesh wall's STL file, or its placement
    if (rank == 0) std::cerr << e.what() << "\n";
    return 2;
  } catch (const StateError& e) {  // a checkpoint or snapshot that breaks a rule
    if (rank == 0) std::cerr << e.what() << "\n";
    return 1;
  } catch (const SetupError& e) {
    if (rank == 0) std::cerr << e.what() << "\n";
    return 1;
  } catch (const ParallelError& e) {  // every rank holds the same message
    if (rank == 0) std::cerr << e.what() << "\n";
    return 1;
  } catch (const OutputError& e) {  // agreed on by all ranks
    if (rank == 0) std::cerr << "grain: error: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {  // on any rank: say what ran out
    std::cerr << "grain: error on rank " << rank << ": out of memory (std::bad_alloc): the "
              << "scene's particles, neighbour lists or output need more memory than this "
              << "machine gives the run; fewer or larger particles, coarse-grained parcels "
              << "(`coarse_grain: k`), or more ranks on more nodes\n";
    MPI_Abort(MPI_COMM_WORLD, 1);
    return 1;
  } catch (const std::exception& e) {  // unexpected: print on every rank, with the rank
    std::cerr << "grain: error on rank " << rank << ": " << e.what() << "\n";
    MPI_Abort(MPI_COMM_WORLD, 1);
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0;
  int size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const std::vector<std::string> args(argv + 1, argv + argc);
  const int code = dispatch(argc > 0 ? argv[0] : "grain", args, rank, size);
  MPI_Finalize();
  return code;
}
