# Runs a tutorial's Allrun on a fresh copy and checks its output:
#
#   cmake -DTUTORIAL_SOURCE=tutorials/... -DTUTORIAL_DIR=<scratch> -DBUILD_DIR=<build>
#         [-DARGS="--short;..."] [-DEXPECT=<regex the output must match>] -P run_tutorial.cmake
#
# The copy sits at the same depth below a folder holding scripts/ as in the repository
# (Allrun finds scripts/foam_env.sh at ../../..), so the repository's scripts/ is linked in.
foreach(var TUTORIAL_SOURCE TUTORIAL_DIR BUILD_DIR)
  if(NOT ${var})
    message(FATAL_ERROR "run_tutorial.cmake: -D${var}=... is required")
  endif()
endforeach()

get_filename_component(name "${TUTORIAL_SOURCE}" NAME)
get_filename_component(group_dir "${TUTORIAL_SOURCE}" DIRECTORY)
get_filename_component(group "${group_dir}" NAME)
get_filename_component(tutorials_dir "${group_dir}" DIRECTORY)
get_filename_component(repo "${tutorials_dir}" DIRECTORY)

file(REMOVE_RECURSE "${TUTORIAL_DIR}")
set(case "${TUTORIAL_DIR}/tutorials/${group}/${name}")
file(MAKE_DIRECTORY "${TUTORIAL_DIR}/tutorials/${group}")
file(COPY "${TUTORIAL_SOURCE}" DESTINATION "${TUTORIAL_DIR}/tutorials/${group}")
file(CREATE_LINK "${repo}/scripts" "${TUTORIAL_DIR}/scripts" SYMBOLIC)

execute_process(COMMAND "${case}/Allclean")
execute_process(COMMAND "${case}/Allrun" ${ARGS} "${BUILD_DIR}"
                WORKING_DIRECTORY "${case}"
                OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
file(WRITE "${TUTORIAL_DIR}/log.Allrun" "${out}${err}")
message(STATUS "${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${name}: Allrun ${ARGS} failed (exit ${rc}); logs in ${case}")
endif()
if(EXPECT AND NOT "${out}" MATCHES "${EXPECT}")
  message(FATAL_ERROR "${name}: the output does not match '${EXPECT}'")
endif()
