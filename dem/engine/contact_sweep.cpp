#include "dem/engine/contact_sweep.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

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

// The overlap guard keeps the largest overlap / min(r_a, r_b) of the sweep, R. A contact
// beats R only if fl(overlap / m) > R, hence overlap > R m exactly; and with c = 1 - 2^-50,
// fl(fl(R c) m) <= R m c (1 + 2^-53)^2 < R m. So `overlap > fl(fl(R c) m)` lets through every
// contact that beats R (and a few that do not), and only those pay for the division, which
// then decides exactly as before. (Assumes R m is not subnormal: overlaps of 1e-300 m.)
class OverlapGate {
 public:
  explicit OverlapGate(double largest) { set(largest); }
  void set(double largest) { scaled_ = largest * (1 - 0x1p-50); }
  bool may_beat(double overlap, double min_radius) const { return overlap > scaled_ * min_radius; }

 private:
  double scaled_;
};

// The list entries found touching, gathered before the kernel runs on them: the apart test
// decides whether an entry is kept without a branch (three in four entries are apart, in no
// order a branch predictor could learn), and the kernel then runs over touching pairs only,
// in list order, so every force is summed in the same order as entry by entry.
struct Touching {
  int i;  // local particle
  int k;  // list entry
};
constexpr int kBatch = 64;

// h unchanged when `keep`, else +0 in every component (what setZero() writes), without a
// branch.
inline void keep_or_zero(bool keep, Vec3& h) {
  const std::uint64_t mask = -static_cast<std::uint64_t>(keep);
  for (int a = 0; a < 3; ++a)
    h[a] = std::bit_cast<double>(std::bit_cast<std::uint64_t>(h[a]) & mask);
}

template <class Law>
void local_pair_sweep(ContactSweep& s) {
  Particles& p = s.p;
  const int n = static_cast<int>(p.size());
  // The arrays' addresses, read once: through the vectors, every store of a force would
  // make the compiler load each array's address again.
  const GlobalId* id = p.id.data();
  const Vec3* x = p.x.data();
  const Vec3* v = p.v.data();
  const Vec3* w = p.omega.data();
  const double* radius = p.radius.data();
  const double* mass = p.mass.data();
  const double* inertia = p.inertia.data();
  const int* material = p.material.data();
  Vec3* force = p.force.data();
  Vec3* torque = p.torque.data();
  const int* offsets = s.local_list.offsets.data();
  const int* partner = s.local_list.j.data();
  Vec3* springs_t = Law::keeps_tangential ? s.local_springs.tangential.data() : nullptr;
  Vec3* springs_r = Law::keeps_rolling ? s.local_springs.rolling.data() : nullptr;
  Vec3 unused;
  Touching batch[kBatch];
  OverlapGate gate(s.max_overlap_ratio);
  const auto evaluate = [&](const Touching& t) __attribute__((always_inline)) {
    const int i = t.i, k = t.k, j = partner[k];
    Vec3& ht = Law::keeps_tangential ? springs_t[k] : unused;
    Vec3& hr = Law::keeps_rolling ? springs_r[k] : unused;
    const int a = id[i] < id[j] ? i : j, b = a == i ? j : i;
    double overlap;
    const ContactResult r =
        pair_force<Law>(s, x[a] - x[b], Body{v[a], w[a], radius[a], mass[a], inertia[a], material[a]},
                        Body{v[b], w[b], radius[b], mass[b], inertia[b], material[b]}, ht, hr,
                        overlap);
    force[a] += r.force;
    force[b] -= r.force;
    if constexpr (Law::needs_spin) {
      torque[a] += r.torque_i;
      torque[b] += r.torque_j;
    }
    ++s.contacts;
    // The guard's details are gathered only for a new largest overlap (rare).
    const double min_r = std::min(radius[a], radius[b]);
    if (gate.may_beat(overlap, min_r)) [[unlikely]]
      if (const double ratio = overlap / min_r; ratio > s.max_overlap_ratio) {
        s.worst.consider(ratio, s.max_overlap_ratio, id[a], id[b],
                         (x[a] - x[b]).normalized().dot(v[b] - v[a]),
                         radius[a] * radius[b] / (radius[a] + radius[b]),
                         mass[a] * mass[b] / (mass[a] + mass[b]),
                         s.table(material[a], material[b]).y_star);
        gate.set(s.max_overlap_ratio);
      }
  };
  // Fills the batch, evaluates it, fills it again from where it stopped (within a
  // particle's list if need be); one call site keeps the kernel inlined.
  int i = 0, k = n > 0 ? offsets[0] : 0;
  while (i < n) {
    int m = 0;
    for (; i < n; ++i, k = i < n ? offsets[i] : k) {
      const Vec3 xi = x[i];
      const double ri = radius[i];
      const int end = offsets[i + 1], stop = std::min(end, k + (kBatch - m));
      for (; k < stop; ++k) {
        const bool touching = !apart(xi - x[partner[k]], ri + radius[partner[k]]);
        batch[m] = {i, k};
        m += touching;
        if constexpr (Law::keeps_tangential) keep_or_zero(touching, springs_t[k]);
        if constexpr (Law::keeps_rolling) keep_or_zero(touching, springs_r[k]);
      }
      if (k < end) break;  // batch offered its last free place: evaluate, then go on with i
    }
    for (int c = 0; c < m; ++c) evaluate(batch[c]);
  }
}

template <class Law>
void ghost_pair_sweep(ContactSweep& s) {
  Particles& p = s.p;
  const Ghosts& g = s.ghosts;
  const int n = static_cast<int>(p.size());
  const GlobalId* id = p.id.data();
  const Vec3* x = p.x.data();
  const Vec3* v = p.v.data();
  const Vec3* w = p.omega.data();
  const double* radius = p.radius.data();
  const double* mass = p.mass.data();
  const double* inertia = p.inertia.data();
  const int* material = p.material.data();
  Vec3* force = p.force.data();
  Vec3* torque = p.torque.data();
  const GlobalId* g_id = g.id.data();
  const Vec3* g_x = g.x.data();
  const Vec3* g_shift = g.shift.data();
  const Vec3* g_v = g.v.data();
  const Vec3* g_w = g.omega.data();
  const double* g_radius = g.radius.data();
  const double* g_mass = g.mass.data();
  const double* g_inertia = g.inertia.data();
  const int* g_material = g.material.data();
  const int* offsets = s.ghost_list.offsets.data();
  const int* partner = s.ghost_list.j.data();
  Vec3* springs_t = Law::keeps_tangential ? s.ghost_springs.tangential.data() : nullptr;
  Vec3* springs_r = Law::keeps_rolling ? s.ghost_springs.rolling.data() : nullptr;
  Vec3 unused;
  const Vec3 zero = Vec3::Zero();
  Touching batch[kBatch];
  OverlapGate gate(s.max_overlap_ratio);
  const auto evaluate = [&](const Touching& t) __attribute__((always_inline)) {
    const int i = t.i, k = t.k, q = partner[k];
    Vec3& ht = Law::keeps_tangential ? springs_t[k] : unused;
    Vec3& hr = Law::keeps_rolling ? springs_r[k] : unused;
    const Body local{v[i], w[i], radius[i], mass[i], inertia[i], material[i]};
    const Body ghost{g_v[q], g_w[q], g_radius[q], g_mass[q], g_inertia[q], g_material[q]};
    const bool local_first = id[i] < g_id[q];
    double overlap;
    const ContactResult r = local_first
                                ? pair_force<Law>(s, (x[i] - g_x[q]) + (zero - g_shift[q]), local,
                                                  ghost, ht, hr, overlap)
                                : pair_force<Law>(s, (g_x[q] - x[i]) + (g_shift[q] - zero), ghost,
                                                  local, ht, hr, overlap);
    force[i] += local_first ? r.force : Vec3(-r.force);
    if constexpr (Law::needs_spin) torque[i] += local_first ? r.torque_i : r.torque_j;
    // Both owners see this contact; the owner of the lower id counts it.
    if (local_first) ++s.contacts;
    const double min_r = std::min(local.r, ghost.r);
    if (gate.may_beat(overlap, min_r)) [[unlikely]]
      if (const double ratio = overlap / min_r; ratio > s.max_overlap_ratio) {
        s.worst.consider(ratio, s.max_overlap_ratio, id[i], g_id[q],
                         ((x[i] - g_x[q]) - g_shift[q]).normalized().dot(ghost.v - local.v),
                         local.r * ghost.r / (local.r + ghost.r),
                         local.m * ghost.m / (local.m + ghost.m),
                         s.table(local.material, ghost.material).y_star);
        gate.set(s.max_overlap_ratio);
      }
  };
  int i = 0, k = n > 0 ? offsets[0] : 0;
  while (i < n) {
    int m = 0;
    for (; i < n; ++i, k = i < n ? offsets[i] : k) {
      const Vec3 xi = x[i];
      const double ri = radius[i];
      const int end = offsets[i + 1], stop = std::min(end, k + (kBatch - m));
      for (; k < stop; ++k) {
        const int q = partner[k];
        const bool touching = !apart((xi - g_x[q]) + (zero - g_shift[q]), ri + g_radius[q]);
        batch[m] = {i, k};
        m += touching;
        if constexpr (Law::keeps_tangential) keep_or_zero(touching, springs_t[k]);
        if constexpr (Law::keeps_rolling) keep_or_zero(touching, springs_r[k]);
      }
      if (k < end) break;
    }
    for (int c = 0; c < m; ++c) evaluate(batch[c]);
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
