# grainflow_mesh_check(NAME SOURCE PREFIX FAILURES LINE): the step the mesh checks of
# cellpoint/cellpoint.cmake and reconstruct/reconstruct.cmake share. blockMesh in a fresh copy
# of the case folder SOURCE (at ${WORK}/NAME), then ${CHECK} -case on it, both through
# ${FOAM_ENV}; logs in the case folder. LINE is set to the check's line "PREFIX: ...", and a
# line is appended to the variable FAILURES when there is none, it lacks " status=ok", or the
# check exits non-zero. A failing blockMesh stops the script.
function(grainflow_mesh_check name source prefix failures_var line_var)
  set(case "${WORK}/${name}")
  file(REMOVE_RECURSE "${case}")
  file(MAKE_DIRECTORY "${case}")
  file(COPY "${source}/" DESTINATION "${case}")
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
      message(FATAL_ERROR "${name}: ${step} failed (exit ${rc}); log ${case}/log.${step}")
    endif()
  endforeach()
  set(failures "${${failures_var}}")
  string(REGEX MATCH "${prefix}: [^\n]*" line "${out}")
  if(NOT line)
    string(APPEND failures "\n  ${name}: no '${prefix}:' line (exit ${rc}); see ${case}/log.check")
  else()
    message(STATUS "${name}: ${line}")
    if(NOT line MATCHES " status=ok" OR NOT rc EQUAL 0)
      string(APPEND failures "\n  ${name}: ${line} (exit ${rc})")
    endif()
  endif()
  set(${failures_var} "${failures}" PARENT_SCOPE)
  set(${line_var} "${line}" PARENT_SCOPE)
endfunction()
