// libFuzzer target: any bytes as an STL file, ASCII or binary, then what a mesh
// wall does with the mesh on load (dem/walls/wall_set.cpp): place it and build its
// contact-search grid.
//
// The reader's contract (dem/walls/stl_reader.hpp) is that every input either
// yields a usable TriangleMesh or throws GeometryError naming the file and the line
// or triangle. Anything else — another exception, a crash, a sanitizer report, a
// hang, an allocation beyond libFuzzer's -malloc_limit_mb (e.g. trusting a binary
// header's triangle count, or a search grid sized by a hostile extent) — is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "dem/walls/stl_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    grainflow::MeshTransform placement;
    placement.scale = 1e-3;  // mm -> m, as CAD exports usually need
    placement.rotation_angle = 0.5;
    placement.translation = grainflow::Vec3(0.1, 0, 0);
    grainflow::StlReport report;
    grainflow::TriangleMesh mesh = grainflow::parse_stl(bytes, "fuzz.stl", placement, &report);
    // As wall_set.cpp does without a particle radius: cells of the mean edge. The grid
    // is capped at 2^16 cells instead of the default 2^22 so that an input is tried in
    // about a millisecond rather than ten; the bounding logic is the same.
    mesh.build_grid(mesh.mean_edge_length(), std::size_t{1} << 16);
  } catch (const grainflow::GeometryError&) {
    // The clear error the contract allows.
  }
  return 0;
}
