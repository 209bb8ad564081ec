# Tutorial tests (included by tests/CMakeLists.txt): a tutorial's Allrun in its quick mode, on
# a fresh copy in the build tree (run_tutorial.sh), so that the source tree stays clean. The
# tutorial's analyse.py decides pass or fail (its exit status).
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
