# Random hard scenes (tests/stress/hard_scenes/hard_scenes.py, docs/stability.md "A generator
# of hard scenes"): seeds 0 to 23 run `grain run` on scenes drawn across the parameter space
# and check the invariants listed in the script. These 24 seeds hold every one of the 8
# families 3 times, each of the 24 contact-slot combinations once, and every family on 1 and
# on 2 ranks.
# Bound: under 3 minutes on 2 shared cores (measured figure in docs/stability.md); a run over
# 25 s counts as a failure of its seed.
find_program(GRAINFLOW_HARD_SCENES_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
if(GRAINFLOW_HARD_SCENES_PYTHON)
  execute_process(COMMAND ${GRAINFLOW_HARD_SCENES_PYTHON} -c "import h5py, numpy, yaml"
                  RESULT_VARIABLE _hard_scenes_missing OUTPUT_QUIET ERROR_QUIET)
endif()
if(NOT GRAINFLOW_HARD_SCENES_PYTHON OR NOT _hard_scenes_missing EQUAL 0)
  message(STATUS "python3 with h5py, numpy and yaml not found: the test hard_scenes.ci is skipped")
  return()
endif()
add_test(NAME hard_scenes.ci
         COMMAND ${GRAINFLOW_HARD_SCENES_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/hard_scenes.py
                 --grain $<TARGET_FILE:grain> --mpiexec ${MPIEXEC_EXECUTABLE} --seeds 0:24
                 --timeout 25 --work ${PROJECT_BINARY_DIR}/test_output/hard_scenes)
set_tests_properties(hard_scenes.ci PROPERTIES ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}"
                     LABELS stress PROCESSORS 2 TIMEOUT 240)
