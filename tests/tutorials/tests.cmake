# Tutorial tests (included by tests/CMakeLists.txt): a tutorial's Allrun in its quick mode, on
# a fresh copy in the build tree (run_tutorial.sh), so that the source tree stays clean. The
# tutorial's analyse.py decides pass or fail (its exit status).

# The tutorials' analyse.py (and tutorials/run_index.py) on the output of stopped, restarted
# and damaged runs, built by hand in tests/tutorials/analyse_test.py (every number known by
# construction; about a second each; no grain or grainFoam run):
# tutorial.analyse_hopper_restarted_folder: a discharge restarted into another folder (its
#   series starts at 0.32 s): said, with --bed; with --bed the t = 0 solid fraction 0.5227
#   (147 beads in the cylinder), the rate 5.236 g/s, Beverloo from them, the fit 0.32-1.00 s.
# tutorial.analyse_pour_settle_cut_log: a last log row cut before its exponent and a damaged
#   row: left out and named (file:line); final kinetic energy 1.001e-02 J (it said 5.65 J).
# tutorial.analyse_run_index_damaged_index: particles.xdmf cut short in a folder of two runs
#   of one scene: the last run's 3 snapshots (up to the end of log.csv), the damaged index
#   named with its remedy, the others named; pour_settle/analyse.py on it (it stopped).
# tutorial.analyse_heatedBed_restart_log: a coupled run restarted at 0.36 s: the restart's log
#   alone is refused, naming its start and --log; --log with both pieces gives the constructed
#   well-mixed bed (375.69 K, 3.7845 J gained) and passes (it said FAILED).
# tutorial.analyse_ergun_restart_folders: postProcessing/inletPressure/0/ and 0.3/ joined: the
#   stages measure the constructed 80 Pa and the weight/area 256.70 Pa (it said nan, FAILED);
#   without 0.3/ the empty window is named.
grainflow_find_python(GRAINFLOW_ANALYSE_PYTHON "h5py,numpy,matplotlib,yaml"
                      "the tutorial.analyse_* tests are")
if(GRAINFLOW_ANALYSE_PYTHON)
  foreach(_case hopper_restarted_folder pour_settle_cut_log run_index_damaged_index
                heatedBed_restart_log ergun_restart_folders)
    add_test(NAME tutorial.analyse_${_case}
             COMMAND ${GRAINFLOW_ANALYSE_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/analyse_test.py ${_case}
                     --work ${PROJECT_BINARY_DIR}/test_output/tutorials/analyse_${_case})
    set_tests_properties(tutorial.analyse_${_case} PROPERTIES
      ENVIRONMENT "GRAINFLOW_PYTHON_CHOSEN=1"
      LABELS "scripts;tutorial"
      TIMEOUT 120)
  endforeach()
endif()

if(NOT TARGET grainFoam OR NOT TARGET grainflowFoamBCs)
  return()
endif()

# tutorial.fluidisedBed_short: tutorials/cfd-dem/fluidisedBed, `Allrun --short` (serial):
# 2000 glass beads poured into the 60 x 9 x 240 mm column and fluidised at 2 U_mf.
# Reference: the bed's buoyant weight per area, N V_p (rho_p - rho_f) g / A (DESIGN.md
# section 7). analyse.py --short fails when the pressure drop averaged over 0.4-0.6 s is more
# than 10 % away from it (5 % in the full tutorial, averaged over 0.5 s of a 12 000-bead
# bed; 0.2 s of a 5 mm bed leaves a few per cent of fluctuation in the average).
# Measured: 0.990 of the weight; about 40 s of CPU time.
add_test(NAME tutorial.fluidisedBed_short
         COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/run_tutorial.sh
                 ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}
                 ${CMAKE_CURRENT_BINARY_DIR}/tutorials/fluidisedBed_short fluidisedBed --short)
set_tests_properties(tutorial.fluidisedBed_short PROPERTIES
  ENVIRONMENT "GRAINFLOW_FOAM_BASHRC=${OpenFOAM_BASHRC}"
  LABELS "tutorial;foam"
  TIMEOUT 300)

# The other CFD-DEM tutorials, the same way.
function(grain_tutorial_test name case ranks)
  add_test(NAME tutorial.${name}
           COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/run_tutorial.sh ${PROJECT_SOURCE_DIR}
                   ${PROJECT_BINARY_DIR} ${CMAKE_CURRENT_BINARY_DIR}/tutorials/${name} ${case}
                   ${ARGN})
  set_tests_properties(tutorial.${name} PROPERTIES
    ENVIRONMENT "GRAINFLOW_FOAM_BASHRC=${OpenFOAM_BASHRC}"
    LABELS "tutorial;foam;coupling"
    PROCESSORS ${ranks}
    TIMEOUT 600)
endfunction()

# One sphere settling in water: terminal velocity within 3 % of Schiller-Naumann, on 1 and
# on 2 ranks (the processor plane cuts the particle's footprint).
grain_tutorial_test(settlingParticle settlingParticle 1)
grain_tutorial_test(settlingParticle_np2 settlingParticle 2 -np 2)
# Packed bed, short stages: Ergun within 10 % below U_mf (a fixed bed), bed weight within 5 %
# above it; 1 and 2 ranks.
grain_tutorial_test(ergunPackedBed_short ergunPackedBed 1 --short)
grain_tutorial_test(ergunPackedBed_short_np2 ergunPackedBed 2 --short -np 2)
