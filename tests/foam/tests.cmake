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

# foam.superficial_inlet: the superficialVelocityInlet condition of libgrainflowFoamBCs.so on
# tests/foam/superficial_inlet_case (0.1 x 0.1 x 0.2 m box, 4 x 4 x 8 cells, inlet at z = 0):
# superficialInletCheck evaluates it against a non-uniform void fraction, serial and on 2 ranks
# after decomposePar, which must load the library through the case's `libs` entry. Reference:
# the inlet fluid flux sum eps_b U_b.S_f = U_s.sum S_f = -U_s,z * 0.01 m^2 (see
# superficial_inlet.cmake and foam_solver/boundaryConditions/tests/superficialInletCheck.C).
if(TARGET superficialInletCheck)
  add_test(NAME foam.superficial_inlet
           COMMAND ${CMAKE_COMMAND}
                   -DFOAM_ENV=${PROJECT_SOURCE_DIR}/scripts/foam_env.sh
                   -DCHECK=$<TARGET_FILE:superficialInletCheck>
                   -DLIB_DIR=$<TARGET_FILE_DIR:grainflowFoamBCs>
                   -DMPIEXEC=${MPIEXEC_EXECUTABLE}
                   -DCASE_SOURCE=${CMAKE_CURRENT_LIST_DIR}/superficial_inlet_case
                   -DCASE_DIR=${CMAKE_CURRENT_BINARY_DIR}/foam/superficial_inlet
                   -P ${CMAKE_CURRENT_LIST_DIR}/superficial_inlet.cmake)
  set_tests_properties(foam.superficial_inlet PROPERTIES
    ENVIRONMENT "GRAINFLOW_FOAM_BASHRC=${OpenFOAM_BASHRC};${GRAINFLOW_MPIEXEC_ENV}"
    LABELS "foam;mpi"
    PROCESSORS 2
    TIMEOUT 300)
endif()
