#include "dem/parallel/decomposition.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace grainflow {

std::array<int, 3> choose_processor_grid(int ranks, const Vec3& length, double min_box,
                                         const std::optional<Vec3>& extent) {
  const Vec3 e = extent.value_or(length);
  std::array<int, 3> best{ranks, 1, 1};
  double best_area = 0;
  bool found = false, best_fits = false;
  // From the most ranks along x down: on equal areas the first grid met is kept.
  for (int nx = ranks; nx >= 1; --nx) {
    if (ranks % nx) continue;
    for (int ny = ranks / nx; ny >= 1; --ny) {
      if ((ranks / nx) % ny) continue;
      const int nz = ranks / nx / ny;
      const std::array<int, 3> n{nx, ny, nz};
      bool fits = true;
      for (int a = 0; a < 3; ++a) fits = fits && (n[a] == 1 || length[a] / n[a] >= min_box);
      const double area = (nx - 1) * e[1] * e[2] + (ny - 1) * e[0] * e[2] + (nz - 1) * e[0] * e[1];
      // A grid whose boxes are thick enough beats any that is not; then the least area.
      const bool better = !found || (fits && !best_fits) ||
                          (fits == best_fits && area < best_area - 1e-12 * best_area);
      if (better) {
        found = true;
        best_fits = fits;
        best_area = area;
        best = n;
      }
    }
  }
  return best;
}

std::vector<double> balanced_cut_planes(std::vector<double> x, double lo, double hi, int n,
                                        double min_box) {
  std::vector<double> cuts(n + 1);
  for (int k = 0; k <= n; ++k) cuts[k] = lo + (hi - lo) * k / n;
  cuts[n] = hi;
  const std::size_t count = x.size();
  if (count > 0) {
    std::sort(x.begin(), x.end());
    for (int k = 1; k < n; ++k) {
      // Boxes 0 .. k-1 get the first count*k/n coordinates.
      const std::size_t m = count * static_cast<std::size_t>(k) / static_cast<std::size_t>(n);
      if (m == 0)
        cuts[k] = lo;
      else if (m == count)
        cuts[k] = hi;
      else
        cuts[k] = 0.5 * (x[m - 1] + x[m]);
      cuts[k] = std::clamp(cuts[k], lo, hi);
    }
  }
  // No box thinner than min_box (a hair more, so that the thickness computed back from
  // the planes is not below it by round-off): forward from lo, then back from hi.
  const double t = min_box * (1 + 1e-9);
  for (int k = 1; k < n; ++k) cuts[k] = std::max(cuts[k], cuts[k - 1] + t);
  for (int k = n - 1; k >= 1; --k) cuts[k] = std::min(cuts[k], cuts[k + 1] - t);
  return cuts;
}

Decomposition::Decomposition(MPI_Comm world, const Domain& domain, std::array<int, 3> dims)
    : domain_(domain) {
  int world_size = 1;
  MPI_Comm_size(world, &world_size);
  if (dims == std::array<int, 3>{0, 0, 0}) dims = choose_processor_grid(world_size, length());
  if (dims[0] * dims[1] * dims[2] != world_size)
    throw std::invalid_argument("processor grid " + std::to_string(dims[0]) + " x " +
                                std::to_string(dims[1]) + " x " + std::to_string(dims[2]) +
                                " does not match the " + std::to_string(world_size) + " MPI ranks");
  dims_ = dims;
  int periods[3] = {domain.periodic[0], domain.periodic[1], domain.periodic[2]};
  MPI_Cart_create(world, 3, dims_.data(), periods, 0, &comm_);
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  MPI_Cart_coords(comm_, rank_, 3, coords_.data());
  for (int a = 0; a < 3; ++a) {
    MPI_Cart_shift(comm_, a, 1, &neighbour_[a][0], &neighbour_[a][1]);
    cuts_[a].resize(dims_[a] + 1);
    for (int k = 0; k <= dims_[a]; ++k)
      cuts_[a][k] = domain.lo[a] + (domain.hi[a] - domain.lo[a]) * k / dims_[a];
    cuts_[a][dims_[a]] = domain.hi[a];
  }
  update_box();
}

Decomposition::~Decomposition() {
  if (comm_ != MPI_COMM_NULL) {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Comm_free(&comm_);
  }
}

void Decomposition::set_cuts(int axis, const std::vector<double>& planes) {
  if (static_cast<int>(planes.size()) != dims_[axis] + 1)
    throw std::invalid_argument("axis " + std::string(1, "xyz"[axis]) + " needs " +
                                std::to_string(dims_[axis] + 1) + " cut planes, got " +
                                std::to_string(planes.size()));
  if (planes.front() != domain_.lo[axis] || planes.back() != domain_.hi[axis])
    throw std::invalid_argument("cut planes must start at the domain's lo and end at its hi");
  for (std::size_t k = 1; k < planes.size(); ++k)
    if (!(planes[k] > planes[k - 1]))
      throw std::invalid_argument("cut planes must increase strictly");
  cuts_[axis] = planes;
  update_box();
}

void Decomposition::update_box() {
  for (int a = 0; a < 3; ++a) {
    lo_[a] = cuts_[a][coords_[a]];
    hi_[a] = cuts_[a][coords_[a] + 1];
  }
}

int Decomposition::coordinate_of(int axis, double x) const {
  const auto& c = cuts_[axis];
  const int k = static_cast<int>(std::upper_bound(c.begin() + 1, c.end() - 1, x) - c.begin()) - 1;
  return std::clamp(k, 0, dims_[axis] - 1);
}

bool Decomposition::owns(const Vec3& x) const {
  for (int a = 0; a < 3; ++a)
    if (coordinate_of(a, x[a]) != coords_[a]) return false;
  return true;
}

double Decomposition::thinnest_box() const {
  double t = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a)
    for (int k = 0; k < dims_[a]; ++k) t = std::min(t, cuts_[a][k + 1] - cuts_[a][k]);
  return t;
}

}  // namespace grainflow
