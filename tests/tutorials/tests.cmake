# Tutorial tests (included by tests/CMakeLists.txt): a tutorial's Allrun in its quick mode, on
# a fresh copy of the tutorial in the build tree, so that the source tree stays clean.
if(NOT TARGET grainFoam OR NOT TARGET grainflowFoamBCs)
  return()
endif()

# tutorial.fluidisedBed_short: tutorials/cfd-dem/fluidisedBed, `Allrun --short` (serial):
# 2000 glass beads poured into the 48 x 9 x 240 mm column and fluidised at 2.4 U_mf.
# Reference: the bed's buoyant weight per area, N V_p (rho_p - rho_f) g / A (DESIGN.md
# section 7); analyse.py fails the run when the pressure drop averaged over 0.4-0.6 s is more
# than 10 % away from it (5 % in the full tutorial: 0.2 s of a 6-layer bubbling bed leaves
# fluctuations of a few per cent in the average).
add_test(NAME tutorial.fluidisedBed_short
         COMMAND ${CMAKE_COMMAND}
                 -DTUTORIAL_SOURCE=${PROJECT_SOURCE_DIR}/tutorials/cfd-dem/fluidisedBed
                 -DTUTORIAL_DIR=${CMAKE_CURRENT_BINARY_DIR}/tutorials/fluidisedBed
                 -DBUILD_DIR=${PROJECT_BINARY_DIR}
                 "-DEXPECT=fluidisedBed: .* \\(tolerance 10 %: ok\\)"
                 -DARGS=--short
                 -P ${CMAKE_CURRENT_LIST_DIR}/run_tutorial.cmake)
set_tests_properties(tutorial.fluidisedBed_short PROPERTIES
  ENVIRONMENT "GRAINFLOW_FOAM_BASHRC=${OpenFOAM_BASHRC}"
  LABELS "tutorial;foam"
  TIMEOUT 300)
