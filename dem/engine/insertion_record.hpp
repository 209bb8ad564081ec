#pragma once
// What a checkpoint keeps of its run's insertions, so that a restart with a changed `insert`
// section stops instead of going on as another run than the one it says it continues.
//
// A restart inserts nothing at t = 0 (fills, csv and snapshot insertions are in the state
// already) and continues each stream from its delivered total. An insertion added, removed or
// changed in the scene before a restart was therefore skipped, or (a stream's rate) applied back
// to t = 0, delivering at once what the new rate owed since the start. The checkpoint stores
// the record below (dataset /streams/insertions); the restart compares it with the scene's and
// names the first insertion and key that differ.
#include <cstdint>
#include <string>
#include <string_view>

#include "dem/scene/scene.hpp"

namespace grainflow {

// One line per insertion of the scene, in its order: "kind=fill; material=glass;
// coarse_grain=2; seed=7; ...", every number to 17 significant digits, optional keys absent
// when not given. File names (csv, snapshot) are left out: a case folder may move between the
// run and its restart, and those insertions have been read into the state already.
std::string insertion_record(const Scene& scene);

// A 64-bit hash (FNV-1a) of insertion_record(scene), each material's name, density and
// coarse-graining factor, and the model record's lines (sorted): the same for every run of the same
// scene (whatever its output, time or parallel settings), different for another scene's run. Each
// snapshot carries it (root attribute `scene_fingerprint`), so that a restart continues only its
// own run's snapshot series.
std::uint64_t scene_fingerprint(const Scene& scene);

// Throws StateError (restored_state.hpp) when `written`, the record of the checkpoint
// `checkpoint_file`, differs from the scene's record: the message names the scene's insertion
// (its file:line), the first key that differs with both values, and what to do.
void check_insertions(const std::string& written, const Scene& scene,
                      const std::string& checkpoint_file);

// Throws StateError when `written`, the model record of the checkpoint `checkpoint_file`
// (Scene::model_record of the run that wrote it, dataset /scene/model), differs from the scene's:
// the message names the first key that differs (its file:line here), both values, and what to
// do. A restart continues its run with the run's model: a changed heat capacity made the
// particles' thermal energy jump by 37 % at the restart, a changed stiffness or friction would
// have gone on as another run under the same name. With `only` ("domain."), only the keys
// that start with it are compared.
void check_model(const std::string& written, const Scene& scene, const std::string& checkpoint_file,
                 std::string_view only = {});

}  // namespace grainflow
