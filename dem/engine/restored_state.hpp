#pragma once
// Checks of a state read from a file — a checkpoint (`grain run --restart`, a coupled
// restart) or a particle snapshot (`insert: {type: snapshot}`) — before the first step: the
// file's checksums (Fletcher32, verified by HDF5 as it reads) catch values changed after
// writing; these rules catch values that no run can have written. A broken rule stops the
// start with StateError naming the file, the dataset, the index and the rule; nothing is
// written or deleted before (docs/reliability.md, "What is checked on read").
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "dem/core/particles.hpp"
#include "dem/io/checkpoint.hpp"
#include "dem/scene/scene.hpp"

namespace grainflow {

// A state file that breaks a rule of restored_state.hpp (exit code 1 in `grain`).
class StateError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A particle's mass must equal rho (4/3) pi r^3 of its material within this relative
// tolerance: a mass written in single precision (relative error <= 6e-8) passes, a mass of
// another density or radius (off by far more than 1e-6) does not.
inline constexpr double kMassTolerance = 1e-6;

// Where the particles came from, for messages: "<file>: error: dataset '<group><name>',
// index i (particle id n): <rule>; <advice>".
struct StateSource {
  std::string file;
  std::string group;   // the datasets' prefix: "/particles/" (checkpoint) or "/" (snapshot)
  std::string advice;  // what to do, appended to every message
};

// The rules every particle of a state file obeys, in this order per particle: a finite
// position; a finite radius > 0; a material index in [0, materials); mass = rho V of its
// material (kMassTolerance); with `inertia`, inertia = 2/5 m r^2 (same tolerance); then
// ids > 0 and unique. Throws StateError at the first broken rule.
void check_particle_records(const Particles& p, const Scene& scene, const StateSource& source,
                            bool inertia);

// Everything of a checkpoint against the scene it continues: check_particle_records; every
// centre within [lo - s, hi + s] on every axis, s = the larger of its radius and half the
// neighbour skin (a centre drifts up to half a skin between the rebuilds that wrap periodic
// positions and remove particles past bounded sides; the skin as Simulation::initialise sets
// it, from the file's radii and `stream_max_radius`); next_id above every id; time, dt and
// step finite and non-negative (dt > 0); the implicit drag (when present) finite with K >= 0;
// every spring's particle an id of the file, its partner an id of the file or a wall history
// column below `wall_columns`, its tangential and rolling parts finite; `stream_counts`
// (particles each stream delivered, restored from the file) below next_id; the processor grid
// (when present): ranks >= 1, dims in [1, ranks] whose product is ranks, dims+1 planes per
// axis, strictly increasing, from the domain's lo to its hi exactly. Throws StateError.
void check_checkpoint(const CheckpointData& d, const Scene& scene, std::size_t wall_columns,
                      double stream_max_radius, const std::vector<long>& stream_counts);

// A restart continues with the checkpoint's step: the step counts of its snapshot, log and
// checkpoint series and of time.end are the run's (Simulation::restore takes it). A scene whose
// time.step differs from it would be silently ignored: refused instead (SetupError, naming
// time.step's line and the step to set). Called by `grain run --restart` and grainFoam.
void check_restart_step(const Scene& scene, const CheckpointData& d);

}  // namespace grainflow
