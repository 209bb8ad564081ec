#include "dem/walls/wall_set.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "dem/insert/insertion.hpp"
#include "dem/walls/stl_reader.hpp"
#include "dem/walls/wall_contact.hpp"

namespace grainflow {

WallSet::WallSet(const Scene& scene)
    : lo_(scene.domain.lo), hi_(scene.domain.hi), periodic_(scene.domain.periodic) {
  any_periodic_ = periodic_[0] || periodic_[1] || periodic_[2];
  double r_hint = 0;
  for (const Insertion& ins : scene.insertions)
    if (ins.kind == Insertion::Kind::fill || ins.kind == Insertion::Kind::stream)
      r_hint = std::max(r_hint, max_radius(ins.radius));
  for (const Wall& w : scene.walls) {
    Entry e;
    e.kind = w.kind;
    e.name = w.name;
    e.material = w.material;
    e.plane = e.plane0 = w.plane;
    e.cylinder = e.cylinder0 = w.cylinder;
    e.pose = WallPose(w.motion);
    e.column = static_cast<int>(columns_);
    if (w.kind == Wall::Kind::mesh) {
      MeshTransform t;
      t.scale = w.mesh.scale;
      t.rotation_axis = w.mesh.rotate_axis;
      t.rotation_angle = w.mesh.rotate_angle;
      t.translation = w.mesh.translate;
      StlReport rep;
      const std::string of_wall =
          " (the mesh of wall '" + w.name + "'" +
          (w.mesh.file_source.empty() ? std::string() : ", " + w.mesh.file_source) + ")";
      TriangleMesh m = [&] {
        try {
          return read_stl(w.mesh.file, t, &rep, w.mesh.weld_tolerance);
        } catch (const GeometryError& error) {
          throw GeometryError(error.what() + of_wall);
        }
      }();
      // A static mesh none of whose triangles reaches into the domain (by a particle radius)
      // touches no particle: a mistake, most often an STL in millimetres read as metres (a
      // 12 m box around a 12 mm domain).
      const Domain& d = scene.domain;
      const bool moves = w.motion.velocity.squaredNorm() > 0 || w.motion.angular_velocity != 0;
      const Vec3 reach = Vec3::Constant(r_hint);
      const auto reaches_in = [&](const std::array<int, 3>& tri) {
        const Vec3& a = m.vertices()[tri[0]];
        const Vec3& b = m.vertices()[tri[1]];
        const Vec3& c = m.vertices()[tri[2]];
        const Vec3 lo = a.cwiseMin(b).cwiseMin(c), hi = a.cwiseMax(b).cwiseMax(c);
        return (lo.array() <= (d.hi + reach).array()).all() &&
               (hi.array() >= (d.lo - reach).array()).all();
      };
      if (!moves && std::none_of(m.triangles().begin(), m.triangles().end(), reaches_in)) {
        std::ostringstream o;
        o.precision(4);
        o << w.mesh.file << ": error: the mesh spans (" << m.lo()[0] << ", " << m.lo()[1] << ", "
          << m.lo()[2] << ") to (" << m.hi()[0] << ", " << m.hi()[1] << ", " << m.hi()[2]
          << ") m after its placement (scale " << w.mesh.scale << "); the domain spans (" << d.lo[0]
          << ", " << d.lo[1] << ", " << d.lo[2] << ") to (" << d.hi[0] << ", " << d.hi[1] << ", "
          << d.hi[2] << ") m, and none of its triangles reaches into the "
          << "domain: no particle can touch it. An STL in millimetres "
          << "needs `scale: 0.001`; else check `translate` and `rotate`" << of_wall;
        throw GeometryError(o.str());
      }
      // Cells of one particle diameter: a query visits at most 8 small cells, each
      // holding only the few triangles that pass near it. Without a known radius
      // (CSV or snapshot particles only), cells of the mean triangle edge.
      m.build_grid(r_hint > 0 ? 2 * r_hint : m.mean_edge_length());
      std::ostringstream note;
      note << "wall '" << w.name << "': " << m.triangle_count() << " triangles, "
           << m.vertex_count() << " vertices from " << (rep.binary ? "binary" : "ASCII")
           << " STL " << w.mesh.file;
      if (rep.degenerate_removed > 0)
        note << " (" << rep.degenerate_removed << " degenerate triangles removed)";
      note << "; " << rep.welded << " vertices welded (closer than " << rep.weld_distance
           << " m = " << w.mesh.weld_tolerance << " of the diagonal)";
      if (rep.t_junctions > 0)
        note << "; " << rep.t_junctions
             << " T-junction(s) closed (a vertex inside another triangle's edge: that triangle "
                "split there, so that the edge is shared)";
      if (rep.open_edges > 0)
        note << "; " << rep.open_edges
             << " open edges (of one triangle: the rim of an open surface, or seams)";
      notes_.push_back(note.str());
      if (rep.seam_gap >= 0) {
        std::ostringstream warn;
        warn << "warning: wall '" << w.name << "' (" << w.mesh.file
             << "): two open-edge vertices of no common triangle are " << rep.seam_gap
             << " m apart near (" << rep.seam_at[0] << ", " << rep.seam_at[1] << ", "
             << rep.seam_at[2] << "): a seam that welding left open (a sphere on it feels two "
             << "contacts). If they are one point, set `weld_tolerance` above "
             << rep.seam_gap / rep.diagonal << " (now " << w.mesh.weld_tolerance << ")";
        notes_.push_back(warn.str());
      }
      if (rep.t_gap >= 0) {
        std::ostringstream warn;
        warn << "warning: wall '" << w.name << "' (" << w.mesh.file << "): an open-edge vertex at ("
             << rep.t_gap_at[0] << ", " << rep.t_gap_at[1] << ", " << rep.t_gap_at[2] << ") lies "
             << rep.t_gap
             << " m from another triangle's open edge: a T-junction left open (a sphere on it "
                "feels two contacts). If the vertex belongs on that edge, set `weld_tolerance` "
                "above "
             << rep.t_gap / rep.diagonal << " (now " << w.mesh.weld_tolerance
             << "): the edge's triangle is then split at the vertex";
        notes_.push_back(warn.str());
      }
      e.mesh = static_cast<int>(meshes_.size());
      e.closed = rep.open_edges == 0;
      e.surface_velocity = w.mesh.surface_velocity;
      meshes_.push_back(std::move(m));
    }
    columns_ += columns_of(e);
    walls_.push_back(std::move(e));
  }
}

void WallSet::check_closed_meshes(const std::vector<Vec3>& centres, double budget) {
  for (const Entry& e : walls_) {
    if (e.kind != Wall::Kind::mesh || !e.closed || centres.empty()) continue;
    const TriangleMesh& m = meshes_[e.mesh];
    long in_box = 0;
    for (const Vec3& x : centres)
      in_box += (x.array() >= m.lo().array()).all() && (x.array() <= m.hi().array()).all();
    if (static_cast<double>(in_box) * static_cast<double>(m.triangle_count()) > budget) continue;
    long inside = 0;
    for (const Vec3& x : centres) inside += m.encloses(x);
    const long outside = static_cast<long>(centres.size()) - inside;
    if (inside == 0 || outside == 0) continue;
    std::ostringstream o;
    o << "warning: wall '" << e.name << "' is a closed surface, and " << inside << " of the "
      << centres.size() << " particles start inside it, " << outside
      << " outside: the two groups never meet, and those inside a solid obstacle stay trapped "
         "in it. If the mesh is an obstacle, keep the insertions out of it (fill regions "
         "beside it, or csv rows outside it); if it is a container, keep them in it";
    notes_.push_back(o.str());
  }
}

void WallSet::fit_grids(double r_max) {
  if (r_max <= 0) return;
  for (TriangleMesh& m : meshes_)
    if (std::abs(m.cell_size() - 2 * r_max) > 0.25 * m.cell_size()) m.build_grid(2 * r_max);
}

void WallSet::move_to(double t) {
  for (Entry& e : walls_) {
    if (!e.pose.moving()) continue;
    e.pose.move_to(t);
    if (e.kind == Wall::Kind::plane) {
      e.plane.point = e.pose.to_world(e.plane0.point);
      e.plane.normal = e.pose.direction_to_world(e.plane0.normal);
    } else if (e.kind == Wall::Kind::cylinder) {
      e.cylinder.axis_point = e.pose.to_world(e.cylinder0.axis_point);
      e.cylinder.axis = e.pose.direction_to_world(e.cylinder0.axis);
    }
  }
}

bool WallSet::touches_any(const Vec3& x, double r, bool still_only) const {
  WallTouch t;
  MeshTouch m[TriangleMesh::kMaxTouches];
  for (const Entry& e : walls_) {
    if (still_only && e.pose.moving()) continue;
    switch (e.kind) {
      case Wall::Kind::plane:
        if (touch_plane(e.plane, x, r, t)) return true;
        break;
      case Wall::Kind::cylinder:
        if (touch_cylinder(e.cylinder, x, r, t)) return true;
        break;
      case Wall::Kind::mesh:
        if (meshes_[e.mesh].touches(e.pose.to_body(in_period(x)), r, m) > 0) return true;
        break;
    }
  }
  return false;
}

WallSet::Overlap WallSet::deepest_overlap(const Vec3& x, double r) const {
  Overlap deepest;
  auto take = [&](std::size_t k, double overlap) {
    if (overlap > deepest.overlap) deepest = {static_cast<int>(k), overlap};
  };
  WallTouch t;
  MeshTouch m[TriangleMesh::kMaxTouches];
  for (std::size_t k = 0; k < walls_.size(); ++k) {
    const Entry& e = walls_[k];
    switch (e.kind) {
      case Wall::Kind::plane:
        if (touch_plane(e.plane, x, r, t)) take(k, t.overlap);
        break;
      case Wall::Kind::cylinder:
        if (touch_cylinder(e.cylinder, x, r, t)) take(k, t.overlap);
        break;
      case Wall::Kind::mesh: {
        const int n = meshes_[e.mesh].touches(e.pose.to_body(in_period(x)), r, m);
        for (int c = 0; c < n; ++c) take(k, m[c].overlap);
        break;
      }
    }
  }
  return deepest;
}

}  // namespace grainflow
