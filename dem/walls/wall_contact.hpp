#pragma once
// Sphere-wall geometry: for each wall kind, whether a sphere touches it, the
// unit normal pointing from the wall into the particle, the overlap, and the
// wall's surface velocity at the contact point. Walls are treated as flat at the
// contact (R* = particle radius), the usual DEM convention for walls much larger
// than the particles.
#include <cmath>

#include "dem/scene/scene.hpp"

namespace grainflow {

struct WallTouch {
  Vec3 n;
  double overlap;
  Vec3 surface_velocity;
  // The wall's angular velocity [rad/s]: a cylinder's own turning and a rotating motion. The
  // rolling models act on the particle's spin relative to it (a sphere carried round by a
  // drum at the drum's own spin does not roll on it).
  Vec3 spin = Vec3::Zero();
};

inline bool touch_plane(const PlaneWall& w, const Vec3& x, double r, WallTouch& t) {
  const double dist = (x - w.point).dot(w.normal);
  const double overlap = r - dist;
  if (overlap <= 0) return false;
  t.n = w.normal;
  t.overlap = overlap;
  t.surface_velocity.setZero();
  t.spin.setZero();
  return true;
}

// A unit vector normal to the unit vector a, a function of a alone.
inline Vec3 axis_normal(const Vec3& a) {
  return (std::abs(a[0]) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(a).normalized();
}

inline bool touch_cylinder(const CylinderWall& w, const Vec3& x, double r, WallTouch& t) {
  const Vec3 rel = x - w.axis_point;
  const Vec3 radial = rel - rel.dot(w.axis) * w.axis;
  const double rho = radial.norm();
  const double overlap = w.inside ? r - (w.radius - rho) : r - (rho - w.radius);
  if (overlap <= 0) return false;
  // On the axis every radial direction is as near: take one fixed by the axis alone, so a
  // sphere there (the deepest overlap of an `outside` cylinder) is pushed off, not ignored.
  const Vec3 out = rho > 0 ? Vec3(radial / rho) : axis_normal(w.axis);
  t.n = w.inside ? Vec3(-out) : out;
  t.overlap = overlap;
  // Contact point on the cylinder surface; the surface turns about the axis.
  const Vec3 surface_point = w.axis_point + rel.dot(w.axis) * w.axis + w.radius * out;
  t.surface_velocity = w.angular_velocity * w.axis.cross(surface_point - w.axis_point);
  t.spin = w.angular_velocity * w.axis;
  return true;
}

// Planes and cylinders at their t = 0 position; meshes need their loaded geometry
// (WallSet::touches_any) and are not seen here.
inline bool touch_wall(const Wall& w, const Vec3& x, double r, WallTouch& t) {
  switch (w.kind) {
    case Wall::Kind::plane: return touch_plane(w.plane, x, r, t);
    case Wall::Kind::cylinder: return touch_cylinder(w.cylinder, x, r, t);
    case Wall::Kind::mesh: break;
  }
  return false;
}

}  // namespace grainflow
