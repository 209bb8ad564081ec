#pragma once
// Ghost particles: read-only copies of particles owned by other ranks (or periodic
// images of this rank's own), within the interaction range of this rank's box.
//
// A ghost keeps its owner's coordinates unchanged in `x` and its periodic image
// offset separately in `shift` (0 or ±L per axis); it sits at x + shift. Pair
// geometry is then computed as (x_a - x_b) + (shift_a - shift_b) on every rank, so
// both ranks of a pair that crosses a rank boundary get bit-identical forces.
#include <cstddef>
#include <array>
#include <vector>

#include "dem/contact/contact_geometry.hpp"
#include "dem/core/types.hpp"

namespace grainflow {

struct Ghosts {
  std::vector<GlobalId> id;
  std::vector<Vec3> x, shift, v, omega;
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
    radius.clear();
    mass.clear();
    inertia.clear();
    material.clear();
  }
};

// Contact springs of one particle with one partner, keyed by the partner's global id:
// the form in which springs travel with a migrating particle.
struct PartnerHistory {
  GlobalId partner;
  ContactHistory history;
};

// Per-particle data that moves with its particle between ranks (and is permuted
// and compacted with it).
struct CarriedState {
  std::vector<std::vector<ContactHistory>> wall;  // [wall][particle]
  std::vector<std::vector<PartnerHistory>> pairs; // [particle]
  // The implicit drag (K, u) of the step's end, [particle]; carried only across the
  // rebuild after a checkpoint, where the next half kick still needs it. The flag is
  // the same on every rank (a rank may hold no particles).
  bool carries_drag = false;
  std::vector<std::array<double, 4>> drag;
};

}  // namespace grainflow
