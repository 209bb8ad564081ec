#pragma once
// The orthogonal processor grid (DESIGN.md §2): nx × ny × nz boxes whose cut planes
// may be non-uniform and may be imposed from outside (the coupling takes them from
// the mesh decomposition). Each rank owns one box [lo, hi).
#include <mpi.h>

#include <array>
#include <optional>
#include <vector>

#include "dem/core/types.hpp"
#include "dem/scene/scene.hpp"

namespace grainflow {

class Decomposition {
 public:
  // dims: ranks per axis; {0,0,0} picks choose_processor_grid's grid for the domain alone.
  Decomposition(MPI_Comm world, const Domain& domain, std::array<int, 3> dims = {0, 0, 0});
  ~Decomposition();
  Decomposition(const Decomposition&) = delete;
  Decomposition& operator=(const Decomposition&) = delete;

  MPI_Comm comm() const { return comm_; }  // Cartesian communicator
  int rank() const { return rank_; }
  int size() const { return size_; }
  const std::array<int, 3>& dims() const { return dims_; }
  const std::array<int, 3>& coords() const { return coords_; }
  const Domain& domain() const { return domain_; }
  Vec3 length() const { return domain_.hi - domain_.lo; }
  const Vec3& lo() const { return lo_; }  // this rank's box
  const Vec3& hi() const { return hi_; }
  // Neighbour rank along `axis` in direction dir (0: minus, 1: plus); MPI_PROC_NULL
  // at a bounded side; this rank itself on a periodic axis with one rank.
  int neighbour(int axis, int dir) const { return neighbour_[axis][dir]; }
  const std::vector<double>& cuts(int axis) const { return cuts_[axis]; }

  // Imposes the cut planes of one axis: dims(axis)+1 increasing values from the
  // domain's lo to its hi. Throws std::invalid_argument when they do not fit.
  void set_cuts(int axis, const std::vector<double>& planes);

  // Grid coordinate along `axis` of the box holding coordinate x (clamped to the grid).
  int coordinate_of(int axis, double x) const;
  bool owns(const Vec3& x) const;
  // Smallest box thickness over all ranks and axes (ghosts come from neighbours only,
  // so it must exceed the interaction range).
  double thinnest_box() const;

 private:
  void update_box();

  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0, size_ = 1;
  std::array<int, 3> dims_{1, 1, 1}, coords_{0, 0, 0};
  std::array<std::array<int, 2>, 3> neighbour_{};
  std::array<std::vector<double>, 3> cuts_;
  Domain domain_;
  Vec3 lo_, hi_;
};

// The processor grid nx × ny × nz = ranks for a domain of size `length` (docs/parallel.md):
// among the grids whose uniform boxes are at least `min_box` thick along every axis with
// more than one rank (all grids when none is), the one with the least total cut area
// through a region of size `extent` (where the particles are; the domain when absent):
// (nx−1) E_y E_z + (ny−1) E_x E_z + (nz−1) E_x E_y. Equal areas (to 1e-12 relative) go
// to the grid with more ranks along x, then along y.
std::array<int, 3> choose_processor_grid(int ranks, const Vec3& length, double min_box = 0,
                                         const std::optional<Vec3>& extent = std::nullopt);

// The n+1 cut planes of one axis over [lo, hi] that put equal numbers of the coordinates
// `x` into the n boxes (each plane midway between the two coordinates it separates), then
// moved as little as needed so that no box is thinner than min_box (possible when
// hi − lo ≥ n min_box). Without coordinates: uniform planes.
std::vector<double> balanced_cut_planes(std::vector<double> x, double lo, double hi, int n,
                                        double min_box);

}  // namespace grainflow
