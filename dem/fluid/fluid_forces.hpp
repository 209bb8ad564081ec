#pragma once
// The ForceTerm that applies a scene's fluid forces to every particle (one-way mode):
// drag implicitly through ImplicitDrag (re-evaluated each step with the particle's
// current velocity), the others explicitly. The drag law is chosen once, here, and
// compiled into the particle loop.
#include <mpi.h>

#include <limits>
#include <memory>

#include "dem/engine/force_term.hpp"
#include "dem/fluid/coupled_fluid.hpp"
#include "dem/fluid/prescribed_fluid.hpp"
#include "dem/scene/scene.hpp"

namespace grainflow {

// The largest time step at which an explicit lift (a force across the slip, growing it at
// the rate 1/tau_l) together with the implicit drag (damping it at 1/tau_d) does not amplify
// the slip in one step: sqrt(1 + (dt/tau_l)^2) <= 1 + dt/tau_d, i.e.
// dt (1/tau_l^2 - 1/tau_d^2) <= 2/tau_d. Infinity when tau_l >= tau_d (any dt is stable).
inline double explicit_lift_limit(double tau_l, double tau_d) {
  if (!(tau_l < tau_d)) return std::numeric_limits<double>::infinity();
  return 2 / (tau_d * (1 / (tau_l * tau_l) - 1 / (tau_d * tau_d)));
}

// `gravity` is the scene's (for Archimedes buoyancy). Throws UnknownDragLaw or
// std::invalid_argument for settings the parser would have refused.
// With virtual_mass listed, this term must be the last one registered: it rescales the
// step's total force and implicit drag to the added-mass equation (virtual_mass.hpp).
// `domain` and `comm` serve a void fraction computed from the particles (collective).
std::unique_ptr<ForceTerm> make_fluid_forces(const FluidSettings& settings, const Vec3& gravity,
                                             const Domain& domain = Domain{},
                                             MPI_Comm comm = MPI_COMM_WORLD);

// Two-way mode: the fluid state comes from `coupled` (sampled by the coupling once per
// fluid step), not from settings.field, and the term writes back coupled->exchange_force.
// The coupled solver's pressure excludes the hydrostatic part, so the list must have
// buoyancy. virtual_mass is refused (the coupling does not sample Du/Dt yet).
// `comm`: the DEM ranks, over which report() sums its counts (collective then).
std::unique_ptr<ForceTerm> make_coupled_fluid_forces(const FluidSettings& settings,
                                                     const Vec3& gravity,
                                                     std::shared_ptr<CoupledFluid> coupled,
                                                     MPI_Comm comm = MPI_COMM_NULL);

}  // namespace grainflow
