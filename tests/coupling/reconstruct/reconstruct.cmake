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

set(failures "")
foreach(name cellpoint/uniform cellpoint/graded cellpoint/skewed reconstruct/flat)
  get_filename_component(short "${name}" NAME)
  set(case "${WORK}/${short}")
  file(REMOVE_RECURSE "${case}")
  file(MAKE_DIRECTORY "${case}")
  file(COPY "${CASES}/${name}/" DESTINATION "${case}")
  foreach(step blockMesh check)
    if(step STREQUAL "blockMesh")
      set(cmd blockMesh)
    else()
      set(cmd "${CHECK}")
    endif()
    execute_process(COMMAND "${FOAM_ENV}" ${cmd} -case "${case}" WORKING_DIRECTORY "${case}"
                    OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
    file(WRITE "${case}/log.${step}" "${out}${err}")
    if(NOT rc EQUAL 0 AND NOT step STREQUAL "check")
      message(FATAL_ERROR "${short}: ${step} failed (exit ${rc}); log ${case}/log.${step}")
    endif()
  endforeach()
  string(REGEX MATCH "fluxReconstructionCheck: [^\n]*" line "${out}")
  if(NOT line)
    string(APPEND failures "\n  ${short}: no 'fluxReconstructionCheck:' line (exit ${rc}); see ${case}/log.check")
    continue()
  endif()
  message(STATUS "${short}: ${line}")
  if(NOT line MATCHES " status=ok" OR NOT rc EQUAL 0)
    string(APPEND failures "\n  ${short}: ${line} (exit ${rc})")
  endif()
  if(short MATCHES "skewed|flat" AND line MATCHES "nonOrthogonal=0 ")
    string(APPEND failures "\n  ${short}: no non-orthogonal cell, the mesh tests nothing")
  endif()
endforeach()
if(failures)
  message(FATAL_ERROR "coupling.flux_reconstruction:${failures}")
endif()
