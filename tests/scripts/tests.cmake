# Tests of the analysis scripts (included by tests/CMakeLists.txt): scripts/h5_summary.py and
# scripts/plot_log.py on the files tiny `grain run` scenes write (50 beads or 20 parcels,
# 0.02 s; each test runs in about 2-4 s). tests/scripts/scripts_test.py writes the scenes into
# the test's work folder, runs grain and the script, and checks the output; each case is a
# function there.
#
# scripts.h5_summary_folder: a folder holding a checkpoint (50 beads, stored under
#   /particles/) and the snapshots of a later, shorter run of 30 beads over the first run's
#   five: the three snapshots particles.xdmf lists are summarised (30 particles each), the two
#   left over are counted and named, the checkpoint reports its 50 particles and is marked as
#   another run's; without particles.xdmf the newest file's scene_fingerprint decides; a
#   folder without .h5 files, a file that is not HDF5, and HDF5 files that are neither a
#   snapshot nor a checkpoint (empty; /particles a dataset) are one-line errors, exit 1; material
#   indices 2^30, -1 and 7 are each said to be not in material_names (no hang, no wrap-around).
# scripts.h5_summary_coarse_grain: 20 parcels of k = 2 (snapshot and checkpoint): k, the 20
#   parcels and the 160 = 20 x 2^3 real particles they stand for, the real radius = parcel
#   radius / 2 within the insertion's 0.4-0.6 mm, the material as glass[k=2]; a k = 1 run
#   keeps the plain summary (material by name); a real_count or coarse_grain of 0 is a
#   one-line error naming the file and dataset, exit 1.
# scripts.h5_summary_no_index: a folder without particles.xdmf holding two runs of one scene
#   (same scene_fingerprint; 0.02 s, then 0.01 s): only the second run's 3 snapshots (its own
#   index, read before removal, is the reference), the 2 past the end of its log.csv named as
#   ones it cannot tell apart; without log.csv it says it cannot tell runs of one scene
#   apart; an index cut in half: the run's 5 snapshots, the damaged index named with its
#   remedy, a restart from the checkpoint, which the test runs and which rewrites the index.
# scripts.h5_summary_unreadable_snapshot: a run's own snapshot cut to 1000 bytes, reported as a
#   gap by the restart from its checkpoint, is named as unreadable (damaged or truncated) and
#   a gap, with and without particles.xdmf, not as another run's; the 4 others summarised.
# scripts.plot_log_bad_inputs: a missing log, a folder, an HDF5 file, a file that is not a
#   log, -o into a missing folder or onto a folder, -o with an extension matplotlib cannot
#   write (.xyz, .txt), -o the log itself, an unknown column: each exit 1 with one line naming
#   it, no Python traceback; a log with a byte-order mark plots, and a field over csv's
#   131072-character limit (in a row: that row skipped; in the header) is no traceback; -o
#   without an extension writes and names <name>.png.
# scripts.plot_log_damaged_row: a damaged row at line 51 and a last row cut short are left out
#   and reported by line number; the other rows are plotted.
grainflow_find_python(GRAINFLOW_SCRIPTS_PYTHON "h5py,numpy,matplotlib" "the scripts.* tests are")
if(NOT GRAINFLOW_SCRIPTS_PYTHON)
  return()
endif()

foreach(_case h5_summary_folder h5_summary_coarse_grain h5_summary_no_index
              h5_summary_unreadable_snapshot plot_log_bad_inputs plot_log_damaged_row)
  add_test(NAME scripts.${_case}
           COMMAND ${GRAINFLOW_SCRIPTS_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/scripts_test.py ${_case}
                   --grain $<TARGET_FILE:grain>
                   --work ${PROJECT_BINARY_DIR}/test_output/scripts/${_case})
  set_tests_properties(scripts.${_case} PROPERTIES
    ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV};GRAINFLOW_PYTHON_CHOSEN=1"
    LABELS "scripts"
    TIMEOUT 120)
endforeach()
