#pragma once
// Particle-wall part of the contact sweep (see contact_sweep.hpp): one loop per
// wall, with the wall kind chosen outside the particle loop. Included only by
// contact_sweep.cpp, where each contact law is instantiated.
//
// Walls may move (WallSet, wall_motion.hpp): the wall's velocity at the contact
// point enters the relative velocity. Meshes are searched in their body frame.
#include <algorithm>
#include <cmath>

#include "dem/contact/contact_law.hpp"
#include "dem/engine/contact_sweep.hpp"
#include "dem/walls/wall_contact.hpp"
#include "dem/walls/wall_set.hpp"

namespace grainflow {

// The geometry the law sees for particle i touching a wall as `t` describes.
template <class Law>
inline ContactGeometry wall_geometry(const Particles& p, std::size_t i, const WallTouch& t) {
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
  // Springs: the half-step velocities; dashpots: Particles::v_pred (the wall's velocity is
  // that of the step's end, exact for prescribed motion).
  if constexpr (Law::needs_spin) {
    g.v_rel = p.v[i] - t.surface_velocity - g.arm_i * p.omega[i].cross(g.n);
    g.w_rel = p.omega[i] - t.spin;
    if constexpr (Law::predicted_dashpot) {
      g.v_pred = p.v_pred[i] - t.surface_velocity - g.arm_i * p.omega_pred[i].cross(g.n);
      g.w_pred = p.omega_pred[i] - t.spin;
    } else {
      g.v_pred = g.v_rel;
      g.w_pred = g.w_rel;
    }
  } else if constexpr (Law::predicted_dashpot) {
    g.v_rel = p.v[i] - t.surface_velocity;  // the cell dashpot's last drift
    g.v_pred = p.v_pred[i] - t.surface_velocity;
  } else {
    g.v_pred = p.v[i] - t.surface_velocity;
  }
  if constexpr (Law::needs_roll_inertia)
    g.roll_inertia = p.inertia[i] + p.mass[i] * p.radius[i] * p.radius[i];
  return g;
}

// Evaluates one particle-wall contact and adds its force and torque to particle i.
template <class Law>
void apply_wall_contact(ContactSweep& s, std::size_t i, const WallTouch& t, int material,
                        ContactHistory& h) {
  Particles& p = s.p;
  const ContactGeometry g = wall_geometry<Law>(p, i, t);
  const ContactResult r = Law::evaluate(g, s.table(p.material[i], material), s.constants,
                                        h.tangential, h.rolling, s.dt, s.spring_dt);
  p.force[i] += r.force;
  if constexpr (Law::needs_spin) p.torque[i] += r.torque_i;
  if (s.load) *s.load += r.force;
  ++s.contacts;
  if (const double ratio = g.overlap / p.radius[i]; ratio > s.max_overlap_ratio)
    s.worst.consider(ratio, s.max_overlap_ratio, p.id[i], -1, -g.v_pred.dot(g.n), g.r_star, g.m_star,
                     s.table(p.material[i], material).y_star);
}

// A contact of a plane or cylinder wall found touching, waiting to be evaluated with the
// wall's other contacts.
struct WallHit {
  int i;  // particle
  int k;  // its entry of the wall's list: the history slot
  WallTouch t;
};
constexpr int kWallBatch = 32;

// Evaluates the contacts hits[0, m) with a wall of `material`, in order, and adds their
// forces and torques; history[k] holds each one's springs. Defined in contact_sweep.cpp: in
// the lanes of the pair kernel when the law can, else one by one (apply_wall_contact).
template <class Law>
void apply_wall_contacts(ContactSweep& s, int material, const WallHit* hits, int m,
                         std::vector<ContactHistory>& history);

// A plane or a cylinder, against the particles of its neighbour list (all of them when
// `list.all`; the others cannot touch it before the next rebuild). `history` holds the
// springs in list order (one per particle when `list.all`; wall_neighbours.hpp). The touching
// ones are gathered kWallBatch at a time and evaluated together; each particle appears once
// per wall, so its forces are summed in the same order as contact by contact.
template <class Law, class Touch>
void wall_sweep_one(ContactSweep& s, const WallSet::Entry& wall, const WallNeighbours::List& list,
                    std::vector<ContactHistory>& history, Touch touch) {
  Particles& p = s.p;
  WallHit hits[kWallBatch];
  int m = 0;
  const std::size_t n = list.all ? p.size() : list.i.size();
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = list.all ? k : static_cast<std::size_t>(list.i[k]);
    WallHit& hit = hits[m];
    if (!touch(p.x[i], p.radius[i], hit.t)) {
      if constexpr (Law::has_history) history[k] = ContactHistory{};
      continue;
    }
    if (wall.pose.moving()) {
      hit.t.surface_velocity +=
          wall.pose.velocity_at(p.x[i] - (p.radius[i] - hit.t.overlap) * hit.t.n);
      hit.t.spin += wall.pose.spin();
    }
    hit.i = static_cast<int>(i);
    hit.k = static_cast<int>(k);
    if (++m == kWallBatch) {
      apply_wall_contacts<Law>(s, wall.material, hits, m, history);
      m = 0;
    }
  }
  if (m > 0) apply_wall_contacts<Law>(s, wall.material, hits, m, history);
}

// A mesh contact found in the body frame, in the world: normal, overlap and the wall's
// velocity at the contact point (motion and conveyor belt, `belt` in the world frame).
inline WallTouch mesh_wall_touch(const WallSet::Entry& wall, const MeshTouch& touch, const Vec3& x,
                                 double r, bool moving, bool conveyor, const Vec3& belt) {
  WallTouch t;
  t.n = moving ? wall.pose.direction_to_world(touch.n) : touch.n;
  t.overlap = touch.overlap;
  t.surface_velocity.setZero();
  t.spin.setZero();
  if (moving) {
    t.surface_velocity = wall.pose.velocity_at(x - (r - t.overlap) * t.n);
    t.spin = wall.pose.spin();
  }
  if (conveyor) t.surface_velocity += belt - belt.dot(t.n) * t.n;
  return t;
}

// The history slot of particle i's mesh contact with normal n: the unused slot whose key
// normal is closest to n (within WallSet::kSlotMatchCosine), else a free one, else a stale
// one; -1 when all are used. Reads the keys only (the sweep then sets the chosen key to n).
inline int mesh_slot(const std::vector<std::vector<ContactHistory>>& history, int column,
                     std::size_t i, const Vec3& n, const bool* used) {
  constexpr int kSlots = WallSet::kMeshSlots;
  int best = -1;
  double best_cos = WallSet::kSlotMatchCosine;
  for (int j = 0; j < kSlots; ++j) {
    const Vec3& key = history[column + 2 * j + 1][i].tangential;
    if (!used[j] && key.dot(n) > best_cos) {
      best = j;
      best_cos = key.dot(n);
    }
  }
  for (int j = 0; j < kSlots && best < 0; ++j)
    if (!used[j] && history[column + 2 * j + 1][i].tangential.isZero(0)) best = j;
  for (int j = 0; j < kSlots && best < 0; ++j)  // stale key of an older contact
    if (!used[j]) best = j;
  return best;
}

// A mesh: every contact of the particle with the mesh (one per touching feature,
// triangle_mesh.hpp), each with the history slot whose key normal matches it.
template <class Law>
void mesh_sweep(ContactSweep& s, const WallSet::Entry& wall, const TriangleMesh& mesh) {
  constexpr int kSlots = WallSet::kMeshSlots;
  Particles& p = s.p;
  const bool moving = wall.pose.moving();
  const bool conveyor = wall.surface_velocity.squaredNorm() > 0;
  const Vec3 belt = wall.pose.direction_to_world(wall.surface_velocity);
  MeshTouch touch[TriangleMesh::kMaxTouches];
  ContactHistory scratch;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double r = p.radius[i];
    const Vec3 x = s.walls.in_period(p.x[i]);
    const int n = mesh.touches(WallSet::mesh_query(wall, x), r, touch);
    bool used[kSlots] = {};
    for (int k = 0; k < n; ++k) {
      const WallTouch t = mesh_wall_touch(wall, touch[k], x, r, moving, conveyor, belt);
      ContactHistory* h = &scratch;
      if constexpr (Law::has_history) {
        const int best = mesh_slot(s.wall_history, wall.column, i, t.n, used);
        if (best >= 0) {
          used[best] = true;
          s.wall_history[wall.column + 2 * best + 1][i].tangential = t.n;
          h = &s.wall_history[wall.column + 2 * best][i];
        } else {
          scratch = ContactHistory{};  // more contacts than slots: no memory
        }
      }
      apply_wall_contact<Law>(s, i, t, wall.material, *h);
    }
    if constexpr (Law::has_history)
      for (int j = 0; j < kSlots; ++j)
        if (!used[j]) {
          s.wall_history[wall.column + 2 * j][i] = ContactHistory{};
          s.wall_history[wall.column + 2 * j + 1][i] = ContactHistory{};
        }
  }
}

template <class Law>
void wall_sweep(ContactSweep& s) {
  for (std::size_t w = 0; w < s.walls.walls().size(); ++w) {
    const WallSet::Entry& wall = s.walls.walls()[w];
    const WallNeighbours::List& list = s.wall_neighbours.lists[w];
    if (s.wall_forces) s.load = &(*s.wall_forces)[w];
    switch (wall.kind) {
      case Wall::Kind::plane:
        wall_sweep_one<Law>(s, wall, list, s.wall_history[wall.column],
                            [&wall](const Vec3& x, double r, WallTouch& t) {
                              return touch_plane(wall.plane, x, r, t);
                            });
        break;
      case Wall::Kind::cylinder:
        wall_sweep_one<Law>(s, wall, list, s.wall_history[wall.column],
                            [&wall](const Vec3& x, double r, WallTouch& t) {
                              return touch_cylinder(wall.cylinder, x, r, t);
                            });
        break;
      case Wall::Kind::mesh:
        mesh_sweep<Law>(s, wall, s.walls.mesh(wall));
        break;
    }
  }
  s.load = nullptr;
}

}  // namespace grainflow
