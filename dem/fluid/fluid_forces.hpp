#pragma once
// The ForceTerm that applies a scene's fluid forces to every particle (one-way mode):
// drag implicitly through ImplicitDrag (re-evaluated each step with the particle's
// current velocity), the others explicitly. The drag law is chosen once, here, and
// compiled into the particle loop.
#include <mpi.h>

#include <memory>

#include "dem/engine/force_term.hpp"
#include "dem/fluid/prescribed_fluid.hpp"
#include "dem/scene/scene.hpp"

namespace grainflow {

// `gravity` is the scene's (for Archimedes buoyancy). Throws UnknownDragLaw or
// std::invalid_argument for settings the parser would have refused.
// With virtual_mass listed, this term must be the last one registered: it rescales the
// step's total force and implicit drag to the added-mass equation (virtual_mass.hpp).
// `domain` and `comm` serve a void fraction computed from the particles (collective).
std::unique_ptr<ForceTerm> make_fluid_forces(const FluidSettings& settings, const Vec3& gravity,
                                             const Domain& domain = Domain{},
                                             MPI_Comm comm = MPI_COMM_WORLD);

}  // namespace grainflow
