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
// Welding: vertices closer than a tolerance relative to the mesh's size
// (`weld_tolerance` times the diagonal of the file's bounding box; default 1e-5) are one
// vertex, which is what lets the contact rule see shared edges and vertices (two
// triangles whose common edge is 1e-7 m apart in a CAD export are otherwise two contacts
// for a sphere on that edge). Each vertex, in file order, joins the first kept vertex
// within the tolerance, else is kept; triangles that welding collapses are dropped as
// degenerate. Bit-identical vertices are one vertex whatever the tolerance. After welding,
// edges of exactly one triangle are counted as open: the rim of an open surface, or a seam
// wider than the tolerance; two open-edge vertices of no common triangle closer than 1e-3
// of the diagonal are reported as a likely seam, with the tolerance that would weld them.
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

// Default weld tolerance, relative to the diagonal of the mesh's bounding box.
constexpr double kDefaultWeldTolerance = 1e-5;

struct StlReport {
  bool binary = false;
  long facets_read = 0;
  long degenerate_removed = 0;  // counted repairs
  long vertices = 0;            // after welding
  long welded = 0;              // vertices joined to another that was not bit-identical
  double weld_distance = 0;     // the tolerance in metres, after the placement's scale
  long t_junctions = 0;         // vertices found inside another triangle's open edge, whose
                                // triangle was split there (a CAD export's T-junction)
  long open_edges = 0;          // edges of one triangle only, after welding and those splits
  // The closest two open-edge vertices that share no triangle, if closer than 1e-3 of the
  // diagonal (a likely seam): their distance in metres (placed), and a point (placed); -1
  // when there is none.
  double seam_gap = -1;
  Vec3 seam_at = Vec3::Zero();
  // The closest open-edge vertex to another triangle's open edge (inside it) that was not
  // joined to it, if closer than 1e-3 of the diagonal and small against the edges there (a
  // T-junction left open): the distance in metres (placed) and the vertex; -1 when none.
  double t_gap = -1;
  Vec3 t_gap_at = Vec3::Zero();
  double diagonal = 0;  // of the placed mesh's bounding box, m
};

// weld_tolerance: relative to the bounding box's diagonal (0: bit-identical vertices only).
TriangleMesh read_stl(const std::string& path, const MeshTransform& transform = {},
                      StlReport* report = nullptr, double weld_tolerance = kDefaultWeldTolerance);

// The same from the file's bytes; `label` names it in messages.
TriangleMesh parse_stl(const std::string& bytes, const std::string& label,
                       const MeshTransform& transform = {}, StlReport* report = nullptr,
                       double weld_tolerance = kDefaultWeldTolerance);

// Writes an ASCII STL (for tests, benchmarks and tutorials that generate meshes).
void write_ascii_stl(const std::string& path, const std::vector<Vec3>& vertices,
                     const std::vector<std::array<int, 3>>& triangles);

}  // namespace grainflow
