#include "dem/engine/contact_sweep.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "dem/engine/canonical_order.hpp"
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

UniformPairs find_uniform_pairs(const Particles& p, const Ghosts& g) {
  UniformPairs u;
  if (p.size() == 0) return u;
  const double r = p.radius[0], m = p.mass[0];
  const int material = p.material[0];
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.radius[i] != r || p.mass[i] != m || p.material[i] != material) return u;
  for (std::size_t k = 0; k < g.size(); ++k)
    if (g.radius[k] != r || g.mass[k] != m || g.material[k] != material) return u;
  u.all_alike = true;
  u.radius = r;
  u.mass = m;
  u.material = material;
  u.r_star = r * r / (r + r);
  u.m_star = m * m / (m + m);
  return u;
}

namespace {

// The state of one body of a pair, as the pair kernel reads it: of one contact (V = double)
// or of one body of each of the contacts in the lanes of V.
// v, w at the half step (springs), vp, wp predicted at the step's end (dashpots;
// Particles::v_pred). A law without torques reads only vp.
template <class V>
struct Body {
  V3<V> v, w, vp, wp;
  V r, m, inertia;
};

// The material-pair constants a lane-capable law reads (HertzNormal, HistoryTangential), for
// the contacts in the lanes of V.
template <class V>
struct PairCoefficientLanes {
  V y_star, g_star, hertz_beta, hertz_gt_per_gn, friction;
};
template <class V, class Get>
[[gnu::always_inline]] inline PairCoefficientLanes<V> gather_coefficients(Get get) {
  return {gather<V>([&](int l) { return get(l).y_star; }),
          gather<V>([&](int l) { return get(l).g_star; }),
          gather<V>([&](int l) { return get(l).hertz_beta; }),
          gather<V>([&](int l) { return get(l).hertz_gt_per_gn; }),
          gather<V>([&](int l) { return get(l).friction; })};
}

// The lane type of the pair sweeps. Baseline x86-64 (SSE2): four pairs at a time as two SSE2
// chains side by side (Lanes2x2). Measured on the settled bed (CPU time of 1000 steps): Lanes2
// 2.93 s, Lanes2x2 2.69 s, Lanes2xK<3> 3.09 s and <4> 2.94 s (registers spill), GCC's Lanes4
// without AVX 3.46 s. With AVX (GRAINFLOW_AVX, CMakeLists.txt) four pairs in one 256-bit
// chain (Lanes4): its sixteen registers hold twice the lanes and its three-operand
// instructions need no copies, so the kernel runs 598 instead of 915 instructions per
// particle-step, 48 instead of 85 of them spills to the stack. CPU time of 700 steps on an AMD
// EPYC (Zen 4), 4 alternating rounds: Lanes2x2 2.65-2.99 s, Lanes4 2.33-2.36 s, two Lanes4
// chains side by side 2.50-2.75 s; Lanes2x2 with AVX's encoding alone 2.52-2.59 s
// (docs/performance.md).
#if defined(__AVX__)
using PairLanes = Lanes4;
#else
using PairLanes = Lanes2x2;
#endif

// Whether a listed pair is apart: the Verlet lists hold every pair within the skin, and in
// a packed bed about three in four of them do not touch. This test comes first, on the
// positions and radii alone, before anything else of the pair is loaded. It gives the same
// answer bit for bit whichever partner comes first (a negated difference has the same
// squares; + is commutative), so it is asked before the pair is put in canonical order.
inline bool apart(const Vec3& d, double rs) { return d.squaredNorm() >= rs * rs; }

// Evaluates the touching pair (a, b) with displacement d = x_a - x_b, or the pairs in the
// lanes of V. Inlined into the sweeps, like the law's evaluation: the geometry and the result
// then stay in registers instead of going through memory.
// R* and m* are the caller's: r_a r_b / (r_a + r_b) and m_a m_b / (m_a + m_b) (reduced_radius,
// reduced_mass), or those of UniformPairs.
template <class V>
[[gnu::always_inline]] inline V reduced_radius(const Body<V>& a, const Body<V>& b) {
  return a.r * b.r / (a.r + b.r);
}
template <class V>
[[gnu::always_inline]] inline V reduced_mass(const Body<V>& a, const Body<V>& b) {
  return a.m * b.m / (a.m + b.m);
}
// The geometry the law sees for the touching pair (a, b) with displacement d = x_a - x_b.
template <class Law, class V>
[[gnu::always_inline]] inline ContactGeometryT<V> pair_geometry(const V3<V>& d, const Body<V>& a,
                                                                const Body<V>& b, V r_star,
                                                                V m_star, V& overlap) {
  const V rs = a.r + b.r;
  const V dist = lane_sqrt(squared_norm(d));
  ContactGeometryT<V> g;
  g.n = d * (1.0 / dist);  // one division, not three (rounding differs in the last bit)
  g.overlap = overlap = rs - dist;
  g.distance = dist;
  g.r_i = a.r;
  g.r_j = b.r;
  g.arm_i = a.r - 0.5 * g.overlap;
  g.arm_j = b.r - 0.5 * g.overlap;
  g.r_star = r_star;
  g.m_star = m_star;
  g.wall = false;
  if constexpr (Law::needs_spin) {
    // Evaluated first: GCC does not inline Eigen's cross product of an expression.
    const V3<V> arm_w = g.arm_i * a.w + g.arm_j * b.w;
    // Stored from the values, not copied field to field: GCC copies g.v_rel into g.v_pred
    // through 8-byte pieces and 16-byte stores, which the kernel then loads 32 bytes at a
    // time, a load the store buffer cannot serve (perf: 6 % of the pair sweep's time).
    const V3<V> v_rel = a.v - b.v - cross(arm_w, g.n), w_rel = a.w - b.w;
    g.v_rel = v_rel;
    g.w_rel = w_rel;
    if constexpr (Law::predicted_dashpot) {
      const V3<V> arm_wp = g.arm_i * a.wp + g.arm_j * b.wp;
      g.v_pred = a.vp - b.vp - cross(arm_wp, g.n);
      g.w_pred = a.wp - b.wp;
    } else {
      g.v_pred = v_rel;
      g.w_pred = w_rel;
    }
  } else if constexpr (Law::predicted_dashpot) {  // no spring: the normal dashpot's two
    g.v_rel = a.v - b.v;
    g.v_pred = a.vp - b.vp;
  } else {
    g.v_pred = a.v - b.v;
  }
  if constexpr (Law::needs_roll_inertia)
    g.roll_inertia =
        1.0 / (1.0 / (a.inertia + a.m * a.r * a.r) + 1.0 / (b.inertia + b.m * b.r * b.r));
  return g;
}
template <class Law, class V, class PC>
[[gnu::always_inline]] inline ContactResultT<V> pair_force(const ContactSweep& s, const V3<V>& d,
                                                           const Body<V>& a, const Body<V>& b,
                                                           V r_star, V m_star, const PC& pc,
                                                           V3<V>& tangential, V3<V>& rolling,
                                                           V& overlap) {
  const ContactGeometryT<V> g = pair_geometry<Law>(d, a, b, r_star, m_star, overlap);
  return Law::evaluate(g, pc, s.constants, tangential, rolling, s.dt, s.spring_dt);
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
void local_pair_sweep(ContactSweep& s, int a_first, int a_end) {
  Particles& p = s.p;
  const int n = static_cast<int>(p.size());
  // The arrays' addresses, read once: through the vectors, every store of a force would
  // make the compiler load each array's address again.
  const GlobalId* id = p.id.data();
  const Vec3* x = p.x.data();
  const Vec3* v = p.v.data();
  const Vec3* w = p.omega.data();
  const Vec3* vp = p.v_pred.data();
  const Vec3* wp = p.omega_pred.data();
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
  Touching batch[kBatch];
  OverlapGate gate(s.max_overlap_ratio);
  // A touching entry in canonical orientation: a has the lower global id.
  struct Pair {
    int a, b, k;
  };
  const auto canonical = [&](const Touching& t) {
    const int j = partner[t.k];
    const int first = id[t.i] < id[j] ? t.i : j;
    return Pair{first, first == t.i ? j : t.i, t.k};
  };
  const auto body = [&](int q) {
    return Body<double>{v[q], w[q], vp[q], wp[q], radius[q], mass[q], inertia[q]};
  };
  // The contact's forces and torques on both bodies, its count and the overlap guard.
  const auto apply = [&](const Pair& c, const ContactResult& r, double overlap) {
    force[c.a] += r.force;
    force[c.b] -= r.force;
    if constexpr (Law::needs_spin) {
      torque[c.a] += r.torque_i;
      torque[c.b] += r.torque_j;
    }
    ++s.contacts;
    // The guard's details are gathered only for a new largest overlap (rare).
    const double min_r = std::min(radius[c.a], radius[c.b]);
    if (gate.may_beat(overlap, min_r)) [[unlikely]]
      if (const double ratio = overlap / min_r; ratio > s.max_overlap_ratio) {
        s.worst.consider(ratio, s.max_overlap_ratio, id[c.a], id[c.b],
                         (x[c.a] - x[c.b]).normalized().dot(v[c.b] - v[c.a]),
                         radius[c.a] * radius[c.b] / (radius[c.a] + radius[c.b]),
                         mass[c.a] * mass[c.b] / (mass[c.a] + mass[c.b]),
                         s.table(material[c.a], material[c.b]).y_star);
        gate.set(s.max_overlap_ratio);
      }
  };
  // The touching entries batch[0, m), in order: W at a time in the lanes of PairLanes when the
  // law can (the last group filled up with copies of the last entry, whose results are
  // discarded), else one by one. With UniformPairs, radii, masses, R*, m* and the material pair
  // are the same for all.
  const UniformPairs& u = s.uniform;
  using V = PairLanes;
  constexpr int W = lane_count<V>;
  const PairCoefficientLanes<V> uniform_pc =
      u.all_alike ? gather_coefficients<V>([&](int) -> const PairCoefficients& {
        return s.table(u.material, u.material);
      })
                  : PairCoefficientLanes<V>{};
  const auto lanes = [&]<bool Alike>(int m) __attribute__((always_inline)) {
    for (int c = 0; c < m; c += W) {
      Pair group[W];
#pragma GCC unroll 4
      for (int l = 0; l < W; ++l) group[l] = canonical(batch[std::min(c + l, m - 1)]);
      Body<V> a, b;
      if constexpr (Law::predicted_dashpot) {
        a.vp = gather3<V>([&](int l) -> const Vec3& { return vp[group[l].a]; });
        b.vp = gather3<V>([&](int l) -> const Vec3& { return vp[group[l].b]; });
      }
      {  // the half-step velocities: springs, and the cell dashpot's drift (predicted)
        a.v = gather3<V>([&](int l) -> const Vec3& { return v[group[l].a]; });
        b.v = gather3<V>([&](int l) -> const Vec3& { return v[group[l].b]; });
      }
      if constexpr (Law::needs_spin) {
        a.w = gather3<V>([&](int l) -> const Vec3& { return w[group[l].a]; });
        b.w = gather3<V>([&](int l) -> const Vec3& { return w[group[l].b]; });
      }
      if constexpr (Law::needs_spin && Law::predicted_dashpot) {
        a.wp = gather3<V>([&](int l) -> const Vec3& { return wp[group[l].a]; });
        b.wp = gather3<V>([&](int l) -> const Vec3& { return wp[group[l].b]; });
      }
      V r_star, m_star;
      PairCoefficientLanes<V> pc;
      if constexpr (Alike) {
        a.r = b.r = broadcast<V>(u.radius);
        a.m = b.m = broadcast<V>(u.mass);
        r_star = broadcast<V>(u.r_star);
        m_star = broadcast<V>(u.m_star);
        pc = uniform_pc;
      } else {
        a.r = gather<V>([&](int l) { return radius[group[l].a]; });
        a.m = gather<V>([&](int l) { return mass[group[l].a]; });
        b.r = gather<V>([&](int l) { return radius[group[l].b]; });
        b.m = gather<V>([&](int l) { return mass[group[l].b]; });
        r_star = reduced_radius(a, b);
        m_star = reduced_mass(a, b);
        pc = gather_coefficients<V>([&](int l) -> const PairCoefficients& {
          return s.table(material[group[l].a], material[group[l].b]);
        });
      }
      V3<V> ht = zero3<V>(), hr = zero3<V>();
      if constexpr (Law::keeps_tangential)
        ht = gather3<V>([&](int l) -> const Vec3& { return springs_t[group[l].k]; });
      V overlap;
      const ContactResultT<V> r =
          pair_force<Law>(s, gather3<V>([&](int l) { return Vec3(x[group[l].a] - x[group[l].b]); }),
                          a, b, r_star, m_star, pc, ht, hr, overlap);
#pragma GCC unroll 4
      for (int l = 0; l < W; ++l) {
        if (c + l == m) break;
        if constexpr (Law::keeps_tangential) springs_t[group[l].k] = lane(ht, l);
        apply(group[l], ContactResult{lane(r.force, l), lane(r.torque_i, l), lane(r.torque_j, l)},
              overlap[l]);
      }
    }
  };
  const auto evaluate = [&](int m) __attribute__((always_inline)) {
    if constexpr (Law::lanes) {
      if (u.all_alike)
        lanes.template operator()<true>(m);
      else
        lanes.template operator()<false>(m);
    } else {
      Vec3 unused;
      for (int c = 0; c < m; ++c) {
        const Pair p0 = canonical(batch[c]);
        Vec3& ht = Law::keeps_tangential ? springs_t[p0.k] : unused;
        Vec3& hr = Law::keeps_rolling ? springs_r[p0.k] : unused;
        const Body<double> a = body(p0.a), b = body(p0.b);
        double overlap;
        const ContactResult r = pair_force<Law>(
            s, Vec3(x[p0.a] - x[p0.b]), a, b, reduced_radius(a, b), reduced_mass(a, b),
            s.table(material[p0.a], material[p0.b]), ht, hr, overlap);
        apply(p0, r, overlap);
      }
    }
  };
  // Over all entries in one loop (NeighbourList::owner), kBatch at a time: the touching ones
  // of each group are evaluated before the next group is tested; one call site keeps the
  // kernel inlined.
  const int* owner = s.local_list.owner.data();
  const int entries = n > 0 ? offsets[a_end] : 0;
  // Beyond the last-level cache (a rank holding more than kPrefetchAbove particles), the
  // entry test asks for the partner's position, velocities, force and torque (those the law
  // reads) and for the springs kAhead entries (about 23 particles) before the sweep reaches them:
  // the partners above a particle lie one layer of bins ahead in memory, a stream among a dozen
  // that the hardware prefetchers do not follow. The bed of 10^6 spheres (benchmarks/million, 1
  // rank) ran 1.10x faster with it (8.25e6 -> 9.05e6 particle-steps/s), one of 307 200 1.10x and
  // one of 92 160 1.05x; the 30 720-sphere bed, in cache, 0.93x: below the threshold the
  // test is made once per entry and never passes.
  constexpr int kAhead = 96;
  constexpr int kPrefetchAbove = 50000;
  const int prefetch_end = n > kPrefetchAbove ? entries - kAhead : 0;
  for (int k = n > 0 ? offsets[a_first] : 0; k < entries;) {
    int m = 0;
    for (const int stop = std::min(entries, k + kBatch); k < stop; ++k) {
      if (k < prefetch_end) {  // the partner and spring of the entry kAhead on
        const int q = partner[k + kAhead];
        __builtin_prefetch(&x[q]);
        __builtin_prefetch(&v[q]);
        __builtin_prefetch(&force[q], 1);
        if constexpr (Law::needs_spin) {
          __builtin_prefetch(&w[q]);
          __builtin_prefetch(&torque[q], 1);
        }
        if constexpr (Law::predicted_dashpot) {
          __builtin_prefetch(&vp[q]);
          if constexpr (Law::needs_spin) __builtin_prefetch(&wp[q]);
        }
        if constexpr (Law::keeps_tangential) __builtin_prefetch(&springs_t[k + kAhead], 1);
        if constexpr (Law::keeps_rolling) __builtin_prefetch(&springs_r[k + kAhead], 1);
      }
      const int i = owner[k], j = partner[k];
      const bool touching = !apart(x[i] - x[j], radius[i] + radius[j]);
      batch[m] = {i, k};
      m += touching;
      if constexpr (Law::keeps_tangential) keep_or_zero(touching, springs_t[k]);
      if constexpr (Law::keeps_rolling) keep_or_zero(touching, springs_r[k]);
    }
    evaluate(m);
  }
}

}  // namespace

template <class Law>
void apply_wall_contacts(ContactSweep& s, int material, const WallHit* hits, int m,
                         std::vector<ContactHistory>& history) {
  Particles& p = s.p;
  if constexpr (!Law::lanes) {
    ContactHistory unused;
    for (int c = 0; c < m; ++c)
      apply_wall_contact<Law>(s, hits[c].i, hits[c].t, material,
                              Law::has_history ? history[hits[c].k] : unused);
  } else {
    // W contacts at a time in the lanes of the pair kernel (the last group filled up with
    // copies of the last contact, whose results are discarded), with the geometry of
    // wall_geometry() lane by lane: the same operations, so the same bits.
    using V = PairLanes;
    constexpr int W = lane_count<V>;
    static_assert(!Law::needs_roll_inertia && !Law::keeps_rolling);
    const Vec3* v = p.v.data();
    const Vec3* w = p.omega.data();
    const Vec3* vp = p.v_pred.data();
    const Vec3* wp = p.omega_pred.data();
    const double* radius = p.radius.data();
    const double* mass = p.mass.data();
    const int* material_of = p.material.data();
    Vec3* force = p.force.data();
    Vec3* torque = p.torque.data();
    for (int c = 0; c < m; c += W) {
      const WallHit* h[W];
#pragma GCC unroll 4
      for (int l = 0; l < W; ++l) h[l] = &hits[std::min(c + l, m - 1)];
      ContactGeometryT<V> g;
      g.n = gather3<V>([&](int l) -> const Vec3& { return h[l]->t.n; });
      g.overlap = gather<V>([&](int l) { return h[l]->t.overlap; });
      const V r = gather<V>([&](int l) { return radius[h[l]->i]; });
      g.distance = r - g.overlap;
      g.r_i = r;
      g.r_j = V{};
      g.arm_i = g.distance;
      g.arm_j = V{};
      g.r_star = r;
      g.m_star = gather<V>([&](int l) { return mass[h[l]->i]; });
      g.wall = true;
      const V3<V> wall_v =
          gather3<V>([&](int l) -> const Vec3& { return h[l]->t.surface_velocity; });
      const V3<V> vi = gather3<V>([&](int l) -> const Vec3& { return v[h[l]->i]; });
      if constexpr (Law::needs_spin) {
        const V3<V> wi = gather3<V>([&](int l) -> const Vec3& { return w[h[l]->i]; });
        const V3<V> v_rel = vi - wall_v - g.arm_i * cross(wi, g.n);  // as in pair_geometry
        g.v_rel = v_rel;
        // The rolling models see the spin relative to the wall's (wall_geometry).
        const V3<V> wall_w = gather3<V>([&](int l) -> const Vec3& { return h[l]->t.spin; });
        g.w_rel = wi - wall_w;
        if constexpr (Law::predicted_dashpot) {
          const V3<V> wpi = gather3<V>([&](int l) -> const Vec3& { return wp[h[l]->i]; });
          g.v_pred = gather3<V>([&](int l) -> const Vec3& { return vp[h[l]->i]; }) - wall_v -
                     g.arm_i * cross(wpi, g.n);
          g.w_pred = wpi - wall_w;
        } else {
          g.v_pred = v_rel;
          g.w_pred = g.w_rel;
        }
      } else if constexpr (Law::predicted_dashpot) {
        g.v_rel = vi - wall_v;
        g.v_pred = gather3<V>([&](int l) -> const Vec3& { return vp[h[l]->i]; }) - wall_v;
      } else {
        g.v_pred = vi - wall_v;
      }
      const PairCoefficientLanes<V> pc =
          gather_coefficients<V>([&](int l) -> const PairCoefficients& {
            return s.table(material_of[h[l]->i], material);
          });
      V3<V> ht = zero3<V>(), hr = zero3<V>();
      if constexpr (Law::keeps_tangential)
        ht = gather3<V>([&](int l) -> const Vec3& { return history[h[l]->k].tangential; });
      const ContactResultT<V> res = Law::evaluate(g, pc, s.constants, ht, hr, s.dt, s.spring_dt);
#pragma GCC unroll 4
      for (int l = 0; l < W; ++l) {
        if (c + l == m) break;
        const int i = h[l]->i;
        if constexpr (Law::keeps_tangential) history[h[l]->k].tangential = lane(ht, l);
        force[i] += lane(res.force, l);
        if constexpr (Law::needs_spin) torque[i] += lane(res.torque_i, l);
        if (s.load) *s.load += lane(res.force, l);
        ++s.contacts;
        if (const double ratio = g.overlap[l] / radius[i]; ratio > s.max_overlap_ratio)
          s.worst.consider(ratio, s.max_overlap_ratio, p.id[i], -1,
                           -lane(g.v_pred, l).dot(lane(g.n, l)), g.r_star[l], g.m_star[l],
                           s.table(material_of[i], material).y_star);
      }
    }
  }
}

namespace {

template <class Law>
void ghost_pair_sweep(ContactSweep& s, int a_first, int a_end) {
  Particles& p = s.p;
  const Ghosts& g = s.ghosts;
  const int n = static_cast<int>(p.size());
  const GlobalId* id = p.id.data();
  const Vec3* x = p.x.data();
  const Vec3* v = p.v.data();
  const Vec3* w = p.omega.data();
  const Vec3* vp = p.v_pred.data();
  const Vec3* wp = p.omega_pred.data();
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
  const Vec3* g_vp = g.v_pred.data();
  const Vec3* g_wp = g.omega_pred.data();
  const double* g_radius = g.radius.data();
  const double* g_mass = g.mass.data();
  const double* g_inertia = g.inertia.data();
  const int* g_material = g.material.data();
  const int* offsets = s.ghost_list.offsets.data();
  const int* partner = s.ghost_list.j.data();
  Vec3* springs_t = Law::keeps_tangential ? s.ghost_springs.tangential.data() : nullptr;
  Vec3* springs_r = Law::keeps_rolling ? s.ghost_springs.rolling.data() : nullptr;
  const Vec3 zero = Vec3::Zero();
  Touching batch[kBatch];
  OverlapGate gate(s.max_overlap_ratio);
  // A touching entry in canonical orientation (the lower global id first) and the two bodies'
  // displacement. The bodies' fields are read where they are, the local particle's or the
  // ghost's, by the orientation (copying both bodies into the entry and gathering from the
  // copies made this sweep take a third longer).
  struct Pair {
    int i, q, k;
    bool local_first;
    Vec3 d;
  };
  const auto canonical = [&](const Touching& t) {
    const int i = t.i, q = partner[t.k];
    const bool local_first = id[i] < g_id[q];
    return local_first ? Pair{i, q, t.k, true, (x[i] - g_x[q]) + (zero - g_shift[q])}
                       : Pair{i, q, t.k, false, (g_x[q] - x[i]) + (g_shift[q] - zero)};
  };
  // The field of the pair's first (lower id) or second body.
  const auto first = [](const Pair& c, const auto* local, const auto* ghost) -> const auto& {
    return c.local_first ? local[c.i] : ghost[c.q];
  };
  const auto second = [](const Pair& c, const auto* local, const auto* ghost) -> const auto& {
    return c.local_first ? ghost[c.q] : local[c.i];
  };
  const auto body = [&](const Pair& c, bool is_first) {
    const bool local = is_first == c.local_first;
    const int i = c.i, q = c.q;
    return local ? Body<double>{v[i], w[i], vp[i], wp[i], radius[i], mass[i], inertia[i]}
                 : Body<double>{g_v[q],      g_w[q],    g_vp[q],     g_wp[q],
                                g_radius[q], g_mass[q], g_inertia[q]};
  };
  const auto table = [&](const Pair& c) -> const PairCoefficients& {
    return c.local_first ? s.table(material[c.i], g_material[c.q])
                         : s.table(g_material[c.q], material[c.i]);
  };
  const auto apply = [&](const Pair& c, const ContactResult& r, double overlap) {
    const int i = c.i, q = c.q;
    force[i] += c.local_first ? r.force : Vec3(-r.force);
    if constexpr (Law::needs_spin) torque[i] += c.local_first ? r.torque_i : r.torque_j;
    // Both owners see this contact; the owner of the lower id counts it.
    if (c.local_first) ++s.contacts;
    const double min_r = std::min(radius[i], g_radius[q]);
    if (gate.may_beat(overlap, min_r)) [[unlikely]]
      if (const double ratio = overlap / min_r; ratio > s.max_overlap_ratio) {
        s.worst.consider(ratio, s.max_overlap_ratio, id[i], g_id[q],
                         ((x[i] - g_x[q]) - g_shift[q]).normalized().dot(g_v[q] - v[i]),
                         radius[i] * g_radius[q] / (radius[i] + g_radius[q]),
                         mass[i] * g_mass[q] / (mass[i] + g_mass[q]),
                         s.table(material[i], g_material[q]).y_star);
        gate.set(s.max_overlap_ratio);
      }
  };
  using V = PairLanes;
  constexpr int W = lane_count<V>;
  const auto evaluate = [&](int m) __attribute__((always_inline)) {
    if constexpr (Law::lanes) {
      for (int c = 0; c < m; c += W) {
        Pair group[W];
#pragma GCC unroll 4
        for (int l = 0; l < W; ++l) group[l] = canonical(batch[std::min(c + l, m - 1)]);
        Body<V> a, b;
        if constexpr (Law::predicted_dashpot) {
          a.vp = gather3<V>([&](int l) -> const Vec3& { return first(group[l], vp, g_vp); });
          b.vp = gather3<V>([&](int l) -> const Vec3& { return second(group[l], vp, g_vp); });
        }
        {  // the half-step velocities: springs, and the cell dashpot's drift (predicted)
          a.v = gather3<V>([&](int l) -> const Vec3& { return first(group[l], v, g_v); });
          b.v = gather3<V>([&](int l) -> const Vec3& { return second(group[l], v, g_v); });
        }
        if constexpr (Law::needs_spin) {
          a.w = gather3<V>([&](int l) -> const Vec3& { return first(group[l], w, g_w); });
          b.w = gather3<V>([&](int l) -> const Vec3& { return second(group[l], w, g_w); });
        }
        if constexpr (Law::needs_spin && Law::predicted_dashpot) {
          a.wp = gather3<V>([&](int l) -> const Vec3& { return first(group[l], wp, g_wp); });
          b.wp = gather3<V>([&](int l) -> const Vec3& { return second(group[l], wp, g_wp); });
        }
        a.r = gather<V>([&](int l) { return first(group[l], radius, g_radius); });
        a.m = gather<V>([&](int l) { return first(group[l], mass, g_mass); });
        b.r = gather<V>([&](int l) { return second(group[l], radius, g_radius); });
        b.m = gather<V>([&](int l) { return second(group[l], mass, g_mass); });
        const PairCoefficientLanes<V> pc = gather_coefficients<V>(
            [&](int l) -> const PairCoefficients& { return table(group[l]); });
        V3<V> ht = zero3<V>(), hr = zero3<V>();
        if constexpr (Law::keeps_tangential)
          ht = gather3<V>([&](int l) -> const Vec3& { return springs_t[group[l].k]; });
        V overlap;
        const ContactResultT<V> r =
            pair_force<Law>(s, gather3<V>([&](int l) -> const Vec3& { return group[l].d; }), a, b,
                            reduced_radius(a, b), reduced_mass(a, b), pc, ht, hr, overlap);
#pragma GCC unroll 4
        for (int l = 0; l < W; ++l) {
          if (c + l == m) break;
          if constexpr (Law::keeps_tangential) springs_t[group[l].k] = lane(ht, l);
          apply(group[l], ContactResult{lane(r.force, l), lane(r.torque_i, l), lane(r.torque_j, l)},
                overlap[l]);
        }
      }
    } else {
      Vec3 unused;
      for (int c = 0; c < m; ++c) {
        const Pair p0 = canonical(batch[c]);
        Vec3& ht = Law::keeps_tangential ? springs_t[p0.k] : unused;
        Vec3& hr = Law::keeps_rolling ? springs_r[p0.k] : unused;
        const Body<double> a = body(p0, true), b = body(p0, false);
        double overlap;
        const ContactResult r = pair_force<Law>(s, p0.d, a, b, reduced_radius(a, b),
                                                reduced_mass(a, b), table(p0), ht, hr, overlap);
        apply(p0, r, overlap);
      }
    }
  };
  const int* owner = s.ghost_list.owner.data();
  const int entries = n > 0 ? offsets[a_end] : 0;
  for (int k = n > 0 ? offsets[a_first] : 0; k < entries;) {
    int m = 0;
    for (const int stop = std::min(entries, k + kBatch); k < stop; ++k) {
      const int i = owner[k], q = partner[k];
      const bool touching = !apart((x[i] - g_x[q]) + (zero - g_shift[q]), radius[i] + g_radius[q]);
      batch[m] = {i, k};
      m += touching;
      if constexpr (Law::keeps_tangential) keep_or_zero(touching, springs_t[k]);
      if constexpr (Law::keeps_rolling) keep_or_zero(touching, springs_r[k]);
    }
    evaluate(m);
  }
}

// parallel.reproducible: the local and ghost pairs in the order of s.canonical
// (canonical_order.hpp), each touching pair's force and torques added to both its particles
// at once, in that order (a ghost's share goes to a sink). The pair force is the kernel of
// the other sweeps, in the same lanes: a contact's result has the same bits in any lane.
template <class Law>
void canonical_pair_sweep(ContactSweep& s) {
  Particles& p = s.p;
  const Ghosts& g = s.ghosts;
  CanonicalOrder& order = *s.canonical;
  // Where a body's state is read and its share added: the local particles' arrays, or the
  // ghosts' with the sinks.
  struct Source {
    const GlobalId* id;
    const Vec3 *v, *w;
    const Vec3 *vp, *wp;  // the dashpots' predicted velocities (Law::predicted_dashpot)
    const double *radius, *mass, *inertia;
    const int* material;
    Vec3 *force, *torque;
  };
  order.ghost_force.assign(g.size(), Vec3::Zero());
  order.ghost_torque.assign(g.size(), Vec3::Zero());
  const Source L{p.id.data(),        p.v.data(),          p.omega.data(),
                 p.v_pred.data(),    p.omega_pred.data(), p.radius.data(),
                 p.mass.data(),      p.inertia.data(),    p.material.data(),
                 p.force.data(),     p.torque.data()};
  const Source G{g.id.data(),          g.v.data(),          g.omega.data(),
                 g.v_pred.data(),      g.omega_pred.data(), g.radius.data(),
                 g.mass.data(),        g.inertia.data(),    g.material.data(),
                 order.ghost_force.data(), order.ghost_torque.data()};
  const Vec3* x = p.x.data();
  const Vec3* g_x = g.x.data();
  const Vec3* g_shift = g.shift.data();
  const int* l_owner = s.local_list.owner.data();
  const int* l_partner = s.local_list.j.data();
  const int* g_owner = s.ghost_list.owner.data();
  const int* g_partner = s.ghost_list.j.data();
  Vec3* l_springs_t = Law::keeps_tangential ? s.local_springs.tangential.data() : nullptr;
  Vec3* l_springs_r = Law::keeps_rolling ? s.local_springs.rolling.data() : nullptr;
  Vec3* g_springs_t = Law::keeps_tangential ? s.ghost_springs.tangential.data() : nullptr;
  Vec3* g_springs_r = Law::keeps_rolling ? s.ghost_springs.rolling.data() : nullptr;
  const Vec3 zero = Vec3::Zero();
  OverlapGate gate(s.max_overlap_ratio);
  // A touching entry: k >= 0 the local-list entry k of the local particle i, k < 0 the
  // ghost-list entry ~k.
  Touching batch[2 * kBatch];
  // Its two bodies in canonical orientation (the lower global id first), their
  // displacement (x_a - x_b) + (shift_a - shift_b) and its springs.
  struct Pair {
    const Source* a;
    int ia;
    const Source* b;
    int ib;
    Vec3 d;
    Vec3 *spring_t, *spring_r;
    bool counts;  // a contact with a ghost is counted by the owner of the lower id
  };
  const auto canonical_local = [&](const Touching& t) __attribute__((always_inline)) {
    const int i = t.i, j = l_partner[t.k];
    const int a = L.id[i] < L.id[j] ? i : j, b = a == i ? j : i;
    return Pair{&L,
                a,
                &L,
                b,
                Vec3(x[a] - x[b]),
                Law::keeps_tangential ? l_springs_t + t.k : nullptr,
                Law::keeps_rolling ? l_springs_r + t.k : nullptr,
                true};
  };
  const auto canonical = [&](const Touching& t) __attribute__((always_inline)) {
    if (t.k >= 0) return canonical_local(t);
    const int i = t.i, e = ~t.k, q = g_partner[e];
    Vec3* st = Law::keeps_tangential ? g_springs_t + e : nullptr;
    Vec3* sr = Law::keeps_rolling ? g_springs_r + e : nullptr;
    return L.id[i] < G.id[q]
               ? Pair{&L, i, &G, q, (x[i] - g_x[q]) + (zero - g_shift[q]), st, sr, true}
               : Pair{&G, q, &L, i, (g_x[q] - x[i]) + (g_shift[q] - zero), st, sr, false};
  };
  const auto body = [](const Source* src, int k) {
    if constexpr (Law::predicted_dashpot)
      return Body<double>{src->v[k],      src->w[k],    src->vp[k],       src->wp[k],
                          src->radius[k], src->mass[k], src->inertia[k]};
    else
      return Body<double>{src->v[k],      src->w[k],    Vec3::Zero(),     Vec3::Zero(),
                          src->radius[k], src->mass[k], src->inertia[k]};
  };
  const auto table = [&](const Pair& c) -> const PairCoefficients& {
    return s.table(c.a->material[c.ia], c.b->material[c.ib]);
  };
  // Local: both bodies are local particles (c.a == c.b == &L, known to the compiler).
  const auto apply = [&]<bool Local>(const Pair& c, const ContactResult& r, double overlap) {
    const Source& A = Local ? L : *c.a;
    const Source& B = Local ? L : *c.b;
    A.force[c.ia] += r.force;
    B.force[c.ib] -= r.force;
    if constexpr (Law::needs_spin) {
      A.torque[c.ia] += r.torque_i;
      B.torque[c.ib] += r.torque_j;
    }
    s.contacts += Local || c.counts;
    const double ra = A.radius[c.ia], rb = B.radius[c.ib];
    const double min_r = std::min(ra, rb);
    if (gate.may_beat(overlap, min_r)) [[unlikely]]
      if (const double ratio = overlap / min_r; ratio > s.max_overlap_ratio) {
        const double ma = c.a->mass[c.ia], mb = c.b->mass[c.ib];
        s.worst.consider(ratio, s.max_overlap_ratio, c.a->id[c.ia], c.b->id[c.ib],
                         c.d.normalized().dot(c.b->v[c.ib] - c.a->v[c.ia]), ra * rb / (ra + rb),
                         ma * mb / (ma + mb), table(c).y_star);
        gate.set(s.max_overlap_ratio);
      }
  };
  const UniformPairs& u = s.uniform;
  using V = PairLanes;
  constexpr int W = lane_count<V>;
  const PairCoefficientLanes<V> uniform_pc =
      u.all_alike ? gather_coefficients<V>([&](int) -> const PairCoefficients& {
        return s.table(u.material, u.material);
      })
                  : PairCoefficientLanes<V>{};
  // The W touching entries from batch[c] (the last one repeated to fill the group; its
  // results are discarded). Local: all of them local pairs.
  const auto group_lanes = [&]<bool Alike, bool Local>(int c, int m)
                               __attribute__((always_inline)) {
    Pair group[W];
#pragma GCC unroll 4
    for (int l = 0; l < W; ++l) {
      const Touching& t = batch[std::min(c + l, m - 1)];
      group[l] = Local ? canonical_local(t) : canonical(t);
    }
    const auto A = [&](int l) -> const Source& { return Local ? L : *group[l].a; };
    const auto B = [&](int l) -> const Source& { return Local ? L : *group[l].b; };
    {
      Body<V> a, b;
      a.v = gather3<V>([&](int l) -> const Vec3& { return A(l).v[group[l].ia]; });
      a.w = gather3<V>([&](int l) -> const Vec3& { return A(l).w[group[l].ia]; });
      b.v = gather3<V>([&](int l) -> const Vec3& { return B(l).v[group[l].ib]; });
      b.w = gather3<V>([&](int l) -> const Vec3& { return B(l).w[group[l].ib]; });
      if constexpr (Law::predicted_dashpot) {
        a.vp = gather3<V>([&](int l) -> const Vec3& { return A(l).vp[group[l].ia]; });
        b.vp = gather3<V>([&](int l) -> const Vec3& { return B(l).vp[group[l].ib]; });
        a.wp = gather3<V>([&](int l) -> const Vec3& { return A(l).wp[group[l].ia]; });
        b.wp = gather3<V>([&](int l) -> const Vec3& { return B(l).wp[group[l].ib]; });
      }
      V r_star, m_star;
      PairCoefficientLanes<V> pc;
      if constexpr (Alike) {
        a.r = b.r = broadcast<V>(u.radius);
        a.m = b.m = broadcast<V>(u.mass);
        r_star = broadcast<V>(u.r_star);
        m_star = broadcast<V>(u.m_star);
        pc = uniform_pc;
      } else {
        a.r = gather<V>([&](int l) { return A(l).radius[group[l].ia]; });
        a.m = gather<V>([&](int l) { return A(l).mass[group[l].ia]; });
        b.r = gather<V>([&](int l) { return B(l).radius[group[l].ib]; });
        b.m = gather<V>([&](int l) { return B(l).mass[group[l].ib]; });
        r_star = reduced_radius(a, b);
        m_star = reduced_mass(a, b);
        pc = gather_coefficients<V>(
            [&](int l) -> const PairCoefficients& { return table(group[l]); });
      }
      V3<V> ht = zero3<V>(), hr = zero3<V>();
      if constexpr (Law::keeps_tangential)
        ht = gather3<V>([&](int l) -> const Vec3& { return *group[l].spring_t; });
      V overlap;
      const ContactResultT<V> r =
          pair_force<Law>(s, gather3<V>([&](int l) -> const Vec3& { return group[l].d; }), a, b,
                          r_star, m_star, pc, ht, hr, overlap);
#pragma GCC unroll 4
      for (int l = 0; l < W; ++l) {
        if (c + l == m) break;
        if constexpr (Law::keeps_tangential) *group[l].spring_t = lane(ht, l);
        apply.template operator()<Local>(
            group[l], ContactResult{lane(r.force, l), lane(r.torque_i, l), lane(r.torque_j, l)},
            overlap[l]);
      }
    }
  };
  const auto lanes = [&]<bool Alike>(int m) __attribute__((always_inline)) {
    for (int c = 0; c < m; c += W) {
      bool local = true;
#pragma GCC unroll 4
      for (int l = 0; l < W; ++l) local &= batch[std::min(c + l, m - 1)].k >= 0;
      if (local)
        group_lanes.template operator()<Alike, true>(c, m);
      else
        group_lanes.template operator()<Alike, false>(c, m);
    }
  };
  const auto evaluate = [&](int m) __attribute__((always_inline)) {
    if constexpr (Law::lanes) {
      if (u.all_alike)
        lanes.template operator()<true>(m);
      else
        lanes.template operator()<false>(m);
    } else {
      Vec3 unused;
      for (int c = 0; c < m; ++c) {
        const Pair p0 = canonical(batch[c]);
        Vec3& ht = Law::keeps_tangential ? *p0.spring_t : unused;
        Vec3& hr = Law::keeps_rolling ? *p0.spring_r : unused;
        const Body<double> a = body(p0.a, p0.ia), b = body(p0.b, p0.ib);
        double overlap;
        const ContactResult r = pair_force<Law>(s, p0.d, a, b, reduced_radius(a, b),
                                                reduced_mass(a, b), table(p0), ht, hr, overlap);
        apply.template operator()<false>(p0, r, overlap);
      }
    }
  };
  // The entries of each run, kBatch at a time: the touching ones are gathered (without a
  // branch) and evaluated, in order, once kBatch of them have come together.
  int m = 0;
  const auto flush = [&](int least) __attribute__((always_inline)) {
    if (m >= least) {
      evaluate(m);
      m = 0;
    }
  };
  int k = 0, t = 0;
  for (const CanonicalOrder::Run& run : order.runs) {
    while (k < run.local_end) {
      for (const int stop = std::min(run.local_end, k + kBatch); k < stop; ++k) {
        const int i = l_owner[k], j = l_partner[k];
        const bool touching = !apart(x[i] - x[j], L.radius[i] + L.radius[j]);
        batch[m] = {i, k};
        m += touching;
        if constexpr (Law::keeps_tangential) keep_or_zero(touching, l_springs_t[k]);
        if constexpr (Law::keeps_rolling) keep_or_zero(touching, l_springs_r[k]);
      }
      flush(kBatch);
    }
    while (t < run.ghost_end) {
      for (const int stop = std::min(run.ghost_end, t + kBatch); t < stop; ++t) {
        const int e = order.ghost_entries[t];
        const int i = g_owner[e], q = g_partner[e];
        const bool touching =
            !apart((x[i] - g_x[q]) + (zero - g_shift[q]), L.radius[i] + G.radius[q]);
        batch[m] = {i, ~e};
        m += touching;
        if constexpr (Law::keeps_tangential) keep_or_zero(touching, g_springs_t[e]);
        if constexpr (Law::keeps_rolling) keep_or_zero(touching, g_springs_r[e]);
      }
      flush(kBatch);
    }
  }
  flush(1);
}

// Pairs, then walls (in wall order). With Canonical (parallel.reproducible) the pairs in
// canonical order, the default: the local list, then the ghost list.
template <class Law, bool Canonical>
void sweep(ContactSweep& s) {
  if constexpr (Canonical) {
    if (s.ghosts_ready) s.ghosts_ready();
    canonical_pair_sweep<Law>(s);
  } else {
    const int n = static_cast<int>(s.p.size());
    local_pair_sweep<Law>(s, 0, n);
    if (s.ghosts_ready) s.ghosts_ready();
    ghost_pair_sweep<Law>(s, 0, n);
  }
  wall_sweep<Law>(s);
}

template <class Law>
void report_contacts(const ContactSweep& s, ContactNetwork& out) {
  out.clear();
  const Particles& p = s.p;
  const Ghosts& g = s.ghosts;
  const Vec3 zero = Vec3::Zero();
  PairContacts& pairs = out.pairs;
  // A touching pair in canonical orientation (a the lower id, d = x_a - x_b) with copies of
  // its springs.
  const auto add_pair = [&](GlobalId ia, GlobalId ib, const Vec3& xa, const Vec3& d,
                            const Body<double>& a, const Body<double>& b,
                            const PairCoefficients& pc, Vec3 ht, Vec3 hr) {
    double overlap = 0;
    const ContactGeometry geo =
        pair_geometry<Law>(d, a, b, reduced_radius(a, b), reduced_mass(a, b), overlap);
    const ContactResult r = Law::evaluate(geo, pc, s.constants, ht, hr, s.dt, s.spring_dt);
    const double fn = Law::normal_force(geo, pc, s.constants, s.dt);
    const Vec3 normal = fn * geo.n;
    pairs.id.push_back({ia, ib});
    pairs.ends.push_back(xa);
    pairs.ends.push_back(xa - d);
    pairs.point.push_back(xa - geo.arm_i * geo.n);
    pairs.normal_force.push_back(normal);
    pairs.tangential_force.push_back(r.force - normal);
    pairs.normal_force_magnitude.push_back(std::abs(fn));
    pairs.overlap.push_back(overlap);
  };
  const auto spring = [](const ListSprings& springs, int k) {
    ContactHistory h;
    if constexpr (Law::keeps_tangential) h.tangential = springs.tangential[k];
    if constexpr (Law::keeps_rolling) h.rolling = springs.rolling[k];
    return h;
  };
  // The dashpots' velocities as the sweep gives them (predicted ones only when the law reads
  // them; Particles::v_pred).
  const auto body = [&](std::size_t i) {
    if constexpr (Law::predicted_dashpot)
      return Body<double>{p.v[i], p.omega[i], p.v_pred[i], p.omega_pred[i],
                          p.radius[i], p.mass[i], p.inertia[i]};
    else
      return Body<double>{p.v[i], p.omega[i], Vec3::Zero(), Vec3::Zero(),
                          p.radius[i], p.mass[i], p.inertia[i]};
  };
  const auto ghost_body = [&](std::size_t q) {
    if constexpr (Law::predicted_dashpot)
      return Body<double>{g.v[q], g.omega[q], g.v_pred[q], g.omega_pred[q],
                          g.radius[q], g.mass[q], g.inertia[q]};
    else
      return Body<double>{g.v[q], g.omega[q], Vec3::Zero(), Vec3::Zero(),
                          g.radius[q], g.mass[q], g.inertia[q]};
  };
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (int k = s.local_list.offsets[i]; k < s.local_list.offsets[i + 1]; ++k) {
      const std::size_t j = s.local_list.j[k];
      if (apart(p.x[i] - p.x[j], p.radius[i] + p.radius[j])) continue;
      const std::size_t a = p.id[i] < p.id[j] ? i : j, b = a == i ? j : i;
      const ContactHistory h = spring(s.local_springs, k);
      add_pair(p.id[a], p.id[b], p.x[a], Vec3(p.x[a] - p.x[b]), body(a), body(b),
               s.table(p.material[a], p.material[b]), h.tangential, h.rolling);
    }
    for (int k = s.ghost_list.offsets[i]; k < s.ghost_list.offsets[i + 1]; ++k) {
      const std::size_t q = s.ghost_list.j[k];
      // The ghost's owner (or, for a periodic image of a local particle, the other entry)
      // reports the pair when the ghost has the lower id.
      if (!(p.id[i] < g.id[q])) continue;
      const Vec3 d = (p.x[i] - g.x[q]) + (zero - g.shift[q]);
      if (apart(d, p.radius[i] + g.radius[q])) continue;
      const ContactHistory h = spring(s.ghost_springs, k);
      add_pair(p.id[i], g.id[q], p.x[i], d, body(i), ghost_body(q),
               s.table(p.material[i], g.material[q]), h.tangential, h.rolling);
    }
  }
  WallContacts& walls = out.walls;
  const auto add_wall = [&](std::size_t i, int w, const WallTouch& t, int material,
                            ContactHistory h) {
    const ContactGeometry geo = wall_geometry<Law>(p, i, t);
    const PairCoefficients& pc = s.table(p.material[i], material);
    const ContactResult r =
        Law::evaluate(geo, pc, s.constants, h.tangential, h.rolling, s.dt, s.spring_dt);
    const double fn = Law::normal_force(geo, pc, s.constants, s.dt);
    const Vec3 normal = fn * geo.n;
    const Vec3 point = p.x[i] - geo.arm_i * geo.n;
    walls.id.push_back(p.id[i]);
    walls.wall.push_back(w);
    walls.ends.push_back(p.x[i]);
    walls.ends.push_back(point);
    walls.point.push_back(point);
    walls.normal_force.push_back(normal);
    walls.tangential_force.push_back(r.force - normal);
    walls.normal_force_magnitude.push_back(std::abs(fn));
    walls.overlap.push_back(geo.overlap);
  };
  // The walls as wall_sweep() finds their contacts and springs.
  for (std::size_t w = 0; w < s.walls.walls().size(); ++w) {
    const WallSet::Entry& wall = s.walls.walls()[w];
    const int index = static_cast<int>(w);
    if (wall.kind == Wall::Kind::mesh) {
      constexpr int kSlots = WallSet::kMeshSlots;
      const TriangleMesh& mesh = s.walls.mesh(wall);
      const bool moving = wall.pose.moving();
      const bool conveyor = wall.surface_velocity.squaredNorm() > 0;
      const Vec3 belt = wall.pose.direction_to_world(wall.surface_velocity);
      MeshTouch touch[TriangleMesh::kMaxTouches];
      for (std::size_t i = 0; i < p.size(); ++i) {
        const double r = p.radius[i];
        const Vec3 x = s.walls.in_period(p.x[i]);
        const int n = mesh.touches(WallSet::mesh_query(wall, x), r, touch);
        bool used[kSlots] = {};
        for (int k = 0; k < n; ++k) {
          const WallTouch t = mesh_wall_touch(wall, touch[k], x, r, moving, conveyor, belt);
          ContactHistory h;
          if constexpr (Law::has_history) {
            const int best = mesh_slot(s.wall_history, wall.column, i, t.n, used);
            if (best >= 0) {
              used[best] = true;
              h = s.wall_history[wall.column + 2 * best][i];
            }
          }
          add_wall(i, index, t, wall.material, h);
        }
      }
      continue;
    }
    const WallNeighbours::List& list = s.wall_neighbours.lists[w];
    const std::vector<ContactHistory>& history = s.wall_history[wall.column];
    const std::size_t n = list.all ? p.size() : list.i.size();
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = list.all ? k : static_cast<std::size_t>(list.i[k]);
      WallTouch t;
      const bool touching = wall.kind == Wall::Kind::plane
                                ? touch_plane(wall.plane, p.x[i], p.radius[i], t)
                                : touch_cylinder(wall.cylinder, p.x[i], p.radius[i], t);
      if (!touching) continue;
      if (wall.pose.moving()) {
        t.surface_velocity += wall.pose.velocity_at(p.x[i] - (p.radius[i] - t.overlap) * t.n);
        t.spin += wall.pose.spin();
      }
      add_wall(i, index, t, wall.material, Law::has_history ? history[k] : ContactHistory{});
    }
  }
}

template <class Law>
SweepChoice choice(bool canonical) {
  return {canonical ? &sweep<Law, true> : &sweep<Law, false>,
          &report_contacts<Law>,
          Law::has_history,
          Law::keeps_tangential,
          Law::keeps_rolling,
          Law::needs_spin,
          std::string(Law::normal::name) + " + " + Law::tangential::name + " + " +
              Law::rolling::name + " + " + Law::cohesion::name};
}

// Expands the run-time slot choice into one compile-time combination, one slot at a time.
template <class N, class T, class R, class C>
SweepChoice pick_dashpot(const ContactSettings& c, bool canonical) {
  if (c.dashpot_velocity == DashpotVelocity::predicted)
    return choice<ContactLaw<N, T, R, C, true>>(canonical);
  return choice<ContactLaw<N, T, R, C, false>>(canonical);
}
template <class N, class T, class R>
SweepChoice pick_cohesion(const ContactSettings& c, bool canonical) {
  if (c.cohesion == CohesionModel::sjkr) return pick_dashpot<N, T, R, SjkrCohesion>(c, canonical);
  return pick_dashpot<N, T, R, NoCohesion>(c, canonical);
}
template <class N, class T>
SweepChoice pick_rolling(const ContactSettings& c, bool canonical) {
  switch (c.rolling) {
    case RollingModel::cdt: return pick_cohesion<N, T, CdtRolling>(c, canonical);
    case RollingModel::epsd: return pick_cohesion<N, T, EpsdRolling>(c, canonical);
    case RollingModel::none: break;
  }
  return pick_cohesion<N, T, NoRolling>(c, canonical);
}
template <class N>
SweepChoice pick_tangential(const ContactSettings& c, bool canonical) {
  if (c.tangential == TangentialModel::history)
    return pick_rolling<N, HistoryTangential>(c, canonical);
  return pick_rolling<N, NoTangential>(c, canonical);
}

}  // namespace

SweepChoice select_sweep(const ContactSettings& settings, bool canonical) {
  if (settings.normal == NormalModel::hooke)
    return pick_tangential<HookeNormal>(settings, canonical);
  return pick_tangential<HertzNormal>(settings, canonical);
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
        const Vec3 x = s.walls.in_period(p.x[i]);
        const int n = mesh.touches(WallSet::mesh_query(wall, x), r, touch);
        for (int k = 0; k < n; ++k) {
          WallTouch t;
          t.n = moving ? wall.pose.direction_to_world(touch[k].n) : touch[k].n;
          t.overlap = touch[k].overlap;
          t.surface_velocity = belt - belt.dot(t.n) * t.n;
          if (moving) t.surface_velocity += wall.pose.velocity_at(x - (r - t.overlap) * t.n);
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

void tally_contacts(const Particles& p, const Ghosts& g, const NeighbourList& local_list,
                    const NeighbourList& ghost_list, const WallSet& walls,
                    const WallNeighbours& wall_neighbours, std::vector<int>& count,
                    std::vector<double>& overlap_max) {
  count.assign(p.size(), 0);
  overlap_max.assign(p.size(), 0.0);
  const auto add = [&](std::size_t i, double ratio) {
    ++count[i];
    overlap_max[i] = std::max(overlap_max[i], ratio);
  };
  const Vec3 zero = Vec3::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) {
    // Half list: each local pair once, counted for both.
    for (int k = local_list.offsets[i]; k < local_list.offsets[i + 1]; ++k) {
      const std::size_t j = local_list.j[k];
      const Vec3 d = p.x[i] - p.x[j];
      const double rs = p.radius[i] + p.radius[j];
      if (apart(d, rs)) continue;
      const double ratio = (rs - std::sqrt(d.squaredNorm())) / std::min(p.radius[i], p.radius[j]);
      add(i, ratio);
      add(j, ratio);
    }
    // The ghost's owner counts the pair for its own particle.
    for (int k = ghost_list.offsets[i]; k < ghost_list.offsets[i + 1]; ++k) {
      const std::size_t q = ghost_list.j[k];
      const Vec3 d = (p.x[i] - g.x[q]) + (zero - g.shift[q]);
      const double rs = p.radius[i] + g.radius[q];
      if (apart(d, rs)) continue;
      add(i, (rs - std::sqrt(d.squaredNorm())) / std::min(p.radius[i], g.radius[q]));
    }
  }
  for (std::size_t w = 0; w < walls.walls().size(); ++w) {
    const WallSet::Entry& wall = walls.walls()[w];
    if (wall.kind == Wall::Kind::mesh) {
      const TriangleMesh& mesh = walls.mesh(wall);
      MeshTouch touch[TriangleMesh::kMaxTouches];
      for (std::size_t i = 0; i < p.size(); ++i) {
        const int n =
            mesh.touches(WallSet::mesh_query(wall, walls.in_period(p.x[i])), p.radius[i], touch);
        for (int k = 0; k < n; ++k) add(i, touch[k].overlap / p.radius[i]);
      }
      continue;
    }
    const WallNeighbours::List& list = wall_neighbours.lists[w];
    const std::size_t n = list.all ? p.size() : list.i.size();
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = list.all ? k : static_cast<std::size_t>(list.i[k]);
      WallTouch t;
      const bool touching = wall.kind == Wall::Kind::plane
                                ? touch_plane(wall.plane, p.x[i], p.radius[i], t)
                                : touch_cylinder(wall.cylinder, p.x[i], p.radius[i], t);
      if (touching) add(i, t.overlap / p.radius[i]);
    }
  }
}

}  // namespace grainflow
