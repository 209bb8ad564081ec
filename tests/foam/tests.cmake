# Command-level tests of the OpenFOAM side (included by tests/CMakeLists.txt).
if(NOT TARGET foamProbe)
  return()
endif()

# foam.probe_blockMesh: blockMesh builds tests/foam/probe_case (a 0.1 x 0.2 x 0.3 m box of
# 4 x 5 x 6 cells) in a copy in the build tree, then foamProbe opens it through Debian's
# OpenFOAM libraries. Reference: the box geometry, 120 cells and 0.006 m^3.
add_test(NAME foam.probe_blockMesh
         COMMAND ${CMAKE_COMMAND}
                 -DFOAM_ENV=${PROJECT_SOURCE_DIR}/scripts/foam_env.sh
                 -DFOAM_PROBE=$<TARGET_FILE:foamProbe>
                 -DCASE_SOURCE=${CMAKE_CURRENT_LIST_DIR}/probe_case
                 -DCASE_DIR=${CMAKE_CURRENT_BINARY_DIR}/foam/probe_blockMesh
                 -P ${CMAKE_CURRENT_LIST_DIR}/probe_blockMesh.cmake)
set_tests_properties(foam.probe_blockMesh PROPERTIES
  ENVIRONMENT "GRAINFLOW_FOAM_BASHRC=${OpenFOAM_BASHRC}"
  LABELS foam
  TIMEOUT 300)
