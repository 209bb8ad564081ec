// libFuzzer target: any bytes as the text of a scene file.
//
// The parser's contract (dem/scene/scene_parser.hpp) is that every input either
// yields a validated Scene or throws SceneError with file:line:column. Anything
// else — another exception, a crash, a sanitizer report, a hang, an allocation
// beyond libFuzzer's -malloc_limit_mb — is a parser bug. Another exception is
// deliberately not caught here: it reaches std::terminate and libFuzzer reports it.
//
// Relative file names in the scene (csv, mesh, snapshot) resolve against
// tests/fuzz/files/, which holds one small file of each kind, so inputs mutated
// from the seed scenes get past the "file not found" check into the rest of the
// section. The parser only checks that such files exist; it does not read them.
#include <cstddef>
#include <cstdint>
#include <string>

#include "dem/scene/scene_parser.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)grainflow::parse_scene(text, GRAINFLOW_FUZZ_FILES_DIR "/scene.yaml");
  } catch (const grainflow::SceneError&) {
    // The clear error the contract allows.
  }
  return 0;
}
