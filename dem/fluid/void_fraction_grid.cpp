#include "dem/fluid/void_fraction_grid.hpp"

#include <algorithm>
#include <cmath>

namespace grainflow {

VoidFractionGrid::VoidFractionGrid(const Domain& domain, const VoidFractionGridSettings& s)
    : domain_(domain), minimum_(s.minimum) {
  cell_volume_ = 1;
  for (int a = 0; a < 3; ++a) {
    const double length = domain.hi[a] - domain.lo[a];
    n_[a] = std::max(1, static_cast<int>(std::lround(length / s.cell_size)));
    edge_[a] = length / n_[a];
    cell_volume_ *= edge_[a];
  }
  const std::size_t cells = static_cast<std::size_t>(n_[0]) * n_[1] * n_[2];
  solid_.assign(cells, 0.0);
  eps_.assign(cells, 1.0);
}

std::size_t VoidFractionGrid::cell_of(const Vec3& x) const {
  std::size_t index = 0;
  for (int a = 2; a >= 0; --a) {
    double u = (x[a] - domain_.lo[a]) / edge_[a];
    int k = static_cast<int>(std::floor(u));
    // Between rebuilds a particle may sit just past a periodic side: wrap it.
    if (domain_.periodic[a]) k = ((k % n_[a]) + n_[a]) % n_[a];
    k = std::clamp(k, 0, n_[a] - 1);
    index = index * n_[a] + k;
  }
  return index;
}

void VoidFractionGrid::update(const Particles& p, MPI_Comm comm) {
  std::fill(solid_.begin(), solid_.end(), 0.0);
  for (std::size_t i = 0; i < p.size(); ++i) solid_[cell_of(p.x[i])] += sphere_volume(p.radius[i]);
  MPI_Allreduce(MPI_IN_PLACE, solid_.data(), static_cast<int>(solid_.size()), MPI_DOUBLE, MPI_SUM,
                comm);
  for (std::size_t c = 0; c < solid_.size(); ++c) {
    const double eps = 1 - solid_[c] / cell_volume_;
    if (eps < minimum_) {
      ++clamped_total_;
      clamped_volume_ += (minimum_ - eps) * cell_volume_;
      eps_[c] = minimum_;
    } else {
      eps_[c] = eps;
    }
  }
}

}  // namespace grainflow
