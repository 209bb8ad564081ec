#pragma once
// All walls of a run in their current position: planes, cylinders and triangle
// meshes, each with its prescribed motion (wall_motion.hpp), and the layout of the
// contact histories the walls need.
//
// Histories are stored in "columns" (Simulation's wall_history, one vector of
// ContactHistory per column, parallel to the wall's neighbour list or to the particles,
// dem/neighbour/wall_neighbours.hpp): a plane or a cylinder uses one column; a mesh uses
// kMeshSlots slots of two columns each, the slot's spring and its key, the contact normal
// of the last step (kept in the key column's `tangential`). A mesh contact takes the slot
// whose key is closest to its normal (within ~37 degrees), so a spring follows a particle
// that slides or rolls across triangle boundaries of a flat or gently curved mesh.
#include <array>
#include <string>
#include <vector>

#include "dem/scene/scene.hpp"
#include "dem/walls/triangle_mesh.hpp"
#include "dem/walls/wall_motion.hpp"

namespace grainflow {

class WallSet {
 public:
  static constexpr int kMeshSlots = 3;
  static constexpr double kSlotMatchCosine = 0.8;

  struct Entry {
    Wall::Kind kind = Wall::Kind::plane;
    std::string name;
    int material = 0;
    PlaneWall plane;        // current position (plane, cylinder)
    CylinderWall cylinder;  // current position
    int mesh = -1;          // index into meshes()
    bool closed = false;    // a mesh without open edges: a closed surface
    Vec3 surface_velocity = Vec3::Zero();  // mesh conveyor velocity in the body frame
    WallPose pose;
    int column = 0;  // first history column
    // at t = 0
    PlaneWall plane0;
    CylinderWall cylinder0;
  };

  WallSet() = default;
  // Reads every mesh's STL file (GeometryError on a bad file). The largest radius
  // of the scene's fill and stream insertions sizes the mesh search grids.
  explicit WallSet(const Scene& scene);

  // A closed mesh with particle centres (at t = 0) on both sides of it: a warning among notes(),
  // naming the counts (those inside a solid obstacle are trapped there). A mesh with more than
  // `budget` centre-triangle tests is left unchecked.
  void check_closed_meshes(const std::vector<Vec3>& centres, double budget = 2e8);

  // Places every moving wall at time t.
  void move_to(double t);

  // Re-sizes the mesh search grids for particles up to radius r_max (cells of one
  // diameter); call once the particles are known.
  void fit_grids(double r_max);

  const std::vector<Entry>& walls() const { return walls_; }
  const TriangleMesh& mesh(const Entry& e) const { return meshes_[e.mesh]; }
  std::size_t history_columns() const { return columns_; }
  // The history columns of one wall: 2 kMeshSlots for a mesh, 1 for a plane or a cylinder.
  static std::size_t columns_of(const Entry& e) {
    return e.kind == Wall::Kind::mesh ? 2 * kMeshSlots : 1;
  }
  bool empty() const { return walls_.empty(); }

  // True if a sphere at x with radius r touches any wall (insertion).
  // `still_only`: the walls that do not move (a moving one may make room later).
  bool touches_any(const Vec3& x, double r, bool still_only = false) const;

  // The wall a sphere at x with radius r overlaps most (index into walls(); -1: none) and
  // by how much; an overlap above r means its centre is on the wall's far side (planes and
  // cylinders; a mesh has no far side: its overlap is at most r).
  struct Overlap {
    int wall = -1;
    double overlap = 0;
  };
  Overlap deepest_overlap(const Vec3& x, double r) const;

  // One line per mesh: triangles, vertices, repairs (for the run report).
  const std::vector<std::string>& notes() const { return notes_; }

  // x moved into the domain along its periodic axes. Between the neighbour rebuilds that wrap
  // them, centres drift up to half a skin past a periodic side; a mesh is not repeated across
  // the sides, so asked at such a centre it would miss the part of itself where the particle
  // already is (a floor ending at the side: the bead rolls onto its rim and falls through).
  // Planes and cylinders look alike from both sides (scene_parser.cpp) and need no wrap.
  Vec3 in_period(const Vec3& x) const {
    if (!any_periodic_) return x;
    Vec3 y = x;
    for (int a = 0; a < 3; ++a) {
      if (!periodic_[a]) continue;
      if (y[a] < lo_[a])
        y[a] += hi_[a] - lo_[a];
      else if (y[a] >= hi_[a])
        y[a] -= hi_[a] - lo_[a];
    }
    return y;
  }
  // Where mesh e is asked about a particle at x, already in_period: in the mesh's body frame.
  static Vec3 mesh_query(const Entry& e, const Vec3& x) {
    return e.pose.moving() ? e.pose.to_body(x) : x;
  }

 private:
  std::vector<Entry> walls_;
  std::vector<TriangleMesh> meshes_;
  std::size_t columns_ = 0;
  std::vector<std::string> notes_;
  Vec3 lo_ = Vec3::Zero(), hi_ = Vec3::Zero();  // the domain
  std::array<bool, 3> periodic_{false, false, false};
  bool any_periodic_ = false;
};

}  // namespace grainflow
