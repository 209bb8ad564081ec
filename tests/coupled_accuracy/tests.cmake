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

# coupling.undisturbed_settling: one sphere settling at Re_t = 0.1 in cells of 3 d with
# undisturbedVelocity oseenBrinkman: the settling speed within 3 % of Schiller-Naumann's
# terminal velocity (46 % too fast without the correction, docs/models/undisturbed-velocity.md)
# and the momentum exchange balanced to 1e-12 at every write time.
add_test(NAME coupling.undisturbed_settling
         COMMAND ${GRAINFLOW_SWEEPS_PYTHON} ${PROJECT_SOURCE_DIR}/benchmarks/accuracy_cost/coupled/settling_cells.py
                 --re 0.1 --cells 3 --courant 0.05 --width 10 --fall 30 --correction oseenBrinkman
                 --check 3 --work ${CMAKE_CURRENT_BINARY_DIR}/undisturbed_settling
                 --build ${PROJECT_BINARY_DIR})
set_tests_properties(coupling.undisturbed_settling PROPERTIES
  LABELS "foam;coupling;accuracy_cost"
  TIMEOUT 600)

# coupling.bed_surface: the poured bed of tutorials/cfd-dem/ergunPackedBed (3300 beads,
# d = 1 mm) in cells of 2 d, air at 0.2 m/s, drag koch_hill and gidaspow with
# dragVoidFraction sharpInterface: the pressure drop within 3 % of each law's own packed-bed
# closed form with the bed's core eps and mass-equivalent height (-7 to -9 % without), and
# the momentum exchange balanced to 1e-12 (docs/models/bed-surface.md).
add_test(NAME coupling.bed_surface
         COMMAND ${GRAINFLOW_SWEEPS_PYTHON} ${PROJECT_SOURCE_DIR}/benchmarks/accuracy_cost/coupled/bed_surface.py
                 --laws koch_hill,gidaspow --cells 6 --surface sharpInterface --check 3 --end 0.02
                 --work ${CMAKE_CURRENT_BINARY_DIR}/bed_surface
                 --build ${PROJECT_BINARY_DIR})
set_tests_properties(coupling.bed_surface PROPERTIES
  LABELS "foam;coupling;accuracy_cost"
  TIMEOUT 300)
