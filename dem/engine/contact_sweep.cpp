#include "dem/engine/contact_sweep.hpp"

#include <algorithm>
#include <cmath>

#include "dem/engine/wall_sweep.hpp"

namespace grainflow {

void UnresolvedContact::record(double vn, double rs, double ms, double ys, double overlap_ratio_now,
                               GlobalId ia, GlobalId ib, double dt) {
  const double steps = 2.868 * std::pow(ms * ms / (rs * ys * ys * vn), 0.2) / dt;
  if (fewest > 0 && steps >= fewest) return;
  fewest = steps;
  overlap_ratio = overlap_ratio_now;
  double unused = 0;
  contact.consider(1, unused, ia, ib, vn, rs, ms, ys);
}

namespace {

// The state of one body of a pair, as the pair kernel reads it.
struct Body {
  const Vec3& v;
  const Vec3& w;
  double r, m, inertia;
  int material;
};

// Whether a listed pair is apart: the Verlet lists hold every pair within the skin, and in
// a packed bed about three in four of them do not touch. This test comes first, on the
// positions and radii alone, before anything else of the pair is loaded. It gives the same
// answer bit for bit whichever partner comes first (a negated difference has the same
// squares; + is commutative), so it is asked before the pair is put in canonical order.
inline bool apart(const Vec3& d, double rs) { return d.squaredNorm() >= rs * rs; }

// Evaluates the touching pair (a, b) with displacement d = x_a - x_b. Inlined into the
// sweeps, like the law's evaluation: the geometry and the result then stay in registers
// instead of going through memory.
template <class Law>
[[gnu::always_inline]] inline ContactResult pair_force(const ContactSweep& s, const Vec3& d, const Body& a, const Body& b,
                         Vec3& tangential, Vec3& rolling, double& overlap) {
  const double rs = a.r + b.r;
  const double dist = std::sqrt(d.squaredNorm());
  ContactGeometry g;
  g.n = d / dist;
  g.overlap = overlap = rs - dist;
  g.distance = dist;
  g.r_i = a.r;
  g.r_j = b.r;
  g.arm_i = a.r - 0.5 * g.overlap;
  g.arm_j = b.r - 0.5 * g.overlap;
  g.r_star = a.r * b.r / rs;
  g.m_star = a.m * b.m / (a.m + b.m);
  g.wall = false;
  if constexpr (Law::needs_spin) {
    // Evaluated first: GCC does not inline Eigen's cross product of an expression.
    const Vec3 arm_w = g.arm_i * a.w + g.arm_j * b.w;
    g.v_rel = a.v - b.v - arm_w.cross(g.n);
    g.w_rel = a.w - b.w;
  } else {
    g.v_rel = a.v - b.v;
  }
  if constexpr (Law::needs_roll_inertia)
    g.roll_inertia =
        1.0 / (1.0 / (a.inertia + a.m * a.r * a.r) + 1.0 / (b.inertia + b.m * b.r * b.r));
  return Law::evaluate(g, s.table(a.material, b.material), s.constants, tangential, rolling, s.dt);
}

template <class Law>
void local_pair_sweep(ContactSweep& s) {
  Particles& p = s.p;
  Vec3 unused;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (int k = s.local_list.offsets[i]; k < s.local_list.offsets[i + 1]; ++k) {
      const std::size_t j = s.local_list.j[k];
      Vec3& ht = Law::keeps_tangential ? s.local_springs.tangential[k] : unused;
      Vec3& hr = Law::keeps_rolling ? s.local_springs.rolling[k] : unused;
      if (apart(p.x[i] - p.x[j], p.radius[i] + p.radius[j])) {
        if constexpr (Law::keeps_tangential) ht.setZero();
        if constexpr (Law::keeps_rolling) hr.setZero();
        continue;
      }
      const std::size_t a = p.id[i] < p.id[j] ? i : j, b = a == i ? j : i;
      double overlap;
      const ContactResult r = pair_force<Law>(
          s, p.x[a] - p.x[b],
          Body{p.v[a], p.omega[a], p.radius[a], p.mass[a], p.inertia[a], p.material[a]},
          Body{p.v[b], p.omega[b], p.radius[b], p.mass[b], p.inertia[b], p.material[b]}, ht, hr,
          overlap);
      p.force[a] += r.force;
      p.force[b] -= r.force;
      if constexpr (Law::needs_spin) {
        p.torque[a] += r.torque_i;
        p.torque[b] += r.torque_j;
      }
      ++s.contacts;
      // The guard's details are gathered only for a new largest overlap (rare).
      if (const double ratio = overlap / std::min(p.radius[a], p.radius[b]);
          ratio > s.max_overlap_ratio)
        s.worst.consider(ratio, s.max_overlap_ratio, p.id[a], p.id[b],
                         (p.x[a] - p.x[b]).normalized().dot(p.v[b] - p.v[a]),
                         p.radius[a] * p.radius[b] / (p.radius[a] + p.radius[b]),
                         p.mass[a] * p.mass[b] / (p.mass[a] + p.mass[b]),
                         s.table(p.material[a], p.material[b]).y_star);
    }
  }
}

template <class Law>
void ghost_pair_sweep(ContactSweep& s) {
  Particles& p = s.p;
  const Ghosts& g = s.ghosts;
  Vec3 unused;
  const Vec3 zero = Vec3::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (int k = s.ghost_list.offsets[i]; k < s.ghost_list.offsets[i + 1]; ++k) {
      const std::size_t q = s.ghost_list.j[k];
      Vec3& ht = Law::keeps_tangential ? s.ghost_springs.tangential[k] : unused;
      Vec3& hr = Law::keeps_rolling ? s.ghost_springs.rolling[k] : unused;
      if (apart((p.x[i] - g.x[q]) + (zero - g.shift[q]), p.radius[i] + g.radius[q])) {
        if constexpr (Law::keeps_tangential) ht.setZero();
        if constexpr (Law::keeps_rolling) hr.setZero();
        continue;
      }
      const Body local{p.v[i], p.omega[i], p.radius[i], p.mass[i], p.inertia[i], p.material[i]};
      const Body ghost{g.v[q], g.omega[q], g.radius[q], g.mass[q], g.inertia[q], g.material[q]};
      const bool local_first = p.id[i] < g.id[q];
      double overlap;
      const ContactResult r = local_first
                                  ? pair_force<Law>(s, (p.x[i] - g.x[q]) + (zero - g.shift[q]),
                                                    local, ghost, ht, hr, overlap)
                                  : pair_force<Law>(s, (g.x[q] - p.x[i]) + (g.shift[q] - zero),
                                                    ghost, local, ht, hr, overlap);
      p.force[i] += local_first ? r.force : Vec3(-r.force);
      if constexpr (Law::needs_spin) p.torque[i] += local_first ? r.torque_i : r.torque_j;
      // Both owners see this contact; the owner of the lower id counts it.
      if (local_first) ++s.contacts;
      if (const double ratio = overlap / std::min(local.r, ghost.r); ratio > s.max_overlap_ratio)
        s.worst.consider(ratio, s.max_overlap_ratio, p.id[i], g.id[q],
                         ((p.x[i] - g.x[q]) - g.shift[q]).normalized().dot(ghost.v - local.v),
                         local.r * ghost.r / (local.r + ghost.r),
                         local.m * ghost.m / (local.m + ghost.m),
                         s.table(local.material, ghost.material).y_star);
    }
  }
}

template <class Law>
void sweep(ContactSweep& s) {
  local_pair_sweep<Law>(s);
  ghost_pair_sweep<Law>(s);
  wall_sweep<Law>(s);
}

template <class Law>
SweepChoice choice() {
  return {&sweep<Law>,
          Law::has_history,
          Law::keeps_tangential,
          Law::keeps_rolling,
          Law::needs_spin,
          std::string(Law::normal::name) + " + " + Law::tangential::name + " + " +
              Law::rolling::name + " + " + Law::cohesion::name};
}

// Expands the run-time slot choice into one compile-time combination, one slot at a time.
template <class N, class T, class R>
SweepChoice pick_cohesion(const ContactSettings& c) {
  if (c.cohesion == CohesionModel::sjkr) return choice<ContactLaw<N, T, R, SjkrCohesion>>();
  return choice<ContactLaw<N, T, R, NoCohesion>>();
}
template <class N, class T>
SweepChoice pick_rolling(const ContactSettings& c) {
  switch (c.rolling) {
    case RollingModel::cdt: return pick_cohesion<N, T, CdtRolling>(c);
    case RollingModel::epsd: return pick_cohesion<N, T, EpsdRolling>(c);
    case RollingModel::none: break;
  }
  return pick_cohesion<N, T, NoRolling>(c);
}
template <class N>
SweepChoice pick_tangential(const ContactSettings& c) {
  if (c.tangential == TangentialModel::history) return pick_rolling<N, HistoryTangential>(c);
  return pick_rolling<N, NoTangential>(c);
}

}  // namespace

SweepChoice select_sweep(const ContactSettings& settings) {
  if (settings.normal == NormalModel::hooke) return pick_tangential<HookeNormal>(settings);
  return pick_tangential<HertzNormal>(settings);
}

void steps_per_contact_sweep(ContactSweep& s) {
  const Particles& p = s.p;
  const Ghosts& g = s.ghosts;
  UnresolvedContact& u = s.unresolved;
  const Vec3 zero = Vec3::Zero();
  // Pairs: the same lists, touching test and canonical ids as the force sweep.
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (int k = s.local_list.offsets[i]; k < s.local_list.offsets[i + 1]; ++k) {
      const std::size_t j = s.local_list.j[k];
      const Vec3 d = p.x[i] - p.x[j];
      const double rs = p.radius[i] + p.radius[j];
      if (apart(d, rs)) continue;
      const double dist = std::sqrt(d.squaredNorm());
      u.consider((d / dist).dot(p.v[j] - p.v[i]), p.radius[i] * p.radius[j] / rs,
                 p.mass[i] * p.mass[j] / (p.mass[i] + p.mass[j]),
                 s.table(p.material[i], p.material[j]).y_star,
                 (rs - dist) / std::min(p.radius[i], p.radius[j]), std::min(p.id[i], p.id[j]),
                 std::max(p.id[i], p.id[j]), s.dt);
    }
    for (int k = s.ghost_list.offsets[i]; k < s.ghost_list.offsets[i + 1]; ++k) {
      const std::size_t q = s.ghost_list.j[k];
      const Vec3 d = (p.x[i] - g.x[q]) + (zero - g.shift[q]);
      const double rs = p.radius[i] + g.radius[q];
      if (apart(d, rs)) continue;
      const double dist = std::sqrt(d.squaredNorm());
      u.consider((d / dist).dot(g.v[q] - p.v[i]), p.radius[i] * g.radius[q] / rs,
                 p.mass[i] * g.mass[q] / (p.mass[i] + g.mass[q]),
                 s.table(p.material[i], g.material[q]).y_star,
                 (rs - dist) / std::min(p.radius[i], g.radius[q]), std::min(p.id[i], g.id[q]),
                 std::max(p.id[i], g.id[q]), s.dt);
    }
  }
  // Walls: the approach speed relative to the wall's surface at the contact point.
  auto wall_contact = [&](std::size_t i, const WallTouch& t, int material) {
    u.consider(-(p.v[i] - t.surface_velocity).dot(t.n), p.radius[i], p.mass[i],
               s.table(p.material[i], material).y_star, t.overlap / p.radius[i], p.id[i], -1, s.dt);
  };
  for (std::size_t w = 0; w < s.walls.walls().size(); ++w) {
    const WallSet::Entry& wall = s.walls.walls()[w];
    if (wall.kind == Wall::Kind::mesh) {
      const TriangleMesh& mesh = s.walls.mesh(wall);
      const bool moving = wall.pose.moving();
      const Vec3 belt = wall.pose.direction_to_world(wall.surface_velocity);
      MeshTouch touch[TriangleMesh::kMaxTouches];
      for (std::size_t i = 0; i < p.size(); ++i) {
        const double r = p.radius[i];
        const int n = mesh.touches(moving ? wall.pose.to_body(p.x[i]) : p.x[i], r, touch);
        for (int k = 0; k < n; ++k) {
          WallTouch t;
          t.n = moving ? wall.pose.direction_to_world(touch[k].n) : touch[k].n;
          t.overlap = touch[k].overlap;
          t.surface_velocity = belt - belt.dot(t.n) * t.n;
          if (moving) t.surface_velocity += wall.pose.velocity_at(p.x[i] - (r - t.overlap) * t.n);
          wall_contact(i, t, wall.material);
        }
      }
      continue;
    }
    const WallNeighbours::List& list = s.wall_neighbours.lists[w];
    const std::size_t n = list.all ? p.size() : list.i.size();
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = list.all ? k : static_cast<std::size_t>(list.i[k]);
      WallTouch t;
      const bool touching = wall.kind == Wall::Kind::plane
                                ? touch_plane(wall.plane, p.x[i], p.radius[i], t)
                                : touch_cylinder(wall.cylinder, p.x[i], p.radius[i], t);
      if (!touching) continue;
      if (wall.pose.moving())
        t.surface_velocity += wall.pose.velocity_at(p.x[i] - (p.radius[i] - t.overlap) * t.n);
      wall_contact(i, t, wall.material);
    }
  }
}

}  // namespace grainflow
