#pragma once
// What one contact law evaluation sees, and what it returns.
#include <cmath>
#include <cstddef>
#include <type_traits>
#include <vector>

#include "dem/core/lanes.hpp"
#include "dem/core/types.hpp"

namespace grainflow {

// Spring states that must survive from step to step while two bodies touch.
struct ContactHistory {
  Vec3 tangential = Vec3::Zero();  // accumulated tangential spring displacement [m]
  Vec3 rolling = Vec3::Zero();     // EPSD rolling spring torque [N m]
};

// The springs of a neighbour list, parallel to its entries. Only the springs the contact law
// has are stored: with a tangential spring and no EPSD rolling spring (the common choice)
// an entry holds 24 bytes, not the 48 of a ContactHistory.
struct ListSprings {
  std::vector<Vec3> tangential;  // empty unless the law has a tangential spring
  std::vector<Vec3> rolling;     // empty unless the law has a rolling spring (EPSD)

  // `entries` zero springs of the kinds asked for; the memory of the others is released.
  void reset(std::size_t entries, bool with_tangential, bool with_rolling) {
    tangential.assign(with_tangential ? entries : 0, Vec3::Zero());
    rolling.assign(with_rolling ? entries : 0, Vec3::Zero());
    if (!with_tangential) tangential.shrink_to_fit();
    if (!with_rolling) rolling.shrink_to_fit();
  }
  // Both springs of entry k (zero where not stored).
  ContactHistory operator[](std::size_t k) const {
    return {tangential.empty() ? Vec3::Zero() : tangential[k],
            rolling.empty() ? Vec3::Zero() : rolling[k]};
  }
  void set(std::size_t k, const ContactHistory& h) {
    if (!tangential.empty()) tangential[k] = h.tangential;
    if (!rolling.empty()) rolling[k] = h.rolling;
  }
};

// The geometry of one contact (V = double), or of several side by side (V = Lanes2,
// dem/core/lanes.hpp).
template <class V>
struct ContactGeometryT {
  V3<V> n;         // unit normal, pointing from j (or the wall) towards i
  V overlap;       // > 0 [m]
  V distance;      // centre distance (particle pairs) [m]
  V r_i, r_j;      // radii; r_j unused for walls
  V arm_i, arm_j;  // centre to contact point; arm_j = 0 for walls
  V r_star, m_star;
  V roll_inertia;  // EPSD: 1/I_r = 1/(I_i + m_i r_i^2) + 1/(I_j + m_j r_j^2)
  // Velocity of i relative to j at the contact point, and angular velocity of i minus that of
  // j: at the half step (v_rel, w_rel: the springs' increments, over the step) and those the
  // dashpots see (v_pred, w_pred: Particles::v_pred, the half-step or the predicted
  // end-of-step velocity).
  V3<V> v_rel;
  V3<V> w_rel;
  V3<V> v_pred;
  V3<V> w_pred;
  bool wall;
};
using ContactGeometry = ContactGeometryT<double>;

template <class V>
struct ContactResultT {
  V3<V> force;     // on i (j receives -force)
  V3<V> torque_i;  // on i
  V3<V> torque_j;  // on j (ignored for walls)
};
using ContactResult = ContactResultT<double>;

// Stiffness and damping of one contact, from the normal slot.
template <class V>
struct SpringDashpotT {
  V kn, gn, kt, gt;
};
using SpringDashpot = SpringDashpotT<double>;

// Settings that are the same for every pair (from the scene's `contact:` block).
struct ContactConstants {
  double hooke_characteristic_velocity = 0;  // > 0 selects the characteristic-velocity form
  double hooke_kn = 0;                       // explicit stiffness form
  double hooke_kt = 0;
  double epsd_damping_ratio = 0.3;
};

// Keeps a history vector in the current tangent plane: project out the normal
// part (the contact frame has rotated) and restore the magnitude. The projection's squared
// length is |h|^2 - (n.h)^2 (n a unit vector; h is nearly tangent, so no cancellation), which
// the processor has before the projection itself: a shorter chain of dependent operations
// than |h - (n.h) n|^2 (rounding differs in the last bits).
template <class V3T>
[[gnu::always_inline]] inline void rotate_into_tangent_plane(V3T& h, const V3T& n) {
  if constexpr (std::is_same_v<V3T, Vec3>) {
    const double before = h.squaredNorm();
    if (before == 0) return;
    const double along = n.dot(h);
    h -= along * n;
    const double after = before - along * along;
    if (after > 0) h *= std::sqrt(before / after);
  } else {  // the same, lane by lane, both ways computed
    const auto before = squared_norm(h);
    const auto along = dot(n, h);
    const V3T projected = h - along * n;
    const auto after = before - along * along;
    const V3T scaled = projected * lane_sqrt(before / after);
    h = select(before == 0, h, select(after > 0, scaled, projected));
  }
}

}  // namespace grainflow
