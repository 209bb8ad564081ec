#pragma once
// Reading triangle meshes from STL files, ASCII or binary (format: 3D Systems,
// "StereoLithography Interface Specification", 1989; binary = 80-byte header,
// uint32 count, then 50 bytes per triangle: normal, three vertices as float32,
// uint16 attribute).
//
// Which format: a file whose size is exactly 84 + 50 n, n being its uint32 at byte
// 80, is binary even if its header starts with "solid" (many exporters write that);
// otherwise a file starting with "solid" and holding only text (no NUL or control
// bytes) is ASCII. Anything else is an error. The binary count is only compared with
// the file size, never trusted for an allocation.
//
// What is an error (GeometryError naming the file and the line or triangle): a
// binary size that does not match its count, an ASCII facet without exactly three
// vertices or a vertex without exactly three numbers, a number that does not parse,
// a non-finite (NaN, inf) coordinate before or after the placement, a file that ends
// inside a facet, a mesh with no usable triangle. What is repaired
// and counted in StlReport: degenerate triangles (two vertices equal, or all three
// collinear to round-off) are dropped. Facet normals in the file are ignored: a
// mesh wall is two-sided and normals are recomputed from the vertices.
//
// Vertices with bit-identical coordinates in the file are welded into one, which
// is what lets the contact rule see shared edges and vertices.
#include <stdexcept>
#include <string>

#include "dem/core/types.hpp"
#include "dem/walls/triangle_mesh.hpp"

namespace grainflow {

// A wall geometry that cannot be used; the message names the file and where.
class GeometryError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Placement applied on load: x' = R (scale x) + translation, R a rotation by
// `rotation_angle` radians about the unit `rotation_axis` (right hand).
struct MeshTransform {
  double scale = 1;
  Vec3 rotation_axis = Vec3::UnitZ();
  double rotation_angle = 0;
  Vec3 translation = Vec3::Zero();
  Vec3 apply(const Vec3& x) const;
};

struct StlReport {
  bool binary = false;
  long facets_read = 0;
  long degenerate_removed = 0;  // counted repairs
  long vertices = 0;            // after welding
};

TriangleMesh read_stl(const std::string& path, const MeshTransform& transform = {},
                      StlReport* report = nullptr);

// The same from the file's bytes; `label` names it in messages.
TriangleMesh parse_stl(const std::string& bytes, const std::string& label,
                       const MeshTransform& transform = {}, StlReport* report = nullptr);

// Writes an ASCII STL (for tests, benchmarks and tutorials that generate meshes).
void write_ascii_stl(const std::string& path, const std::vector<Vec3>& vertices,
                     const std::vector<std::array<int, 3>>& triangles);

}  // namespace grainflow
