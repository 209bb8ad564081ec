# The CFD-DEM tutorials as tests: each runs its Allrun on a copy in the build tree and passes
# when its analyse.py finds the result within the tolerance its README states.
if(NOT TARGET grainFoam)
  return()
endif()

function(grain_tutorial_test name case ranks)
  add_test(NAME tutorial.${name}
           COMMAND ${CMAKE_CURRENT_LIST_DIR}/run_tutorial.sh ${PROJECT_SOURCE_DIR}
                   ${PROJECT_BINARY_DIR} ${CMAKE_CURRENT_BINARY_DIR}/tutorials/${name} ${case}
                   ${ARGN})
  set_tests_properties(tutorial.${name} PROPERTIES
    LABELS "foam;coupling;tutorial"
    PROCESSORS ${ranks}
    TIMEOUT 600)
endfunction()

# One sphere settling in water: terminal velocity within 3 % of Schiller-Naumann.
grain_tutorial_test(settlingParticle settlingParticle 1)
grain_tutorial_test(settlingParticle_np2 settlingParticle 2 -np 2)
# Packed bed: Ergun within 10 % below U_mf, bed weight within 5 % above (short stages).
grain_tutorial_test(ergunPackedBed_short ergunPackedBed 1 --short)
grain_tutorial_test(ergunPackedBed_short_np2 ergunPackedBed 2 --short -np 2)
