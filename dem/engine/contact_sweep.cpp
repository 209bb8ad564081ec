#include "dem/engine/contact_sweep.hpp"

#include <algorithm>
#include <cmath>

#include "dem/contact/contact_law.hpp"
#include "dem/engine/wall_sweep.hpp"

namespace grainflow {
namespace {

template <class Law, bool Periodic>
void pair_sweep(ContactSweep& s) {
  Particles& p = s.p;
  const std::size_t n = p.size();
  ContactHistory unused;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 xi = p.x[i];
    const double ri = p.radius[i], mi = p.mass[i];
    for (int k = s.list.offsets[i]; k < s.list.offsets[i + 1]; ++k) {
      const int j = s.list.j[k];
      Vec3 d = xi - p.x[j];
      if constexpr (Periodic) d = s.box.min_image(d);
      const double rj = p.radius[j];
      const double rs = ri + rj;
      const double r2 = d.squaredNorm();
      if (r2 >= rs * rs) {
        if constexpr (Law::has_history) s.pair_history[k] = ContactHistory{};
        continue;
      }
      const double dist = std::sqrt(r2);
      ContactGeometry g;
      g.n = d / dist;
      g.overlap = rs - dist;
      g.distance = dist;
      g.r_i = ri;
      g.r_j = rj;
      g.arm_i = ri - 0.5 * g.overlap;
      g.arm_j = rj - 0.5 * g.overlap;
      g.r_star = ri * rj / rs;
      const double mj = p.mass[j];
      g.m_star = mi * mj / (mi + mj);
      g.wall = false;
      if constexpr (Law::needs_spin) {
        g.v_rel = p.v[i] - p.v[j] - (g.arm_i * p.omega[i] + g.arm_j * p.omega[j]).cross(g.n);
        g.w_rel = p.omega[i] - p.omega[j];
      } else {
        g.v_rel = p.v[i] - p.v[j];
      }
      if constexpr (Law::needs_roll_inertia)
        g.roll_inertia = 1.0 / (1.0 / (p.inertia[i] + mi * ri * ri) +
                                1.0 / (p.inertia[j] + mj * rj * rj));
      ContactHistory& h = Law::has_history ? s.pair_history[k] : unused;
      const ContactResult r =
          Law::evaluate(g, s.table(p.material[i], p.material[j]), s.constants, h, s.dt);
      p.force[i] += r.force;
      p.force[j] -= r.force;
      if constexpr (Law::needs_spin) {
        p.torque[i] += r.torque_i;
        p.torque[j] += r.torque_j;
      }
      ++s.contacts;
      s.max_overlap_ratio = std::max(s.max_overlap_ratio, g.overlap / std::min(ri, rj));
    }
  }
}

template <class Law, bool Periodic>
void sweep(ContactSweep& s) {
  pair_sweep<Law, Periodic>(s);
  wall_sweep<Law>(s);
}

template <class Law>
SweepChoice choice(bool periodic) {
  return {periodic ? &sweep<Law, true> : &sweep<Law, false>, Law::has_history, Law::needs_spin,
          std::string(Law::normal::name) + " + " + Law::tangential::name + " + " +
              Law::rolling::name + " + " + Law::cohesion::name};
}

// Expands the run-time slot choice into one compile-time combination, one slot at a time.
template <class N, class T, class R>
SweepChoice pick_cohesion(const ContactSettings& c, bool periodic) {
  if (c.cohesion == CohesionModel::sjkr) return choice<ContactLaw<N, T, R, SjkrCohesion>>(periodic);
  return choice<ContactLaw<N, T, R, NoCohesion>>(periodic);
}
template <class N, class T>
SweepChoice pick_rolling(const ContactSettings& c, bool periodic) {
  switch (c.rolling) {
    case RollingModel::cdt: return pick_cohesion<N, T, CdtRolling>(c, periodic);
    case RollingModel::epsd: return pick_cohesion<N, T, EpsdRolling>(c, periodic);
    case RollingModel::none: break;
  }
  return pick_cohesion<N, T, NoRolling>(c, periodic);
}
template <class N>
SweepChoice pick_tangential(const ContactSettings& c, bool periodic) {
  if (c.tangential == TangentialModel::history)
    return pick_rolling<N, HistoryTangential>(c, periodic);
  return pick_rolling<N, NoTangential>(c, periodic);
}

}  // namespace

SweepChoice select_sweep(const ContactSettings& settings, bool periodic) {
  if (settings.normal == NormalModel::hooke) return pick_tangential<HookeNormal>(settings, periodic);
  return pick_tangential<HertzNormal>(settings, periodic);
}

}  // namespace grainflow
