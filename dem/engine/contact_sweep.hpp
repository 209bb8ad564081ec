#pragma once
// One pass over all contacts (particle pairs from the neighbour list, then
// particle-wall), adding forces and torques. The contact law is chosen once per
// run: select_sweep() returns the instantiation for the scene's slot choice, so
// the per-contact code holds no branch on model names and no virtual call.
#include <string>
#include <vector>

#include "dem/contact/contact_geometry.hpp"
#include "dem/contact/pair_coefficients.hpp"
#include "dem/core/particles.hpp"
#include "dem/neighbour/verlet_list.hpp"
#include "dem/scene/scene.hpp"

namespace grainflow {

struct ContactSweep {
  Particles& p;
  const NeighbourList& list;
  std::vector<ContactHistory>& pair_history;               // parallel to list.j
  const std::vector<Wall>& walls;
  std::vector<std::vector<ContactHistory>>& wall_history;  // [wall][particle]
  const PairTable& table;
  const ContactConstants& constants;
  const Box& box;
  double dt;
  // results of the sweep
  long contacts = 0;
  double max_overlap_ratio = 0;  // overlap / smaller radius
};

using SweepFunction = void (*)(ContactSweep&);

struct SweepChoice {
  SweepFunction run;
  bool has_history;  // pair/wall histories must be kept
  bool needs_spin;   // torques are produced
  std::string name;  // e.g. "hertz + history + none + none"
};

SweepChoice select_sweep(const ContactSettings& settings, bool periodic);

}  // namespace grainflow
