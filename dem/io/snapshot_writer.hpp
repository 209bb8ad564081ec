#pragma once
// Particle snapshots: one HDF5 file per output time, written collectively by all ranks through
// MPI-IO (each rank writes its own contiguous slice, rank 0's particles first), plus an XDMF
// index that ParaView opens as a time series of point clouds.
//
// File layout (see snapshot_fields in xdmf_index.hpp), N = global particle count:
//   /id (int64, N)  /position, /velocity, /angular_velocity (double, N x 3)
//   /radius, /diameter, /mass (double, N)  /material (int32, N)
//   on request (the writer's field set): /force, /torque, /fluid_force (double, N x 3),
//   /coordination (int32, N), /overlap_max (double, N)
//   each dataset is chunked with a Fletcher32 checksum (hdf5_checksum.hpp) and has a string
//   attribute "units"; the root group has the attributes
//   time (double, s), step (int64), count (int64, = N) and grainflow_version (string).
//   With a contact network (write()'s `contacts`): the groups /contacts and /wall_contacts
//   (contact_network.hpp).
#include <mpi.h>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "dem/core/particles.hpp"
#include "dem/io/contact_network.hpp"
#include "dem/io/output_directory.hpp"
#include "dem/io/xdmf_index.hpp"
#include "dem/io/xdmf_index_file.hpp"

namespace grainflow {

// The fields of a snapshot that are not particle state, one value per local particle, in the
// particles' order (Simulation::snapshot_extras); a field the writer does not write may be
// left empty.
struct SnapshotExtras {
  std::vector<Vec3> force;          // total force of the step's end [N]
  std::vector<Vec3> torque;         // total torque of the step's end [N m]
  std::vector<int> coordination;    // touching contacts (particles and walls)
  std::vector<Vec3> fluid_force;    // the fluid's force [N] (zero without fluid)
  std::vector<double> overlap_max;  // largest overlap / smaller radius of its contacts
};

class SnapshotWriter {
 public:
  // `directory` must exist (prepare_output_directory). Files are named
  // <directory>/<basename>_<6-digit index>.h5 and the index <directory>/<basename>.xdmf.
  // `fields`: the datasets each file holds (id and position always).
  SnapshotWriter(MPI_Comm comm, std::string directory, std::string basename = "particles",
                 SnapshotFieldSet fields = snapshot_default_fields);

  // Collective over the communicator: every rank calls it with its own particles (possibly
  // none) and the same time and step. Writes the next snapshot file (under a temporary name,
  // renamed when complete), then adds it to the XDMF index: the first write of this writer
  // (and the first after continue_series) writes the index whole and renames it into place,
  // later ones append one time step in O(1) bytes, the file staying valid if the run is
  // killed at any moment (xdmf_index_file.hpp). Returns the snapshot's path. On any failure every
  // rank throws the same OutputError (naming the file, the failing operation, the HDF5/OS reason
  // and the rank). `extras` must hold every field of the set beyond the default ones, sized
  // p.size() (std::logic_error otherwise).
  // `contacts`: the contact network to write with it (contact_network.hpp), this rank's part;
  // given on every rank or on none.
  std::string write(const Particles& p, double time, long step, const SnapshotExtras& extras = {},
                    const ContactNetwork* contacts = nullptr);

  // Continues an existing series (a restarted run): takes the snapshots already in the
  // directory, in number order, up to the first one past `up_to_step` or of another scene's
  // run, so the next write() gets the number after the last one taken and later files of a
  // stopped run are overwritten. A number missing or unreadable before the last one taken is a
  // gap (missing()); the files after it are taken over. So is one missing or unreadable after
  // the last one taken that particles.xdmf dates at or before `up_to_time` (the checkpoint's
  // time plus half a step): its number is the series', and reusing it would number every later
  // snapshot otherwise than the uninterrupted run does. One the index does not date is
  // written again (reused()). Every rank reads the files' attributes (no communication).
  // Returns how many.
  std::size_t continue_series(long up_to_step, double up_to_time);
  // After continue_series: the gaps it stepped over ("particles_000003.h5 (missing)" or
  // "(unreadable)").
  const std::vector<std::string>& missing() const { return missing_; }
  // After continue_series: files missing or unreadable after the last one taken whose numbers
  // the restart writes again, as the index did not say they came before the checkpoint.
  const std::vector<std::string>& reused() const { return reused_; }

  std::size_t snapshots_written() const { return entries_.size(); }
  // The series' entries so far (after continue_series: the snapshots it took over).
  const std::vector<XdmfEntry>& entries() const { return entries_; }
  std::string index_path() const;
  SnapshotFieldSet fields() const { return fields_; }

  // Each material's coarse-graining factor and listed material (Scene::coarse_grain_table,
  // Scene::real_material_table) for the fields coarse_grain and real_count, and for the root
  // attributes material_coarse_grain and material_real, by which a snapshot insertion maps
  // the parcel classes to its own scene's; empty (the default): every particle is a real one.
  void set_coarse_grain(std::vector<double> per_material, std::vector<int> real_material) {
    coarse_grain_ = std::move(per_material);
    real_material_ = std::move(real_material);
  }
  // The scene's material names (parcel classes included), in material-index order, written as
  // the root attribute `material_names` (the names joined by commas, which a name never
  // holds): a snapshot insertion maps the stored indices onto its own scene's materials by
  // name, so a scene that lists them in another order keeps each particle's material.
  void set_material_names(const std::vector<std::string>& names) {
    material_names_.clear();
    for (const std::string& name : names)
      material_names_ += (material_names_.empty() ? "" : ",") + name;
  }
  // The scene's fingerprint (scene_fingerprint, dem/engine/insertion_record.hpp), written as
  // the root attribute `scene_fingerprint` of each snapshot (0: none). continue_series stops at
  // a file that carries another fingerprint: another scene's run wrote it.
  void set_scene_fingerprint(std::uint64_t fingerprint) { fingerprint_ = fingerprint; }
  // After continue_series: the first file it left out because another scene's run wrote it
  // ("" when none).
  const std::string& foreign_file() const { return foreign_file_; }
  // The series' files in the folder numbered at or after the next one write() would make,
  // in number order: after a restart's run, those the stopped run wrote after its checkpoint
  // and this run did not write over (another snapshot interval, an earlier end).
  std::vector<std::string> files_after_series() const;
  // The series' files in the folder (<basename>_NNNNNN.h5) with their numbers, in order.
  std::vector<std::pair<long, std::string>> numbered_files() const;
  // The time of each snapshot particles.xdmf lists, by name without ".h5" (empty without it).
  std::map<std::string, double> index_times() const;

 private:
  std::vector<double> coarse_grain_;
  std::vector<int> real_material_;
  std::uint64_t fingerprint_ = 0;
  std::string material_names_;
  std::string foreign_file_;
  std::vector<std::string> missing_;
  std::vector<std::string> reused_;
  long next_number_ = 0;  // the number of the next file write() makes
  MPI_Comm comm_;
  int rank_ = 0;
  int size_ = 1;
  bool gather_ = false;  // several ranks on one node: rank 0 writes what they gather to it
  std::string directory_;
  std::string basename_;
  SnapshotFieldSet fields_;
  std::vector<XdmfEntry> entries_;
  std::unique_ptr<XdmfIndexFile> index_;  // rank 0: the open index, once written
};

}  // namespace grainflow
