#pragma once
// The openings of an open triangle mesh: the loops its open edges (edges of one triangle) form,
// each with its width. A hopper's orifice, a hole in a floor: where particles pass through a
// wall. The loop of the longest perimeter is the mesh's outer rim, not an opening, and is left
// out (a flat plate has no opening; an annulus has one, its hole; a tube its narrower end).
#include <vector>

#include "dem/core/types.hpp"
#include "dem/walls/triangle_mesh.hpp"

namespace grainflow {

struct MeshOpening {
  double width = 0;      // the narrowest extent of the loop across, in its own plane [m]: the least
                         // width of its convex hull there
  double perimeter = 0;  // [m]
  Vec3 centre = Vec3::Zero();  // the mean of the loop's vertices (mesh frame)
  std::vector<Vec3> vertices;  // the loop, in order (mesh frame)
};

// Every loop of open edges but the longest, narrowest first.
std::vector<MeshOpening> mesh_openings(const TriangleMesh& mesh);

}  // namespace grainflow
