#pragma once
// Runs a scene given as YAML text, as `grain run` would, in a fresh folder under the build
// tree: for tests that rerun what an error message advises.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "dem/engine/run.hpp"
#include "dem/scene/scene_parser.hpp"

namespace grainflow::test {

struct SceneOutcome {
  std::string error, log;     // the exception's message ("" when the run ended), the output
  std::filesystem::path out;  // the output folder
};

// `name`: the folder under <build>/test_output/<group>/; `csv`: the text of beads.csv next to
// the scene ("" for none); `allow_large_step`: as `grain run --allow-large-dt`.
inline SceneOutcome run_scene_text(const std::string& text, const std::string& group,
                                   const std::string& name, const std::string& csv,
                                   bool allow_large_step = false) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / group / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  if (!csv.empty()) std::ofstream(dir / "beads.csv") << csv;
  const Scene s = parse_scene(text, (dir / "scene.yaml").string());
  RunOptions options;
  options.output_directory = (dir / "out").string();
  options.progress = false;
  options.handle_stop_signals = false;
  options.allow_large_time_step = allow_large_step;
  std::ostringstream log;
  SceneOutcome o;
  o.out = dir / "out";
  try {
    run_scene(s, options, MPI_COMM_WORLD, log);
  } catch (const std::exception& e) {
    o.error = e.what();
  }
  o.log = log.str();
  return o;
}

}  // namespace grainflow::test
