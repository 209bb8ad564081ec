#pragma once
// The openings of an open triangle mesh: the loops its open edges (edges of one triangle) form,
// each with its width. A hopper's orifice, a hole in a floor: where particles pass through a
// wall. In each connected part of the mesh the loop of the largest convex hull (in its plane)
// is the part's outer rim, not an opening, and is left out (a flat plate has no opening, nor
// a baffle beside it; an annulus has one, its hole; a tube its other end).
#include <vector>

#include "dem/core/types.hpp"
#include "dem/walls/triangle_mesh.hpp"

namespace grainflow {

struct MeshOpening {
  double width = 0;      // the diameter of the largest circle inside the loop, in its own
                         // plane [m]: what a sphere must pass through (a slot's width)
  double perimeter = 0;  // [m]
  Vec3 centre = Vec3::Zero();  // the mean of the loop's vertices (mesh frame)
  std::vector<Vec3> vertices;  // the loop, in order (mesh frame)
};

// Every loop of open edges but the parts' rims, narrowest first.
std::vector<MeshOpening> mesh_openings(const TriangleMesh& mesh);

}  // namespace grainflow
