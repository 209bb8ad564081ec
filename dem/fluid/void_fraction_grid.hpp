#pragma once
// Void fraction computed from the particles on a regular grid of cells covering the
// domain (one-way mode; the coupled solver computes it on the OpenFOAM mesh).
//
// Centre method (DESIGN.md §5): a particle's whole volume goes to the cell holding
// its centre; eps = 1 - (solid volume in the cell) / V_cell. Every rank adds its own
// particles and one reduction sums the grid, so eps does not depend on the number of
// ranks. Where eps would fall below the lower bound eps_min it is clamped: each
// clamped cell is counted, and the solid volume the clamp removed is accumulated, so
// the report says how much was lost to it.
#include <mpi.h>

#include <array>
#include <string>
#include <vector>

#include "dem/core/particles.hpp"
#include "dem/fluid/prescribed_fluid.hpp"
#include "dem/scene/scene.hpp"

namespace grainflow {

// The most cells a void-fraction grid may have: 2^26 = 67 108 864. Each cell holds its solid
// volume (a 64-bit integer) and eps (a double): 1 GiB on every rank, summed over the ranks by one
// reduction of that size per step. Finer grids are refused before allocation (docs/stability.md).
constexpr double kMaxVoidFractionCells = 67108864;
constexpr double kVoidFractionBytesPerCell = sizeof(long long) + sizeof(double);

// The cells along each axis the grid takes for a domain (cell_size rounded to fit it).
std::array<double, 3> void_fraction_grid_cells(const Domain& domain,
                                               const VoidFractionGridSettings& settings);

// Why the grid would be too large, for a message that names the scene's key (cells and bytes,
// the limit, the smallest cell_size that fits); "" when it fits.
std::string void_fraction_grid_too_large(const Domain& domain,
                                         const VoidFractionGridSettings& settings);

class VoidFractionGrid {
 public:
  // std::length_error when void_fraction_grid_too_large() has a reason (checked earlier,
  // with the scene's key, by grain check and run: dem/engine/run.cpp).
  VoidFractionGrid(const Domain& domain, const VoidFractionGridSettings& settings);
  // Recomputes eps from this rank's particles and the other ranks' (collective).
  void update(const Particles& p, MPI_Comm comm);
  double at(const Vec3& x) const { return eps_[cell_of(x)]; }
  double cell_volume() const { return cell_volume_; }
  const std::array<int, 3>& cells() const { return n_; }
  long clamped_cells_total() const { return clamped_total_; }  // summed over updates
  double clamped_volume_total() const { return clamped_volume_; }  // [m^3] summed over updates

 private:
  std::size_t cell_of(const Vec3& x) const;

  Domain domain_;
  double minimum_;
  std::array<int, 3> n_{};
  Vec3 edge_;
  double cell_volume_ = 0;
  std::vector<long long> solid_;  // [2^-e cell volumes] (update)
  std::vector<double> eps_;
  long clamped_total_ = 0;
  double clamped_volume_ = 0;
};

}  // namespace grainflow
