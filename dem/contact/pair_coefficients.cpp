#include "dem/contact/pair_coefficients.hpp"

#include <cmath>
#include <map>
#include <numbers>

#include "dem/contact/restitution_mapping.hpp"

namespace grainflow {

PairTable::PairTable(const Scene& scene) : n_(static_cast<int>(scene.materials.size())) {
  table_.resize(static_cast<std::size_t>(n_) * n_);
  std::map<double, double> beta_of_e;  // the Hertz mapping costs ~0.1 s; share it
  for (int a = 0; a < n_; ++a) {
    for (int b = 0; b < n_; ++b) {
      const Material& ma = scene.materials[a];
      const Material& mb = scene.materials[b];
      const MaterialPair& pair = scene.pair(a, b);
      PairCoefficients c;
      c.y_star = 1.0 / ((1 - ma.poisson_ratio * ma.poisson_ratio) / ma.youngs_modulus +
                        (1 - mb.poisson_ratio * mb.poisson_ratio) / mb.youngs_modulus);
      c.g_star = 1.0 / (2 * (2 - ma.poisson_ratio) * (1 + ma.poisson_ratio) / ma.youngs_modulus +
                        2 * (2 - mb.poisson_ratio) * (1 + mb.poisson_ratio) / mb.youngs_modulus);
      c.hertz_gt_per_gn = std::sqrt(4 * c.g_star / c.y_star);
      c.restitution = pair.restitution;
      auto it = beta_of_e.find(pair.restitution);
      if (it == beta_of_e.end())
        it = beta_of_e.emplace(pair.restitution, hertz_damping_for_restitution(pair.restitution))
                 .first;
      c.hertz_beta = it->second;
      const double ln_e = std::log(pair.restitution);
      c.hooke_damping =
          pair.restitution >= 1 ? 0 : 1.0 / std::sqrt(1 + std::pow(std::numbers::pi / ln_e, 2));
      c.friction = pair.friction;
      c.rolling_friction = pair.rolling_friction;
      c.cohesion_energy_density = pair.cohesion_energy_density;
      table_[a * n_ + b] = c;
    }
  }
}

}  // namespace grainflow
