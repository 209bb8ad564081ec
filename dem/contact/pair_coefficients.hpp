#pragma once
// Material-pair constants of the contact laws, computed once at start-up
// (DESIGN.md §3). Everything that depends only on the two materials lives here;
// what depends on the two particles (R*, m*) or the overlap is computed per contact.
#include <vector>

#include "dem/scene/scene.hpp"

namespace grainflow {

struct PairCoefficients {
  double y_star = 0;         // 1/Y* = (1-nu_i^2)/Y_i + (1-nu_j^2)/Y_j
  double g_star = 0;         // 1/G* = 2(2-nu_i)(1+nu_i)/Y_i + 2(2-nu_j)(1+nu_j)/Y_j
  double hertz_gt_per_gn = 0;  // sqrt(4 G*/Y*) = gamma_t / gamma_n of Hertz-Mindlin
  double restitution = 1;
  double hertz_beta = 0;     // damping factor of the Hertz dashpot, mapped exactly to e
  double hooke_damping = 0;  // 1/sqrt(1 + (pi/ln e)^2): gamma_n = sqrt(4 m* k_n) * this
  double friction = 0;
  double rolling_friction = 0;
  double cohesion_energy_density = 0;
};

// A square table over material indices (walls use their own material index).
class PairTable {
 public:
  PairTable() = default;
  explicit PairTable(const Scene& scene);
  const PairCoefficients& operator()(int a, int b) const { return table_[a * n_ + b]; }
  int size() const { return n_; }

 private:
  int n_ = 0;
  std::vector<PairCoefficients> table_;
};

}  // namespace grainflow
