#include "dem/fluid/void_fraction_grid.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace grainflow {

std::array<double, 3> void_fraction_grid_cells(const Domain& domain,
                                               const VoidFractionGridSettings& s) {
  std::array<double, 3> n{};
  for (int a = 0; a < 3; ++a)
    n[a] = std::max(1.0, std::round((domain.hi[a] - domain.lo[a]) / s.cell_size));
  return n;
}

std::string void_fraction_grid_too_large(const Domain& domain, const VoidFractionGridSettings& s) {
  const std::array<double, 3> n = void_fraction_grid_cells(domain, s);
  const double cells = n[0] * n[1] * n[2];
  if (cells <= kMaxVoidFractionCells) return {};
  // The smallest cell size (three significant digits, rounded up) whose grid fits.
  const Vec3 length = domain.hi - domain.lo;
  VoidFractionGridSettings fit = s;
  fit.cell_size = std::cbrt(length.prod() / kMaxVoidFractionCells);
  const double scale = std::pow(10.0, std::floor(std::log10(fit.cell_size)) - 2);
  fit.cell_size = std::ceil(fit.cell_size / scale) * scale;
  for (;;) {
    const std::array<double, 3> m = void_fraction_grid_cells(domain, fit);
    if (m[0] * m[1] * m[2] <= kMaxVoidFractionCells) break;
    fit.cell_size += scale;
  }
  std::ostringstream o;
  o.precision(4);
  o << "cell_size " << s.cell_size << " m over the domain's " << length[0] << " x " << length[1]
    << " x " << length[2] << " m gives " << n[0] << " x " << n[1] << " x " << n[2] << " = " << cells
    << " cells, " << cells * kVoidFractionBytesPerCell / 1e9 << " GB on every rank; the limit is "
    << static_cast<long>(kMaxVoidFractionCells) << " cells ("
    << kMaxVoidFractionCells * kVoidFractionBytesPerCell / 1e9
    << " GB). Use cell_size >= " << fit.cell_size
    << " m (the grid covers the whole domain), or a smaller domain";
  return o.str();
}

VoidFractionGrid::VoidFractionGrid(const Domain& domain, const VoidFractionGridSettings& s)
    : domain_(domain), minimum_(s.minimum) {
  if (const std::string why = void_fraction_grid_too_large(domain, s); !why.empty())
    throw std::length_error("void fraction grid: " + why);
  const std::array<double, 3> counts = void_fraction_grid_cells(domain, s);
  cell_volume_ = 1;
  for (int a = 0; a < 3; ++a) {
    const double length = domain.hi[a] - domain.lo[a];
    n_[a] = static_cast<int>(counts[a]);
    edge_[a] = length / n_[a];
    cell_volume_ *= edge_[a];
  }
  const std::size_t cells = static_cast<std::size_t>(n_[0]) * n_[1] * n_[2];
  solid_.assign(cells, 0);
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
  // The solid volume of each cell is summed in integers: each particle's volume in units of
  // 2^-e cell volumes, rounded. Integer sums do not depend on their order, so eps is the same
  // whichever rank holds a particle and in whatever order a rank stores them: bit for bit on
  // any number of ranks (docs/parallel.md, "Reproducible results"). A floating-point sum
  // differed in the last bit between 2 and 3 ranks, and a chaotic scene grew that.
  // e is the largest exponent for which no cell can overflow: no cell holds more than the
  // particle count times the largest particle (count and maximum are exact on any ranks).
  long long count = static_cast<long long>(p.size());
  double largest = 0;  // [cell volumes]
  for (std::size_t i = 0; i < p.size(); ++i)
    largest = std::max(largest, sphere_volume(p.radius[i]) / cell_volume_);
  MPI_Allreduce(MPI_IN_PLACE, &count, 1, MPI_LONG_LONG, MPI_SUM, comm);
  MPI_Allreduce(MPI_IN_PLACE, &largest, 1, MPI_DOUBLE, MPI_MAX, comm);
  const double bound = std::max(static_cast<double>(count) * largest, 1.0);
  const int e = 61 - static_cast<int>(std::ceil(std::log2(bound)));
  std::fill(solid_.begin(), solid_.end(), 0);
  for (std::size_t i = 0; i < p.size(); ++i)
    solid_[cell_of(p.x[i])] +=
        std::llround(std::ldexp(sphere_volume(p.radius[i]) / cell_volume_, e));
  MPI_Allreduce(MPI_IN_PLACE, solid_.data(), static_cast<int>(solid_.size()), MPI_LONG_LONG,
                MPI_SUM, comm);
  for (std::size_t c = 0; c < solid_.size(); ++c) {
    const double eps = 1 - std::ldexp(static_cast<double>(solid_[c]), -e);
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
