#pragma once
// The shared decomposition (DESIGN.md §2): the DEM's processor grid read off the fluid
// mesh's decomposition. Every rank's cells must fill one box, and the boxes together
// must form an orthogonal grid of nx × ny × nz boxes covering the scene's domain (what
// OpenFOAM's `simple` and `hierarchical` methods produce on a box-shaped mesh). C++17.
#include <stdexcept>
#include <string>
#include <vector>

#include "coupling/dem_link.hpp"

namespace grainflow::coupling {

class DecompositionMismatch : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

// `boxes[r]` is the bounding box of rank r's cells. Planes closer than `tolerance`
// (relative to the domain size) are the same plane. Throws DecompositionMismatch with
// a message that says what does not fit and which decomposition methods work.
ProcessorGrid processor_grid_from_boxes(const std::vector<Box>& boxes, int rank,
                                        const Box& domain, double tolerance = 1e-9);

}  // namespace grainflow::coupling
