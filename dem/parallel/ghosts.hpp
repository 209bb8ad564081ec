#pragma once
// Ghost particles: read-only copies of particles owned by other ranks (or periodic
// images of this rank's own), within the interaction range of this rank's box.
//
// A ghost keeps its owner's coordinates unchanged in `x` and its periodic image
// offset separately in `shift` (0 or ±L per axis); it sits at x + shift. Pair
// geometry is then computed as (x_a - x_b) + (shift_a - shift_b) on every rank, so
// both ranks of a pair that crosses a rank boundary get bit-identical forces.
#include <cstddef>
#include <vector>

#include "dem/core/types.hpp"

namespace grainflow {

struct Ghosts {
  std::vector<GlobalId> id;
  std::vector<Vec3> x, shift, v, omega;
  std::vector<Vec3> v_pred, omega_pred;  // the owner's Particles::v_pred and omega_pred
                                          // (empty unless the exchange carries them)
  std::vector<double> radius, mass, inertia;
  std::vector<int> material;

  std::size_t size() const { return id.size(); }
  Vec3 position(std::size_t k) const { return x[k] + shift[k]; }
  void clear() {
    id.clear();
    x.clear();
    shift.clear();
    v.clear();
    omega.clear();
    v_pred.clear();
    omega_pred.clear();
    radius.clear();
    mass.clear();
    inertia.clear();
    material.clear();
  }
};

}  // namespace grainflow
