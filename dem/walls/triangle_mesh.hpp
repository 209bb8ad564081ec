#pragma once
// A rigid triangle mesh wall in its own (body) frame: welded vertices, triangles,
// the triangles around every edge and vertex, and a uniform grid of triangles for
// contact search. Particle-mesh contacts follow the one-contact-per-local-minimum
// rule of docs/theory/walls.md: a sphere touching the shared edge or vertex of
// several triangles feels one contact, not one per triangle.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "dem/core/types.hpp"
#include "dem/walls/closest_point.hpp"

namespace grainflow {

// One particle-mesh contact in the body frame.
struct MeshTouch {
  Vec3 n;        // unit normal from the mesh towards the sphere centre
  Vec3 point;    // closest point on the mesh
  double overlap;
  int triangle;  // owning triangle
  TriangleFeature feature;
};

class TriangleMesh {
 public:
  // Most contacts one sphere can have with one mesh (a sphere in a concave corner
  // of a box has 3); further ones are dropped and counted by the caller.
  static constexpr int kMaxTouches = 8;

  TriangleMesh() = default;
  // `vertices` are welded (shared between triangles that share them); triangles are
  // non-degenerate, counter-clockwise seen from the side their normal points to.
  TriangleMesh(std::vector<Vec3> vertices, std::vector<std::array<int, 3>> triangles);

  // Builds the search grid with cells of about `cell` metres (enlarged when the
  // grid would exceed `max_cells`). Search stays correct for any sphere radius;
  // the cell size only sets the cost.
  void build_grid(double cell, std::size_t max_cells = 1u << 22);

  // The contacts of a sphere (centre c, radius r, body frame) with the mesh: at most
  // kMaxTouches are written to `out`; returns how many.
  int touches(const Vec3& c, double r, MeshTouch* out) const;

  // Reference search over every triangle (same rule, no grid): for tests and the benchmark.
  int touches_brute_force(const Vec3& c, double r, MeshTouch* out) const;

  std::size_t triangle_count() const { return tris_.size(); }
  std::size_t vertex_count() const { return verts_.size(); }
  const std::vector<Vec3>& vertices() const { return verts_; }
  const std::vector<std::array<int, 3>>& triangles() const { return tris_; }
  // Whether the point lies inside the surface (body frame): the parity of its crossings by a
  // ray from x along a fixed, skew direction. Meaningful for a closed surface (no open edges);
  // every triangle is tested, after the bounding box.
  bool encloses(const Vec3& x) const;
  Vec3 lo() const { return lo_; }  // bounding box
  Vec3 hi() const { return hi_; }
  double cell_size() const { return cell_; }
  double mean_edge_length() const;

 private:
  struct Candidate {
    int tri;
    TriangleFeature f;
    Vec3 q;
    double d2;
  };
  template <class ForEach>
  int resolve(const Vec3& c, double r, ForEach&& for_each_triangle, MeshTouch* out) const;

  std::vector<Vec3> verts_;
  std::vector<std::array<int, 3>> tris_;
  std::vector<Vec3> normal_;                 // unit normal of each triangle
  std::vector<double> offset_;               // normal . (a vertex): the plane is n.x = offset
  std::vector<std::array<int, 3>> edge_of_;  // edge ids of AB, BC, CA
  std::vector<int> edge_start_, edge_tris_;  // CSR: triangles around each edge
  std::vector<int> vert_start_, vert_tris_;  // CSR: triangles around each vertex
  Vec3 lo_ = Vec3::Zero(), hi_ = Vec3::Zero();
  // Uniform grid: cell (i, j, k) holds every triangle whose bounding box overlaps it.
  double cell_ = 0, inv_cell_ = 0;
  std::array<int, 3> dims_{0, 0, 0};
  std::vector<int> cell_start_, cell_tris_;
  std::vector<std::array<int, 3>> tri_cell_lo_;  // first cell of each triangle's box
};

}  // namespace grainflow
