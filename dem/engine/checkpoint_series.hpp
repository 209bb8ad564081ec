#pragma once
// Periodic checkpoints of a run: <directory>/checkpoint_<step, 9 digits>.h5, keeping the
// newest K. An older file is deleted only after the new one has been renamed into place
// (Simulation::write_checkpoint), so at every moment at least one complete checkpoint exists.
#include <mpi.h>

#include <deque>
#include <string>
#include <vector>

namespace grainflow {

class Simulation;

class CheckpointSeries {
 public:
  // `adopt_up_to_step` >= 0 (a restarted run): the checkpoints already in `directory` with
  // step <= it count as the series' oldest members. Files of other runs are left alone.
  // Partial checkpoints (checkpoint_<step>.h5.part) that a killed run left behind are
  // deleted: they are never complete checkpoints (see removed_partial()).
  // With `record` (the scene's insertion_record, dem/engine/insertion_record.hpp) and `model`
  // (Scene::model_record), a checkpoint whose own record or model (its lines in any order)
  // differs was written by another scene's run: it is not adopted, so never deleted (see
  // foreign()); a checkpoint without a record predates it and is adopted. A later write over
  // such a file under the same name says so in warning().
  CheckpointSeries(MPI_Comm comm, std::string directory, int keep, long adopt_up_to_step = -1,
                   const std::string& record = {}, const std::string& model = {});

  // Collective: writes the checkpoint of the simulation's current step (which also rebuilds
  // its neighbour lists, see Simulation::write_checkpoint), then deletes the
  // oldest beyond `keep` (a failed deletion is reported in the returned warning, not fatal).
  // Returns the new checkpoint's path. Throws OutputError (every rank) if the write fails.
  std::string write(Simulation& sim);

  static std::string file_name(long step);  // checkpoint_000001234.h5
  const std::string& warning() const { return warning_; }
  // Rank 0: the partial checkpoints the constructor deleted (or could not delete: warning()).
  const std::vector<std::string>& removed_partial() const { return removed_partial_; }
  // The checkpoints up to the adopted step that another scene's run wrote, left alone.
  const std::vector<std::string>& foreign() const { return foreign_; }
  // The newest complete checkpoint of the series ("" when none), on every rank.
  const std::string& newest() const { return newest_; }
  // For a failed output write: how to continue ("The newest complete checkpoint is ...; ...
  // continue with: <command>", the command continuing from newest(), see continue_command in
  // run.hpp).
  std::string resume_hint(const std::string& command) const;

 private:
  MPI_Comm comm_;
  int rank_ = 0;
  std::string directory_;
  int keep_;
  std::deque<std::string> files_;  // oldest first (rank 0 only)
  std::string newest_;
  std::string warning_;
  std::vector<std::string> removed_partial_;
  std::vector<std::string> foreign_;
  std::string record_, model_;
  // Whether the checkpoint at `path` was written by another scene's run (see the constructor).
  bool is_foreign(const std::string& path) const;
};

}  // namespace grainflow
