#include "dem/parallel/decomposition.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace grainflow {

std::array<int, 3> choose_processor_grid(int ranks, const Vec3& length) {
  std::array<int, 3> best{ranks, 1, 1};
  double best_area = std::numeric_limits<double>::infinity();
  for (int nx = 1; nx <= ranks; ++nx) {
    if (ranks % nx) continue;
    for (int ny = 1; ny <= ranks / nx; ++ny) {
      if ((ranks / nx) % ny) continue;
      const int nz = ranks / nx / ny;
      const double area = (nx - 1) * length[1] * length[2] + (ny - 1) * length[0] * length[2] +
                          (nz - 1) * length[0] * length[1];
      if (area < best_area - 1e-12 * best_area) {
        best_area = area;
        best = {nx, ny, nz};
      }
    }
  }
  return best;
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
