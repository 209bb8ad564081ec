#pragma once
// Particle-wall part of the contact sweep (see contact_sweep.hpp): one loop per
// wall, with the wall kind chosen outside the particle loop. Included only by
// contact_sweep.cpp, where each contact law is instantiated.
#include <algorithm>
#include <cmath>

#include "dem/contact/contact_law.hpp"
#include "dem/engine/contact_sweep.hpp"
#include "dem/walls/wall_contact.hpp"

namespace grainflow {

template <class Law, class Touch>
void wall_sweep_one(ContactSweep& s, const Wall& wall, std::vector<ContactHistory>& history,
                Touch touch) {
  Particles& p = s.p;
  ContactHistory unused;
  for (std::size_t i = 0; i < p.size(); ++i) {
    WallTouch t;
    if (!touch(p.x[i], p.radius[i], t)) {
      if constexpr (Law::has_history) history[i] = ContactHistory{};
      continue;
    }
    ContactGeometry g;
    g.n = t.n;
    g.overlap = t.overlap;
    g.distance = p.radius[i] - t.overlap;
    g.r_i = p.radius[i];
    g.r_j = 0;
    g.arm_i = g.distance;
    g.arm_j = 0;
    g.r_star = p.radius[i];
    g.m_star = p.mass[i];
    g.wall = true;
    if constexpr (Law::needs_spin) {
      g.v_rel = p.v[i] - t.surface_velocity - g.arm_i * p.omega[i].cross(g.n);
      g.w_rel = p.omega[i];
    } else {
      g.v_rel = p.v[i] - t.surface_velocity;
    }
    if constexpr (Law::needs_roll_inertia)
      g.roll_inertia = p.inertia[i] + p.mass[i] * p.radius[i] * p.radius[i];
    ContactHistory& h = Law::has_history ? history[i] : unused;
    const ContactResult r =
        Law::evaluate(g, s.table(p.material[i], wall.material), s.constants, h, s.dt);
    p.force[i] += r.force;
    if constexpr (Law::needs_spin) p.torque[i] += r.torque_i;
    ++s.contacts;
    s.max_overlap_ratio = std::max(s.max_overlap_ratio, g.overlap / p.radius[i]);
  }
}

template <class Law>
void wall_sweep(ContactSweep& s) {
  for (std::size_t w = 0; w < s.walls.size(); ++w) {
    const Wall& wall = s.walls[w];
    if (wall.kind == Wall::Kind::plane)
      wall_sweep_one<Law>(s, wall, s.wall_history[w],
                          [&wall](const Vec3& x, double r, WallTouch& t) {
                            return touch_plane(wall.plane, x, r, t);
                          });
    else
      wall_sweep_one<Law>(s, wall, s.wall_history[w],
                          [&wall](const Vec3& x, double r, WallTouch& t) {
                            return touch_cylinder(wall.cylinder, x, r, t);
                          });
  }
}

}  // namespace grainflow
