#include "dem/walls/wall_travel.hpp"

#include "dem/core/number_format.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "dem/engine/time_step.hpp"

namespace grainflow {
namespace {

// Distance of x from the line through p along the unit vector a.
double distance_to_axis(const Vec3& x, const Vec3& p, const Vec3& a) {
  const Vec3 d = x - p;
  return (d - d.dot(a) * a).norm();
}

// The farthest corner of the domain from the rotation axis.
double farthest_domain_corner(const Domain& d, const WallMotion& m) {
  double rho = 0;
  for (int c = 0; c < 8; ++c) {
    const Vec3 x((c & 1) ? d.hi[0] : d.lo[0], (c & 2) ? d.hi[1] : d.lo[1],
                 (c & 4) ? d.hi[2] : d.lo[2]);
    rho = std::max(rho, distance_to_axis(x, m.axis_point, m.axis));
  }
  return rho;
}

bool parallel(const Vec3& a, const Vec3& b) { return a.cross(b).norm() <= 1e-12; }

}  // namespace

double wall_sweep_speed(const Scene& scene, const WallSet& walls, std::size_t k) {
  const Wall& w = scene.walls[k];
  const WallMotion& m = w.motion;
  const double spin = std::abs(m.angular_velocity);
  // The axis moves with V during the run: the domain's corners may come that much farther.
  const double axis_travel = m.velocity.norm() * scene.time.end;
  switch (w.kind) {
    case Wall::Kind::plane: {
      const Vec3& n = w.plane.normal;
      const double rotation = spin == 0 || parallel(m.axis, n)
                                  ? 0.0
                                  : spin * (farthest_domain_corner(scene.domain, m) + axis_travel);
      return std::abs(n.dot(m.velocity)) + rotation;
    }
    case Wall::Kind::cylinder: {
      const Vec3& c = w.cylinder.axis;
      const bool own_axis =
          parallel(m.axis, c) && distance_to_axis(m.axis_point, w.cylinder.axis_point, c) <=
                                     1e-12 * std::max(1.0, w.cylinder.radius);
      const double rotation = spin == 0 || own_axis
                                  ? 0.0
                                  : spin * (farthest_domain_corner(scene.domain, m) + axis_travel);
      return (m.velocity - m.velocity.dot(c) * c).norm() + rotation;
    }
    case Wall::Kind::mesh: {
      double rho = 0;
      if (spin > 0)
        for (const Vec3& v : walls.mesh(walls.walls()[k]).vertices())
          rho = std::max(rho, distance_to_axis(v, m.axis_point, m.axis));
      return m.velocity.norm() + spin * rho;
    }
  }
  return 0;
}

WallTravelReport check_wall_travel(const Scene& scene, const WallSet& walls, double dt,
                                   double r_min, int material, const PairTable& table,
                                   double startup_step) {
  WallTravelReport rep;
  const double limit = scene.time.max_step_travel;
  long worst = -1;  // index into rep.walls
  double fit = 0;
  for (std::size_t k = 0; k < scene.walls.size(); ++k) {
    const WallMotion& m = scene.walls[k].motion;
    if (m.velocity.squaredNorm() == 0 && m.angular_velocity == 0) continue;
    const double v = wall_sweep_speed(scene, walls, k);
    rep.walls.push_back({scene.walls[k].name, k, v, v * dt});
    std::ostringstream o;
    o.precision(4);
    o << "wall '" << scene.walls[k].name << "' moves ";
    if (v == 0) {
      o << "only along its own surface (no travel across particles)";
    } else {
      o << v * dt << " m per step (sweep speed " << v << " m/s x dt = " << dt << " s)";
      if (r_min > 0) o << " = " << v * dt / r_min << " x the smallest radius " << r_min << " m";
      if (limit > 0) o << "; limit " << limit << " (key time.max_step_travel)";
    }
    rep.notes.push_back(o.str());
    if (limit > 0 && r_min > 0 && v * dt > limit * r_min) {
      if (worst < 0 || v > rep.walls[worst].speed) {
        worst = static_cast<long>(rep.walls.size()) - 1;
        fit = limit * r_min / v;
      }
    }
  }
  if (worst < 0) return rep;
  const WallTravel& w = rep.walls[worst];
  // The fastest wall sets the step; it fits every slower one too.
  const double wall_fit = round_down_3(fit), travel_step = round_down_3(fit / 2);
  const bool startup_smaller = startup_step < travel_step;
  const double step = startup_smaller ? round_down_3(startup_step) : travel_step;
  rep.fitting_step = step;
  std::ostringstream o;
  o.precision(4);
  o << scene.file << ": error: wall '" << w.name << "' moves " << w.travel / r_min
    << " x the smallest particle radius per step (sweep speed " << w.speed << " m/s x dt = " << dt
    << " s = " << w.travel << " m; smallest radius " << r_min << " m); the limit is " << limit
    << " (key time.max_step_travel, the same rule as for particles). So fast a wall can pass "
       "through a particle between two steps without ever overlapping it, which no contact "
       "guard can see. A step of at most "
    << step << " s fits: the wall alone needs at most " << wall_fit
    << " s, and a particle it strikes leaves at up to twice the wall's speed";
  if (startup_smaller)
    o << " (" << travel_step << " s); the start-up checks of dt (the Rayleigh and contact times"
      << (scene.heat ? ", heat conduction" : "") << ") need at most " << round_down_3(startup_step)
      << " s";
  if (scene.contact.normal == NormalModel::hertz && material >= 0) {
    const int wall_material = scene.walls[w.index].material;
    const double mass = scene.materials[material].density * sphere_volume(r_min);
    const double tc =
        hertz_contact_time(table(material, wall_material).y_star, r_min, mass, w.speed);
    rep.impact_step = round_down_3(tc / 20);
    o << "; resolving the impact of that particle on the wall at " << w.speed
      << " m/s needs at most " << rep.impact_step
      << " s (1/20 of the Hertz contact time against a wall of its material '"
      << scene.materials[wall_material].name << "')";
  }
  o << ". Or slow the wall (its `motion`), or use larger particles";
  rep.error = o.str();
  return rep;
}

}  // namespace grainflow
