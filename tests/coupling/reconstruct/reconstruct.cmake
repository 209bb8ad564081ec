# coupling.flux_reconstruction: grainFoam's reconstruction of the cell velocity from face
# fluxes (coupling/foam/fluxReconstruction.H) against its closed form, by
# fluxReconstructionCheck, on four meshes made by blockMesh in fresh copies of the cases:
#   uniform, graded, skewed  tests/coupling/cellpoint/ (box cells; graded box cells, cyclic
#                            along x; skewed, twisted, graded cells);
#   flat                     reconstruct/flat: a 2-D mesh of parallelograms (empty front and
#                            back).
# Each must print status=ok; skewed and flat must have non-orthogonal cells.
#
#   cmake -DFOAM_ENV=scripts/foam_env.sh -DCHECK=bin/fluxReconstructionCheck
#         -DCASES=tests/coupling -DWORK=<scratch> -P reconstruct.cmake
foreach(var FOAM_ENV CHECK CASES WORK)
  if(NOT ${var})
    message(FATAL_ERROR "reconstruct.cmake: -D${var}=... is required")
  endif()
endforeach()

include(${CMAKE_CURRENT_LIST_DIR}/../mesh_check.cmake)
set(failures "")
foreach(name cellpoint/uniform cellpoint/graded cellpoint/skewed reconstruct/flat)
  get_filename_component(short "${name}" NAME)
  grainflow_mesh_check(${short} "${CASES}/${name}" fluxReconstructionCheck failures line)
  if(short MATCHES "skewed|flat" AND line MATCHES "nonOrthogonal=0 ")
    string(APPEND failures "\n  ${short}: no non-orthogonal cell, the mesh tests nothing")
  endif()
endforeach()
if(failures)
  message(FATAL_ERROR "coupling.flux_reconstruction:${failures}")
endif()
