#pragma once
// The NaN / Inf guard: one pass over positions, velocities and spins after each step, so a
// blow-up stops the run at the first bad step, naming the particle, instead of writing
// snapshots full of NaN (or crashing later in the binning of a NaN position).
#include <mpi.h>

#include <string>

#include "dem/core/particles.hpp"

namespace grainflow {

// With heat on (`temperatures`), a temperature that is not finite or not above 0 K counts as
// well: a fixed heat flow out of a particle (a wall's negative heat_flux, a negative
// heat_source) is not bounded by its temperature, and ran on below 0 K.

// Collective: true on every rank when any rank holds a particle whose position, velocity or
// angular velocity is not finite. One MPI_Allreduce of an int.
bool non_finite_anywhere(const Particles& p, MPI_Comm comm);
// The same from each rank's own answer (`local_bad`: this rank holds a non-finite state).
bool non_finite_anywhere(bool local_bad, MPI_Comm comm);
// Whether p holds a non-finite position, velocity or angular velocity, or with
// `temperatures` a temperature not finite or not above 0 K (no communication).
bool has_non_finite(const Particles& p, bool temperatures = false);
// Whether every temperature is finite and above 0 K (no communication).
bool temperatures_positive(const Particles& p);

// This rank's first such particle described for the user (id, rank, step, time, position,
// velocity, angular velocity, force and torque), or "" when this rank has none. Local.
// `force_terms`: the force terms enabled with their dt / time-scale ratios
// (Simulation::force_limits_summary), or "" when the run has none.
std::string describe_first_non_finite(const Particles& p, long step, double time, int rank,
                                      const std::string& force_terms = "",
                                      bool temperatures = false);

class Simulation;

// The guard of a run (`grain run`, the coupled DEM): when any rank holds a non-finite
// particle, writes every particle of this step to <directory>/diagnostic_<n>.h5 and throws
// the same ParallelError on every rank, describing the first bad particle. `local_bad`:
// this rank holds a non-finite state (after a step, Simulation::state_finite() knows it
// without another pass). Collective.
void guard_finite(const Simulation& sim, bool local_bad, const std::string& directory,
                  MPI_Comm comm);
// The guard after Simulation::step(), which has already agreed on every rank whether all
// states are finite (Simulation::state_finite_everywhere, in the step's one reduction):
// communicates only when one is not. Collective.
void guard_finite_after_step(const Simulation& sim, const std::string& directory, MPI_Comm comm);

}  // namespace grainflow
