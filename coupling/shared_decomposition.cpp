#include "coupling/shared_decomposition.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

namespace grainflow::coupling {
namespace {

const char* const kMethods =
    "decompose the mesh with method `simple` or `hierarchical` in system/decomposeParDict (they "
    "cut a box-shaped mesh into a grid of boxes when the cells along each direction divide "
    "evenly among the processors along it: they split by cell count, so 7 layers over 2 "
    "processors share one layer between them); scotch, metis and other graph methods do not";

std::string box_text(const Box& b) {
  std::ostringstream s;
  s.precision(9);
  s << "[" << b.lo[0] << ", " << b.hi[0] << "] x [" << b.lo[1] << ", " << b.hi[1] << "] x ["
    << b.lo[2] << ", " << b.hi[2] << "]";
  return s.str();
}

// Index of the plane equal to x within tol, or -1.
int plane_index(const std::vector<double>& planes, double x, double tol) {
  for (std::size_t k = 0; k < planes.size(); ++k)
    if (std::abs(planes[k] - x) <= tol) return static_cast<int>(k);
  return -1;
}

}  // namespace

ProcessorGrid processor_grid_from_boxes(const std::vector<Box>& boxes, int rank,
                                        const Box& domain, double tolerance) {
  ProcessorGrid grid;
  const int ranks = static_cast<int>(boxes.size());
  for (int a = 0; a < 3; ++a) {
    const double length = domain.hi[a] - domain.lo[a];
    const double tol = tolerance * length;
    double lo = boxes[0].lo[a], hi = boxes[0].hi[a];
    for (const Box& b : boxes) {
      lo = std::min(lo, b.lo[a]);
      hi = std::max(hi, b.hi[a]);
    }
    if (std::abs(lo - domain.lo[a]) > tol || std::abs(hi - domain.hi[a]) > tol) {
      std::ostringstream s;
      s.precision(12);
      s << "the fluid mesh spans [" << lo << ", " << hi << "] m along " << "xyz"[a]
        << " but the scene's domain is [" << domain.lo[a] << ", " << domain.hi[a]
        << "] m; the DEM domain and the mesh must be the same box";
      throw DecompositionMismatch(s.str());
    }
    std::vector<double> planes;
    for (const Box& b : boxes)
      for (double x : {b.lo[a], b.hi[a]})
        if (plane_index(planes, x, tol) < 0) planes.push_back(x);
    std::sort(planes.begin(), planes.end());
    planes.front() = domain.lo[a];
    planes.back() = domain.hi[a];
    grid.cuts[a] = planes;
    grid.dims[a] = static_cast<int>(planes.size()) - 1;
  }
  if (grid.dims[0] * grid.dims[1] * grid.dims[2] != ranks) {
    std::ostringstream s;
    s << "the " << ranks << " processor meshes do not form a grid of boxes: the bounding boxes "
      << "of their cells have sides on " << grid.dims[0] + 1 << " x " << grid.dims[1] + 1 << " x "
      << grid.dims[2] + 1 << " planes, which would cut the domain into "
      << grid.dims[0] * grid.dims[1] * grid.dims[2] << " boxes, not " << ranks
      << " (a processor whose cells are not one box, such as scattered cells or slabs, does "
         "this); "
      << kMethods;
    throw DecompositionMismatch(s.str());
  }
  std::set<std::array<int, 3>> taken;
  for (int r = 0; r < ranks; ++r) {
    std::array<int, 3> c{};
    for (int a = 0; a < 3; ++a) {
      const double tol = tolerance * (domain.hi[a] - domain.lo[a]);
      const int i = plane_index(grid.cuts[a], boxes[r].lo[a], tol);
      const int j = plane_index(grid.cuts[a], boxes[r].hi[a], tol);
      if (i < 0 || j != i + 1) {
        std::ostringstream s;
        s << "processor " << r << "'s cells span " << box_text(boxes[r])
          << ", which is not one box of the processor grid the other processors imply; "
          << kMethods;
        throw DecompositionMismatch(s.str());
      }
      c[a] = i;
    }
    if (!taken.insert(c).second) {
      std::ostringstream s;
      s << "processors overlap: processor " << r << "'s cells span " << box_text(boxes[r])
        << ", the box of another processor; " << kMethods;
      throw DecompositionMismatch(s.str());
    }
    if (r == rank) grid.coords = c;
  }
  return grid;
}

}  // namespace grainflow::coupling
