// grain: the standalone DEM executable.
#include <mpi.h>

#include <algorithm>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

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

exit codes: 0 success, 1 refused (time step) or run failure, 2 bad input or usage
docs: README.md (quick start, running a scene), docs/scene-reference.md (every scene key)
)";

int usage_error(const std::string& what) {
  std::cerr << "grain: " << what << "\n\n" << kUsage;
  return 2;
}

int dispatch(const std::string& program, const std::vector<std::string>& args, int rank) {
  using namespace grainflow;
  if (args.empty()) return usage_error("no command given");
  const std::string& cmd = args[0];
  if (cmd == "--help" || cmd == "-h" || cmd == "help") {
    if (rank == 0) std::cout << kUsage;
    return 0;
  }
  if (cmd == "--version") {
    if (rank == 0) std::cout << "grain (grainflow) " << GRAINFLOW_VERSION << "\n";
    return 0;
  }
  if (cmd != "run" && cmd != "check")
    return usage_error("unknown command '" + cmd + "'; allowed: run, check, --help, --version");
  // Options before or after the scene file, `--key value` or `--key=value`; each at most once.
  RunOptions options;
  options.program = program;
  std::string scene_file;
  std::vector<std::string> given;
  for (std::size_t k = 1; k < args.size(); ++k) {
    const std::string& a = args[k];
    if (a == "--help" || a == "-h") {  // `grain run --help`: the usage, as `grain --help`
      if (rank == 0) std::cout << kUsage;
      return 0;
    }
    if (!a.starts_with("--")) {
      if (!scene_file.empty())
        return usage_error("'" + cmd + "' takes one scene file, got '" + scene_file + "' and '" +
                           a + "'");
      scene_file = a;
      continue;
    }
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
    if (key == "--output") options.output_directory = value;
    if (key == "--restart") options.restart = value;
    if (key == "--no-progress") options.progress = false;
    if (key == "--allow-large-dt") options.allow_large_time_step = true;
  }
  if (scene_file.empty()) return usage_error("'" + cmd + "' needs a scene file");
  try {
    const Scene scene = load_scene(scene_file);
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
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const std::vector<std::string> args(argv + 1, argv + argc);
  const int code = dispatch(argc > 0 ? argv[0] : "grain", args, rank);
  MPI_Finalize();
  return code;
}
