#pragma once
// Reading a scene: YAML text -> validated Scene. Every check happens here, at parse
// time, so a run never starts on a bad scene. The first mistake found is thrown as a
// SceneError pointing at the offending key or value (file:line:column).
// Key reference: docs/scene-reference.md.
#include <string>

#include "dem/scene/scene.hpp"
#include "dem/scene/scene_error.hpp"

namespace grainflow {

// Reads and validates the scene file at `path`. A missing or unreadable file is a
// SceneError with line 0. Relative file names inside the scene (CSV insertions) are
// resolved against the scene file's folder. Scene::file is `path` as given.
Scene load_scene(const std::string& path);

// The bytes of the scene file at `path` (load_scene's first half): a SceneError with line 0
// when it is missing, a directory or unreadable.
std::string read_scene_file(const std::string& path);

// Validates scene text. `file_label` names the text in messages and in
// Insertion::source, becomes Scene::file, and its folder is where relative file names
// inside the scene are looked up (tests pass a path inside tests/data/scenes/).
Scene parse_scene(const std::string& yaml_text, const std::string& file_label);

}  // namespace grainflow
