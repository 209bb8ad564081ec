#pragma once
// Drag laws chosen by name (the scene's `fluid.drag`). The registry is read once at
// set-up; the per-particle loop calls the chosen law through a template parameter
// (dem/fluid/fluid_forces.cpp), never through this table.
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "dem/fluid/drag_input.hpp"

namespace grainflow {

using DragFunction = double (*)(const DragInput&);

struct DragLaw {
  const char* name;       // as written in a scene
  DragFunction function;  // K [kg/s] of F = K (u_f - v)
  const char* source;     // paper, for logs and docs
  bool total_force_fit;   // normalised as the total force (mean-pressure part removed by ε)
  // The largest Reynolds number (the law's own: superficial ρ_f ε d U/μ, or the single
  // sphere's for schiller_naumann) of the data the law was fitted to or derived for; the run
  // counts the particle-steps beyond it and warns (docs/models/fluid-forces.md, "Validity").
  double fitted_reynolds;
  const char* fitted_range;             // where that bound comes from, for the warning
  bool single_sphere_reynolds = false;  // Re without ε (schiller_naumann)
};

// Every law, in the order the docs list them.
const std::vector<DragLaw>& drag_laws();
std::vector<std::string> drag_law_names();

class UnknownDragLaw : public std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// The law called `name`; an unknown name throws UnknownDragLaw whose message lists
// every valid name.
const DragLaw& drag_law(std::string_view name);

}  // namespace grainflow
