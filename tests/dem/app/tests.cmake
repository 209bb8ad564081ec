# Command-level tests of `grain`: what a user types and sees.
set(_grain $<TARGET_FILE:grain>)
set(_expect ${CMAKE_CURRENT_LIST_DIR}/expect_command.cmake)
set(_scenes ${PROJECT_SOURCE_DIR}/tests/data/scenes)
set(_work ${PROJECT_BINARY_DIR}/test_output/grain)

function(grain_cli_test name code regex)
  cmake_parse_arguments(ARG "" "WORKDIR;FORBID" "CMD;FILES" ${ARGN})
  # Lists travel to the script joined by '|' (a ';' would split add_test's arguments).
  string(REPLACE ";" "|" cmd "${ARG_CMD}")
  string(REPLACE ";" "|" files "${ARG_FILES}")
  string(REPLACE ";" "|" regex "${regex}")
  add_test(NAME grain.${name}
           COMMAND ${CMAKE_COMMAND} "-DCMD=${cmd}" -DEXPECT_CODE=${code} "-DEXPECT_REGEX=${regex}"
                   "-DFORBID_REGEX=${ARG_FORBID}" "-DWORKDIR=${ARG_WORKDIR}" "-DEXPECT_FILES=${files}"
                   -P ${_expect})
  set_tests_properties(grain.${name} PROPERTIES ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}")
endfunction()

# The contact-time error of the pair whose contact time suffers most, named when it is not
# the pair of the worst restitution error.
grain_cli_test(check_names_the_contact_time_pair 0
               "restitution error ≈ 3.3 % \\(worst ≈ 3.9 %\\), contact-time error ≈ 0.43 % \\(s-wall 'floor', 17.7 steps, e = 0.9\\) \\(s-L at 1 m/s, e = 0.1"
               CMD ${_grain} check ${_scenes}/mixed_pairs_accuracy.yaml)
grain_cli_test(version 0 "grain \\(grainflow\\) [0-9]+\\.[0-9]+\\.[0-9]+" CMD ${_grain} --version)
grain_cli_test(help 0 "usage: grain" CMD ${_grain} --help)
grain_cli_test(no_command 2 "no command given" CMD ${_grain})
grain_cli_test(unknown_command 2 "unknown command 'frobnicate'; allowed: run, check" CMD ${_grain} frobnicate)
grain_cli_test(unknown_option 2 "unknown option '--fast' for 'run'" CMD ${_grain} run x.yaml --fast)
# Options: before or after the scene, `--key value` or `--key=value`, each at most once; a
# missing value and a run option given to check are named as such.
grain_cli_test(option_without_value 2 "option '--restart' needs a value: --restart CHECKPOINT.h5"
               CMD ${_grain} run x.yaml --restart)
grain_cli_test(option_given_twice 2 "option '--output' is given twice; give it once"
               CMD ${_grain} run x.yaml --output a --output b)
grain_cli_test(run_option_to_check 2 "option '--output' is for 'run'; 'check' takes the scene file and --restart"
               CMD ${_grain} check x.yaml --output o)
grain_cli_test(two_scene_files 2 "'run' takes one scene file, got 'a.yaml' and 'b.yaml'"
               CMD ${_grain} run a.yaml b.yaml)
grain_cli_test(options_before_scene 0 "done: 2000 steps, 1 particles \\(0 removed\\)"
               CMD ${_grain} run --output=out --no-progress ${_scenes}/fluid/lone_bead.yaml
               WORKDIR ${_work}/options_before_scene FILES out/log.csv)
# time.end between two steps (2.5 steps): check and run agree on 2 steps and say that the run
# ends at t = 8e-4 s, not at time.end; the log's last row is at that time.
grain_cli_test(check_end_between_steps 0
               "steps to reach t_end = 0.001 s: 2 \\(end / step = 2.5 is not whole.*ends at t = 0.0008 s\\)"
               CMD ${_grain} check ${_scenes}/end_between_steps.yaml)
grain_cli_test(run_end_between_steps 0
               "note: time.end / step = 2.5 is not whole: the run takes 2 steps, the nearest whole number, and ends at t = 0.0008 s;done: 2 steps"
               CMD ${_grain} run ${_scenes}/end_between_steps.yaml --output out --no-progress
               WORKDIR ${_work}/end_between_steps)
# The environment variables grain reads: a value it would not take is refused by name at
# start-up (it had failed at the first snapshot, or been taken for 0).
grain_cli_test(bad_buffered_writes 1
               "GRAINFLOW_BUFFERED_WRITES is 'yes'; allowed values: 0 .* or 1"
               CMD env GRAINFLOW_BUFFERED_WRITES=yes ${_grain} check ${_scenes}/minimal.yaml)
grain_cli_test(bad_snapshot_mpiio 1
               "GRAINFLOW_SNAPSHOT_MPIIO is 'yes'; allowed values: 0 .* or 1"
               CMD env GRAINFLOW_SNAPSHOT_MPIIO=yes ${_grain} run ${_scenes}/minimal.yaml --output out
               WORKDIR ${_work}/bad_snapshot_mpiio)
grain_cli_test(missing_scene_file 2 "no_such.yaml: error: cannot open the scene file"
               CMD ${_grain} check ${_scenes}/no_such.yaml)
grain_cli_test(check_minimal 0 "Rayleigh time t_R = ;contact time t_c = ;steps per impact"
               CMD ${_grain} check ${_scenes}/minimal.yaml)
# The travel guard's speed for the smallest bead: r / dt = 0.4004 mm / (0.07 t_R), with
# t_R = pi r sqrt(rho / G) / (0.1631 nu + 0.8766) = 4.896e-5 s (DESIGN.md §3): 116.8 m/s.
# One bead in a periodic column of water, nothing it could touch: no contact law, no
# interactions, no elastic constants in the scene; grain check says none is needed.
grain_cli_test(check_lone_bead 0
               "contact law: none needed;no contact can happen \\(no walls, one particle\\)"
               CMD ${_grain} check ${_scenes}/fluid/lone_bead.yaml)
# The same bead with the step as a Rayleigh fraction: no contact can happen, so there is no
# Rayleigh time to size it by, and the error says why (it said the scene had no particles).
grain_cli_test(check_lone_bead_rayleigh 1
               "lone_bead_rayleigh.yaml:10: error: time.rayleigh_fraction sizes the step by the Rayleigh time of the contacts, and no contact can happen in this scene \\(1 particle\\(s\\), no walls\\); give time.step instead"
               CMD ${_grain} check ${_scenes}/fluid/lone_bead_rayleigh.yaml)
grain_cli_test(run_lone_bead 0 "done: 2000 steps, 1 particles \\(0 removed\\)"
               CMD ${_grain} run ${_scenes}/fluid/lone_bead.yaml --output out --no-progress
               WORKDIR ${_work}/lone_bead)
grain_cli_test(check_reports_travel_limit 0
               "travel guard: a particle that moves more than 1 x its radius in one step stops the run [(]key time.max_step_travel[)]: above 116.[78] m/s for the smallest"
               CMD ${_grain} check ${_scenes}/minimal.yaml FORBID "warning")
grain_cli_test(check_warns_travel_limit 0
               "above 116.[78] m/s for the smallest.*; warning: that is below time.expected_max_speed = 150 m/s"
               CMD ${_grain} check ${_scenes}/fast_impacts.yaml)
# The time step placed on the measured accuracy curve (docs/accuracy-vs-cost.md):
# minimal.yaml runs at 0.07 t_R with e = 0.9 between its glass beads, with the default dashpots:
# the check also quotes the table of contact.dashpot_velocity: predicted. (';' separates the
# regexes that must all match.)
grain_cli_test(check_reports_accuracy 0
               "dt = 0.07 t_R, [0-9.]+ steps per impact: restitution error .+ [0-9.e-]+ % \\(worst .+ [0-9.e-]+ %\\), contact-time error .+ [0-9.e-]+ % \\(glass-glass at 1 m/s, e = 0.9;measured, docs/accuracy-vs-cost.md\\);with `contact: {dashpot_velocity: predicted}` .+ the restitution error at this dt would be .+ [0-9.e-]+ % and the contact-time error .+ [0-9.e-]+ %"
               CMD ${_grain} check ${_scenes}/minimal.yaml)
grain_cli_test(bad_restitution 2 "bad/restitution.yaml:13:[0-9]+: error: .*restitution.*value 1.2 is out of range.*\\(0, 1\\]"
               CMD ${_grain} check ${_scenes}/bad/restitution.yaml)
grain_cli_test(bad_model_name 2 "bad/model_name.yaml:[0-9]+:[0-9]+: error: .*'hertzz'; allowed: hertz, hooke"
               CMD ${_grain} run ${_scenes}/bad/model_name.yaml WORKDIR ${_work}/bad_model
               FORBID "Rayleigh")
grain_cli_test(refuses_huge_time_step 1 "error: dt is too large;refusing to run with this time step"
               CMD ${_grain} run ${_scenes}/bad/huge_time_step.yaml --no-progress
               WORKDIR ${_work}/huge_dt)
# The particles a stream will insert set the time step as those present do: t_R of a 0.1 mm
# glass bead, 0.1224 r = 1.224e-5 s (DESIGN.md §3), not the 2 mm fill's (found by the
# restart check of the hard-scene generator: such a run ended "done" with the streamed
# beads' contacts unresolved, and its restart from a checkpoint was refused).
grain_cli_test(refuses_step_too_large_for_streamed_particles 1
               "Rayleigh time t_R = 1.224e-05 s [(]smallest 'glass' particle, of the stream at [^)]*stream_unresolved.yaml:17[)];error: dt is too large to resolve contacts;would refuse this time step; use dt <= 2.69e-06 s"
               CMD ${_grain} check ${_scenes}/bad/stream_unresolved.yaml)
grain_cli_test(run_refuses_step_too_large_for_streamed_particles 1
               "error: refusing to run with this time step [(]see above[)]; use dt <= 2.69e-06 s"
               CMD ${_grain} run ${_scenes}/bad/stream_unresolved.yaml --no-progress
               WORKDIR ${_work}/stream_unresolved)
grain_cli_test(unwritable_output 1 "/etc/hostname/out"
               CMD ${_grain} run ${_scenes}/minimal.yaml --output /etc/hostname/out)
grain_cli_test(run_periodic_bed 0 "done: [0-9]+ steps, 300 particles \\(0 removed\\);particles.xdmf"
               CMD ${_grain} run ${_scenes}/periodic_bed.yaml --output out --no-progress
               WORKDIR ${_work}/run_periodic_bed
               FILES out/particles.xdmf out/log.csv out/particles_000000.h5 out/particles_000010.h5)
# open_sides.yaml has a floor but no side walls: beads that bounce out over the sides
# must be removed, counted and reported, never silently dropped.
grain_cli_test(reports_removed_particles 0
               "particle\\(s\\) left the domain through a bounded side and were removed;done: [0-9]+ steps, [0-9]+ particles \\([1-9][0-9]* removed\\)"
               CMD ${_grain} run ${_scenes}/open_sides.yaml --output out --no-progress
               WORKDIR ${_work}/reports_removed)
# The scene of docs/scene-reference.md's example does what its comment says: no bead lost.
grain_cli_test(runs_minimal_example 0 "done: [0-9]+ steps, 500 particles \\(0 removed\\)"
               CMD ${_grain} run ${_scenes}/minimal.yaml --output out --no-progress
               WORKDIR ${_work}/runs_minimal FORBID "warning")
grain_cli_test(runs_on_two_ranks 0 "MPI ranks: 2 as a;done: [0-9]+ steps, 300 particles \\(0 removed\\)"
               CMD ${MPIEXEC_EXECUTABLE} -np 2 --oversubscribe ${_grain} run ${_scenes}/periodic_bed.yaml
                   --output out --no-progress
               WORKDIR ${_work}/two_ranks
               FILES out/particles.xdmf out/log.csv out/particles_000010.h5)
set_tests_properties(grain.runs_on_two_ranks PROPERTIES PROCESSORS 2)
# Forced past the refusal, the run is stopped by the steps-per-contact guard at the first
# contact it cannot resolve; with that guard off, by the travel guard (a bead thrown faster
# than one radius per step); with both off, by the overlap guard (docs/stability.md).
# The refusal itself is then a warning, not an error.
grain_cli_test(steps_guard_stops_run 1
               "warning: dt is too large to resolve contacts;[(]running anyway: --allow-large-dt[)];particles? [0-9]+ and [a-z0-9 ']+ approach at [0-9.e-]+ m/s;only [0-9.e-]+ steps of dt = 0.001 s [(]fewer than 5, key time.min_steps_per_contact[)]"
               CMD ${_grain} run ${_scenes}/bad/huge_time_step.yaml --allow-large-dt --no-progress
                   --output out
               FORBID "error: dt is too large"
               WORKDIR ${_work}/steps_guard)
grain_cli_test(travel_guard_stops_run 1
               "particle [0-9]+ moves [0-9.]+ of its radii per step;key time.max_step_travel"
               CMD ${_grain} run ${_scenes}/bad/huge_time_step_travel_guard.yaml --allow-large-dt
                   --no-progress --output out
               WORKDIR ${_work}/travel_guard)
grain_cli_test(overlap_guard_stops_run 1
               "particle [0-9]+ and wall '[^']+' overlap by [0-9.]+ % of the smaller radius"
               CMD ${_grain} run ${_scenes}/bad/huge_time_step_no_steps_guard.yaml --allow-large-dt
                   --no-progress --output out
               WORKDIR ${_work}/overlap_guard)

# Reliability (docs/reliability.md): SIGTERM finishes the step, writes a checkpoint, exits 0.
# These read HDF5 with h5py (scripts/python.sh picks the Python).
grainflow_find_python(GRAINFLOW_PYTHON3 "h5py,numpy" "the SIGTERM and NaN-guard tests of grain are")
if(GRAINFLOW_PYTHON3)
  add_test(NAME grain.stop_signal_writes_checkpoint
           COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/stop_signal.sh ${_grain}
                   ${_scenes}/stop_signal.yaml ${_work}/stop_signal ${GRAINFLOW_PYTHON3})
  add_test(NAME grain.stop_signal_two_ranks
           COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/stop_signal.sh ${_grain}
                   ${_scenes}/stop_signal.yaml ${_work}/stop_signal_2 ${GRAINFLOW_PYTHON3}
                   ${MPIEXEC_EXECUTABLE} 2)
  # Two SIGTERMs a millisecond apart (GNU timeout's way) stop the run once, cleanly.
  add_test(NAME grain.stop_signal_twice
           COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/stop_signal_twice.sh ${_grain}
                   ${_scenes}/stop_signal.yaml ${_work}/stop_signal_twice)
  set_tests_properties(grain.stop_signal_twice PROPERTIES TIMEOUT 300)
  set_tests_properties(grain.stop_signal_writes_checkpoint grain.stop_signal_two_ranks
                       PROPERTIES ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}" TIMEOUT 60)
  set_tests_properties(grain.stop_signal_two_ranks PROPERTIES PROCESSORS 2)
  add_test(NAME grain.nan_guard_stops_run
           COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/nan_guard.sh ${_grain}
                   ${_scenes}/checkpointed_bed.yaml ${_work}/nan_guard ${GRAINFLOW_PYTHON3})
  set_tests_properties(grain.nan_guard_stops_run
                       PROPERTIES ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}" TIMEOUT 60)
  # 20 SIGKILLs, most while a 3 MB checkpoint is being written (about 17 s).
  add_test(NAME grain.kill_during_checkpoint
           COMMAND ${GRAINFLOW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/kill_during_checkpoint.py
                   ${_grain} ${_scenes}/kill_during_checkpoint.yaml ${_work}/kill_during_checkpoint 20)
  set_tests_properties(grain.kill_during_checkpoint
                       PROPERTIES ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}" TIMEOUT 120)
  # 6 SIGKILLs at random moments of a run that writes a snapshot every 10 steps and appends
  # to the XDMF index each time, restarting from checkpoints; the index must parse and list
  # only files that open with the listed contents (about 25 s: grain starts in 2-3 s here).
  add_test(NAME grain.kill_during_snapshots
           COMMAND ${GRAINFLOW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/kill_during_snapshots.py
                   ${_grain} ${_scenes}/kill_during_snapshots.yaml ${_work}/kill_during_snapshots 6)
  set_tests_properties(grain.kill_during_snapshots
                       PROPERTIES ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}" TIMEOUT 120)
  # ParaView's own XDMF reader (pvbatch, Debian's paraview package) reads a run's snapshots
  # with the extra fields, value for value, and renders them, and reads a run whose first
  # and last snapshots hold no particle without an error (about 20 s).
  execute_process(COMMAND bash ${PROJECT_SOURCE_DIR}/scripts/pvbatch.sh --check
                  RESULT_VARIABLE _no_paraview)
  if(_no_paraview EQUAL 0)
    add_test(NAME grain.paraview_reads_snapshots
             COMMAND ${GRAINFLOW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/paraview_reads_snapshots.py
                     ${_grain} ${_scenes}/paraview_snapshots.yaml
                     ${_work}/paraview_reads_snapshots ${PROJECT_SOURCE_DIR}/scripts/pvbatch.sh
                     ${_scenes}/paraview_empty_times.yaml)
    set_tests_properties(grain.paraview_reads_snapshots
                         PROPERTIES ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}" TIMEOUT 120)
  else()
    message(STATUS "pvbatch or Xvfb missing (scripts/bootstrap.sh installs them): "
                   "grain.paraview_reads_snapshots skipped")
  endif()
  # A disk that fills mid-run (snapshot, then checkpoint) and an unwritable output directory,
  # on small tmpfs mounts (about 20 s, 2 ranks); skipped when mounting is not permitted.
  add_test(NAME grain.disk_full
           COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/disk_full.sh ${_grain}
                   ${_scenes}/disk_full.yaml ${_work}/disk_full ${GRAINFLOW_PYTHON3}
                   ${MPIEXEC_EXECUTABLE})
  set_tests_properties(grain.disk_full PROPERTIES ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}"
                       TIMEOUT 300 PROCESSORS 2 SKIP_RETURN_CODE 77)
  # Ranks that got different command lines or scene files (standard input, a file missing on
  # one node, an option on one rank) all stop with one message and exit 2, none waiting
  # (rank_agreement.sh; about 20 s).
  add_test(NAME grain.rank_agreement
           COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/rank_agreement.sh ${_grain}
                   ${_scenes}/minimal.yaml ${_work}/rank_agreement ${MPIEXEC_EXECUTABLE})
  set_tests_properties(grain.rank_agreement PROPERTIES ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}"
                       TIMEOUT 600 PROCESSORS 2 LABELS mpi)
  # The "continue with:" line after SIGTERM, run as printed, continues in the --output folder
  # with the snapshot numbering going on (1 and 2 ranks).
  add_test(NAME grain.continue_command
           COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/continue_command.sh ${_grain}
                   ${_scenes}/continue_command.yaml ${_work}/continue_command ${GRAINFLOW_PYTHON3})
  add_test(NAME grain.continue_command_two_ranks
           COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/continue_command.sh ${_grain}
                   ${_scenes}/continue_command.yaml ${_work}/continue_command_2
                   ${GRAINFLOW_PYTHON3} ${MPIEXEC_EXECUTABLE} 2)
  set_tests_properties(grain.continue_command grain.continue_command_two_ranks
                       PROPERTIES ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}" TIMEOUT 120)
  set_tests_properties(grain.continue_command_two_ranks PROPERTIES PROCESSORS 2)
  # Hostile checkpoints and snapshots (docs/reliability.md, "What is checked on read"): a real
  # file with one value changed (or one bit flipped) is refused with exit code 1, naming the
  # file, the dataset, the index and the rule, and nothing in the output directory changes.
  # Random single-bit flips of a real checkpoint and snapshot: each start is refused naming the
  # file, or runs bit for bit like the intact file (tests/dem/app/bit_flips.py; about 5 s).
  add_test(NAME grain.bit_flips
           COMMAND ${GRAINFLOW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/bit_flips.py ${_grain}
                   ${_scenes}/checkpointed_bed.yaml ${_work}/bit_flips --seeds 0:6)
  set_tests_properties(grain.bit_flips PROPERTIES TIMEOUT 300 ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}")
  # Every default docs/scene-reference.md states is what grain does: each key left out, written
  # with its documented value, and written with another value, in a small scene; the first two
  # must agree bit for bit (report, log, every HDF5 dataset), the third must differ. A table row
  # with a stated default that no check covers fails the test (documented_defaults.py; about
  # 160 runs, 20 s).
  add_test(NAME grain.documented_defaults
           COMMAND ${GRAINFLOW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/documented_defaults.py ${_grain}
                   ${PROJECT_SOURCE_DIR}/docs/scene-reference.md ${_work}/documented_defaults
                   --mpiexec ${MPIEXEC_EXECUTABLE})
  set_tests_properties(grain.documented_defaults PROPERTIES TIMEOUT 600 PROCESSORS 2
                       ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}")
  set(_state_work ${_work}/state_file_checks)
  add_test(NAME grain.state_file_checks.setup
           COMMAND ${GRAINFLOW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/state_file_checks.py ${_grain}
                   ${_scenes}/checkpointed_bed.yaml ${_state_work} setup)
  set_tests_properties(grain.state_file_checks.setup PROPERTIES FIXTURES_SETUP grain_state_files)
  set(_state_cases material_max material_past position_bounded position_periodic negative_radius
                   equal_ids zero_mass mass_not_rho_v velocity_bit chunk_record)
  foreach(_kind checkpoint snapshot)
    set(_cases ${_state_cases})
    if(_kind STREQUAL "checkpoint")
      list(APPEND _cases spring_partner spring_wall next_id largest_radius removed step_changed
                         grid_ranks grid_planes dt_bit time_bit
                         end_before)
    endif()
    foreach(_case ${_cases})
      add_test(NAME grain.state_file_checks.${_kind}.${_case}
               COMMAND ${GRAINFLOW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/state_file_checks.py
                       ${_grain} ${_scenes}/checkpointed_bed.yaml ${_state_work} ${_kind} ${_case})
      set_tests_properties(grain.state_file_checks.${_kind}.${_case} PROPERTIES
                           FIXTURES_REQUIRED grain_state_files TIMEOUT 60
                           ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}")
    endforeach()
  endforeach()
endif()
grain_cli_test(restart_missing_checkpoint 1
               "cannot restart from 'no_such_checkpoint.h5': no such file \\(nothing was created or changed\\)"
               CMD ${_grain} run ${_scenes}/periodic_bed.yaml --output out --no-progress
                   --restart no_such_checkpoint.h5
               WORKDIR ${_work}/restart_missing)

# parallel.reproducible through the command line (docs/parallel.md): snapshots on 1, 2 and 3
# ranks and a restart on 3 ranks equal bit for bit (about 15 s of CPU).
if(GRAINFLOW_PYTHON3)
  # A restart into a folder that also holds another scene's run takes over only its own
  # snapshots and never deletes the other run's checkpoints, and steps over gaps (foreign_files.py;
  # about 20 s).
  add_test(NAME grain.foreign_files
           COMMAND ${GRAINFLOW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/foreign_files.py ${_grain}
                   ${_scenes}/stop_signal.yaml ${_work}/foreign_files)
  set_tests_properties(grain.foreign_files PROPERTIES ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}"
                                                      TIMEOUT 300)
  # What a user's files and folders may not silently do: inputs the run would overwrite,
  # a second YAML document, '~', the particle files named, a restart at its end (about 5 s).
  add_test(NAME grain.user_files
           COMMAND ${GRAINFLOW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/user_files.py ${_grain}
                   ${_work}/user_files)
  set_tests_properties(grain.user_files PROPERTIES TIMEOUT 300)
  # log.csv's thermal_J against the energy balance of heat sources in an adiabatic box, on 1
  # and 2 ranks (heat_log.py; about 2 s).
  add_test(NAME grain.heat_log
           COMMAND ${GRAINFLOW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/heat_log.py ${_grain}
                   ${_work}/heat_log ${MPIEXEC_EXECUTABLE})
  set_tests_properties(grain.heat_log PROPERTIES ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}"
                                                 TIMEOUT 300 PROCESSORS 2)
  add_test(NAME grain.reproducible_snapshots
           COMMAND ${GRAINFLOW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/reproducible_snapshots.py
                   ${_grain} ${_scenes}/periodic_bed_reproducible.yaml
                   ${_work}/reproducible_snapshots ${MPIEXEC_EXECUTABLE})
  set_tests_properties(grain.reproducible_snapshots
                       PROPERTIES ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}" TIMEOUT 300 PROCESSORS 2)
  # The same with contact.dashpot_velocity: predicted: the predicted velocities reach the ghosts
  # and migrating particles bit for bit, and a restart continues exactly.
  add_test(NAME grain.reproducible_snapshots_predicted
           COMMAND ${GRAINFLOW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/reproducible_snapshots.py
                   ${_grain} ${_scenes}/periodic_bed_reproducible_predicted.yaml
                   ${_work}/reproducible_snapshots_predicted ${MPIEXEC_EXECUTABLE})
  set_tests_properties(grain.reproducible_snapshots_predicted
                       PROPERTIES ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}" TIMEOUT 300 PROCESSORS 2)
  # With heat transfer: the heat flows are summed in the same canonical order, so the
  # temperatures are equal bit for bit too.
  add_test(NAME grain.reproducible_snapshots_heat
           COMMAND ${GRAINFLOW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/reproducible_snapshots.py
                   ${_grain} ${_scenes}/periodic_bed_reproducible_heat.yaml
                   ${_work}/reproducible_snapshots_heat ${MPIEXEC_EXECUTABLE})
  set_tests_properties(grain.reproducible_snapshots_heat
                       PROPERTIES ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}" TIMEOUT 300 PROCESSORS 2)
endif()


# Every advice an error or warning of grain gives works when applied as written: 32 messages
# (time-step refusals and warnings, heat and fluid-force limits, the run-time guards' proposed
# steps, the overlap guard's max_overlap / stiffness / cohesion proposals, periodic axis, MPI
# ranks, mesh welding, restart, scene-file suggestions), each triggered by a tiny scene, its
# advised value read from the message, applied, and rerun with `grain check` or `grain run`:
# the message must be gone (tests/dem/app/advice_reruns.py; about 70 runs, 17 s). Advice
# that does not work is listed there in KNOWN_BROKEN and fails the test as "BUG".
if(GRAINFLOW_PYTHON3)
  add_test(NAME grain.advice_reruns
           COMMAND ${GRAINFLOW_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/advice_reruns.py ${_grain}
                   ${_work}/advice_reruns --mpiexec ${MPIEXEC_EXECUTABLE})
  set_tests_properties(grain.advice_reruns PROPERTIES TIMEOUT 300 PROCESSORS 2
                       ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}")
endif()
