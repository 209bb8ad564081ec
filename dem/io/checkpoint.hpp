#pragma once
// Checkpoints: the complete dynamic state of a run — every particle's state and
// every contact spring — in one HDF5 file that any number of ranks can read back.
//
// write_checkpoint gathers the ranks' parts on rank 0, which writes
// <path>.part and renames it to <path> once complete, so a crash mid-write never
// leaves a truncated checkpoint under the final name. read_checkpoint lets every
// rank read the whole file; the engine then keeps what each rank owns.
//
// Every dataset is chunked with a Fletcher32 checksum (hdf5_checksum.hpp), which HDF5
// verifies on reading: read_checkpoint names the dataset whose checksum fails. What the
// values must satisfy is checked by check_checkpoint (dem/engine/restored_state.hpp).
//
// Layout: attributes format ("grainflow-checkpoint-3"), time, dt, step, next_id, rebuilds,
// largest_radius, removed, attributes_checksum (attributes_checksum() below);
// /particles/{id, position, velocity, angular_velocity, force, torque, radius, mass,
// inertia, material} — force and torque are those of the step's end, which the next
// velocity-Verlet half kick uses (recomputing them would advance the springs twice);
// with heat transfer /particles/temperature;
// with fluid forces also /particles/{drag_coefficient, drag_fluid_velocity}, the
// implicit drag K and u of the step's end, which that half kick uses too (a coupled
// run cannot recompute them: they come from the fluid of the step before);
// /springs/{particle, partner, tangential, rolling}, where a wall spring
// has partner = -1 - wall index. A pair's spring may be listed once per partner;
// /streams/state (uint8 text, StreamInsertion::save_state(): the stream insertions'
// delivered totals, radii drawn but not placed and generator states);
// /scene/model (uint8 text, optional: the run's Scene::model_record, which a restart's scene
// must equal);
// /log/table (uint8 text, optional: the run's log.csv up to this step, LogTable::record(), which
// a restart makes its log.csv whatever the folder's file holds);
// /decomposition/{ranks, dims, cuts_x, cuts_y, cuts_z}: the processor grid the run used when
// it wrote the file — its rank count, ranks per axis and each axis's dims+1 cut planes from
// the domain's lo to its hi — so that a restart on as many ranks continues on the same boxes
// (docs/parallel.md, "The default grid"). Format 1 files (before stream state was saved)
// have no /streams group; format 1 and 2 files have no /decomposition group.
#include <mpi.h>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "dem/core/particles.hpp"
#include "dem/io/output_directory.hpp"

namespace grainflow {

struct CheckpointSpring {
  GlobalId particle;
  GlobalId partner;  // global id of the other particle, or -1 - wall index
  Vec3 tangential;
  Vec3 rolling;
};

// The processor grid of the run that wrote a checkpoint.
struct CheckpointGrid {
  int ranks = 1;                            // MPI ranks of that run
  std::array<int, 3> dims{1, 1, 1};         // ranks per axis
  std::array<std::vector<double>, 3> cuts;  // per axis: dims+1 planes, lo .. hi
};

struct CheckpointData {
  double time = 0;
  double dt = 0;
  long step = 0;
  GlobalId next_id = 1;
  // Neighbour-list rebuilds before this checkpoint: they pace `parallel.balance` (every 10th
  // rebuild checks the load), so a restart continues the balancing bit for bit. Root
  // attribute `rebuilds`, optional (0 when absent: files written before it).
  long rebuilds = 0;
  // The interaction range's radius the run chose at its start (Simulation::initialise: the
  // largest radius present or to come from a stream), which sets the default skin, the bins and
  // the ghost width. A restart takes it (or a larger one), so that a run whose largest particle
  // left the domain continues with the lists of the uninterrupted run. Root attribute
  // `largest_radius`, optional (absent: files written before it, or before the first step).
  std::optional<double> largest_radius;
  // The Verlet skin the run used (neighbour.skin, or its default), by which a centre may have
  // drifted past the domain's sides since the last rebuild: a restart with a smaller skin
  // accepts the run's positions. Root attribute `skin`, optional (absent: files written before
  // it; written with largest_radius).
  std::optional<double> skin;
  // How the run set its step: time.rayleigh_fraction's value, or 0 when it gave time.step.
  // A restart keeps the run's step, and refuses a scene that sets it otherwise
  // (check_restart_step). Root attribute `rayleigh_fraction`, optional (absent: files written
  // before it, not checked then).
  std::optional<double> rayleigh_fraction;
  // Particles that left through a bounded side before this checkpoint, over all ranks: the
  // restart's log and summary count on from it. Root attribute `removed`, optional (0).
  long removed = 0;
  Particles particles;
  // The implicit drag of the step's end, aligned with `particles`; empty when the run
  // has no fluid forces.
  std::vector<double> drag_coefficient;
  std::vector<Vec3> drag_fluid_velocity;
  std::vector<CheckpointSpring> springs;
  // Whether particles.temperature is part of the state (the run had heat on): written as
  // /particles/temperature, read back when present.
  bool has_temperature = false;
  // The stream insertions' progress (taken from rank 0 when writing); absent in a format 1
  // file, which cannot continue a scene with streams.
  std::optional<std::string> streams;
  // The run's insertions (insertion_record, dem/engine/insertion_record.hpp), compared with
  // the scene's on restart; the dataset /streams/insertions, absent in files written before it
  // (not checked then).
  std::optional<std::string> insertions;
  // The run's model (Scene::model_record), compared with the scene's on restart; dataset
  // /scene/model, absent in files written before it (not checked then).
  std::optional<std::string> model;
  // The run's log table up to this step (header and rows, as log.csv holds them; taken from
  // rank 0 when writing); absent in files written before it and in grainFoam's checkpoints.
  std::optional<std::string> log;
  // The processor grid (taken from rank 0 when writing); absent in format 1 and 2 files.
  std::optional<CheckpointGrid> grid;
  // Each material index's coarse-graining factor and listed material (Scene's materials:
  // Material::coarse_grain, Material::real_material or the index itself), written as root
  // attributes; empty in a file written before they were, which is then not checked for them.
  std::vector<double> material_coarse_grain;
  std::vector<int> material_real;
  // output.wall_loads: the time integral of each wall's contact forces on the particles
  // since the last log row (x, y, z per wall, summed over ranks), then that time span;
  // the root attribute `wall_impulse`, absent (empty) in a run without wall loads.
  std::vector<double> wall_impulse;
  // The root attributes have no HDF5 checksum of their own (only datasets are filtered): a
  // flipped bit of time, dt, step, next_id, rebuilds or the arrays above would pass every rule
  // that can be checked. The writer stores attributes_checksum(*this) as the root attribute
  // `attributes_checksum`; read_checkpoint sets `attributes_checksum_stored` to it and
  // `attributes_checksum_read` to the checksum of the values it read. Both are empty for a file
  // written before the attribute was (not checked then).
  std::optional<std::uint32_t> attributes_checksum_stored, attributes_checksum_read;
  std::string file;  // set by read_checkpoint: where it came from, for messages
};

// The Fletcher32 checksum (hdf5_checksum.hpp) of the root attributes' values, in a fixed
// order and width: time, dt, step, next_id, rebuilds, then the material count and each
// material's coarse_grain and listed material, then the wall_impulse count and values, then
// (when the file has them) largest_radius and removed (as doubles and 64-bit integers,
// little-endian).
std::uint32_t attributes_checksum(const CheckpointData& d);

// Collective. `local` holds this rank's particles and springs; time, dt, step and
// next_id are taken from rank 0. Throws OutputError (on every rank) on failure.
void write_checkpoint(MPI_Comm comm, const std::string& path, const CheckpointData& local);

// Reads the whole checkpoint (not collective). Throws OutputError naming the file
// and what is wrong with it.
CheckpointData read_checkpoint(const std::string& path);

// Whether the HDF5 file at `path` is a particle snapshot (datasets at its root, no
// checkpoint `format` attribute), told by its contents, not its name; false when it cannot
// be opened (read_checkpoint then names what is wrong).
bool is_particle_snapshot(const std::string& path);

// The record of the run's insertions (/streams/insertions) of the checkpoint at `path`, without
// reading the rest; empty when the file cannot be read or holds no record.
std::optional<std::string> read_checkpoint_insertions(const std::string& path);
// The same for the run's model record (/scene/model, Scene::model_record).
std::optional<std::string> read_checkpoint_model(const std::string& path);

}  // namespace grainflow
