# accuracy_cost.coupled_short: the short coupled accuracy-versus-cost sweeps
# (benchmarks/accuracy_cost/coupled/coupled_sweeps.py --short): 8 grainFoam runs; passes when
# every error falls as its knob is refined (cell size, DEM steps per fluid step). Timings are
# recorded, not checked.
if(NOT TARGET grainFoam OR NOT TARGET grainflowFoamBCs)
  return()
endif()
grainflow_find_python(GRAINFLOW_SWEEPS_PYTHON "h5py,numpy" "accuracy_cost.coupled_short is")
if(NOT GRAINFLOW_SWEEPS_PYTHON)
  return()
endif()
add_test(NAME accuracy_cost.coupled_short
         COMMAND ${GRAINFLOW_SWEEPS_PYTHON} ${PROJECT_SOURCE_DIR}/benchmarks/accuracy_cost/coupled/coupled_sweeps.py
                 --short --work ${CMAKE_CURRENT_BINARY_DIR}/accuracy_cost_coupled_short
                 --build ${PROJECT_BINARY_DIR})
set_tests_properties(accuracy_cost.coupled_short PROPERTIES
  LABELS "foam;coupling;accuracy_cost"
  TIMEOUT 900)
