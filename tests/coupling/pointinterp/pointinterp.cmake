# coupling.point_interpolation: grainflow's point interpolation of records (coupling/foam/
# pointInterpolation) against OpenFOAM's volPointInterpolation, bit for bit, by
# pointInterpolationCheck, and the coupling's grad p (coupling/foam/gaussLinearGrad.H)
# against fvc::grad (Gauss linear), on meshes made by blockMesh in fresh copies of the cases
# here:
#   thin     2 x 10 x 24 box cells between symmetry patches (the Goldschmidt benchmark's
#            shape), walls, an inlet and an outlet patch; 1 rank and 2 (cut across z);
#   twisted  9 x 6 x 7 skewed cells, a symmetry patch on curved faces (point normals vary),
#            a symmetryPlane, walls; 1 rank and 2 (cut across x);
#   slab     12 x 1 x 16, empty front and back (two-dimensional); 1 rank;
#   cyclic   ../cellpoint/graded (cyclic along x): the class must say it does not reproduce
#            it (the coupling then uses volPointInterpolation itself); its grad p is checked
#            (the cyclic patch is coupled: the interpolation across it).
# Each must print status=ok (cyclic: status=unsupported).
#
#   cmake -DFOAM_ENV=scripts/foam_env.sh -DCHECK=bin/pointInterpolationCheck -DMPIEXEC=mpiexec
#         -DCASES=tests/coupling/pointinterp -DCOMMON=tests/coupling/cellpoint/uniform/system
#         -DWORK=<scratch> -P pointinterp.cmake
foreach(var FOAM_ENV CHECK MPIEXEC CASES COMMON WORK)
  if(NOT ${var})
    message(FATAL_ERROR "pointinterp.cmake: -D${var}=... is required")
  endif()
endforeach()

function(foam_step case log)
  execute_process(COMMAND "${FOAM_ENV}" ${ARGN} WORKING_DIRECTORY "${case}"
                  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
  file(WRITE "${case}/log.${log}" "${out}${err}")
  set(step_out "${out}" PARENT_SCOPE)
  set(step_rc "${rc}" PARENT_SCOPE)
endfunction()

set(failures "")
foreach(run thin:1 thin:2 twisted:1 twisted:2 slab:1 cyclic:1)
  string(REPLACE ":" ";" parts "${run}")
  list(GET parts 0 name)
  list(GET parts 1 ranks)
  set(case "${WORK}/${name}_np${ranks}")
  file(REMOVE_RECURSE "${case}")
  file(MAKE_DIRECTORY "${case}/system")
  file(COPY "${COMMON}/controlDict" "${COMMON}/fvSchemes" "${COMMON}/fvSolution"
       DESTINATION "${case}/system")
  if(name STREQUAL "cyclic")
    file(COPY "${CASES}/../cellpoint/graded/system/blockMeshDict" DESTINATION "${case}/system")
  else()
    file(COPY "${CASES}/${name}/system/" DESTINATION "${case}/system")
  endif()
  foam_step("${case}" blockMesh blockMesh -case "${case}")
  if(NOT step_rc EQUAL 0)
    message(FATAL_ERROR "${name}: blockMesh failed (exit ${step_rc}); log ${case}/log.blockMesh")
  endif()
  if(ranks GREATER 1)
    foam_step("${case}" decomposePar decomposePar -case "${case}")
    if(NOT step_rc EQUAL 0)
      message(FATAL_ERROR "${name}: decomposePar failed (exit ${step_rc}); log ${case}/log.decomposePar")
    endif()
    foam_step("${case}" check "${MPIEXEC}" -np ${ranks} "${CHECK}" -parallel -case "${case}")
  else()
    foam_step("${case}" check "${CHECK}" -case "${case}")
  endif()
  string(REGEX MATCH "pointInterpolationCheck: [^\n]*" line "${step_out}")
  if(NOT line)
    string(APPEND failures "\n  ${name} on ${ranks}: no 'pointInterpolationCheck:' line (exit ${step_rc}); see ${case}/log.check")
    continue()
  endif()
  message(STATUS "${name} on ${ranks}: ${line}")
  if(name STREQUAL "cyclic")
    set(expected " status=unsupported")
  else()
    set(expected " status=ok")
  endif()
  if(NOT line MATCHES "${expected}" OR NOT step_rc EQUAL 0)
    string(APPEND failures "\n  ${name} on ${ranks}: ${line} (exit ${step_rc}), expected${expected}")
  endif()
endforeach()
if(failures)
  message(FATAL_ERROR "coupling.point_interpolation:${failures}")
endif()
