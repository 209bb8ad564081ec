#pragma once
// What one contact law evaluation sees, and what it returns.
#include <cmath>

#include "dem/core/types.hpp"

namespace grainflow {

// Spring states that must survive from step to step while two bodies touch.
struct ContactHistory {
  Vec3 tangential = Vec3::Zero();  // accumulated tangential spring displacement [m]
  Vec3 rolling = Vec3::Zero();     // EPSD rolling spring torque [N m]
};

struct ContactGeometry {
  Vec3 n;               // unit normal, pointing from j (or the wall) towards i
  double overlap;       // > 0 [m]
  double distance;      // centre distance (particle pairs) [m]
  double r_i, r_j;      // radii; r_j unused for walls
  double arm_i, arm_j;  // centre to contact point; arm_j = 0 for walls
  double r_star, m_star;
  double roll_inertia;  // EPSD: 1/I_r = 1/(I_i + m_i r_i^2) + 1/(I_j + m_j r_j^2)
  Vec3 v_rel;           // velocity of i relative to j at the contact point
  Vec3 w_rel;           // angular velocity of i minus that of j
  bool wall;
};

struct ContactResult {
  Vec3 force;     // on i (j receives -force)
  Vec3 torque_i;  // on i
  Vec3 torque_j;  // on j (ignored for walls)
};

// Stiffness and damping of one contact, from the normal slot.
struct SpringDashpot {
  double kn, gn, kt, gt;
};

// Settings that are the same for every pair (from the scene's `contact:` block).
struct ContactConstants {
  double hooke_characteristic_velocity = 0;  // > 0 selects the characteristic-velocity form
  double hooke_kn = 0;                       // explicit stiffness form
  double hooke_kt = 0;
  double epsd_damping_ratio = 0.3;
};

// Keeps a history vector in the current tangent plane: project out the normal
// part (the contact frame has rotated) and restore the magnitude.
inline void rotate_into_tangent_plane(Vec3& h, const Vec3& n) {
  const double before = h.squaredNorm();
  if (before == 0) return;
  h -= n.dot(h) * n;
  const double after = h.squaredNorm();
  if (after > 0) h *= std::sqrt(before / after);
}

}  // namespace grainflow
