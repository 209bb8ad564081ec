# Runs blockMesh and foamProbe on a fresh copy of probe_case and checks foamProbe's line.
#   cmake -DFOAM_ENV=scripts/foam_env.sh -DFOAM_PROBE=bin/foamProbe
#         -DCASE_SOURCE=tests/foam/probe_case -DCASE_DIR=<scratch> -P probe_blockMesh.cmake
foreach(var FOAM_ENV FOAM_PROBE CASE_SOURCE CASE_DIR)
  if(NOT ${var})
    message(FATAL_ERROR "probe_blockMesh.cmake: -D${var}=... is required")
  endif()
endforeach()

# A fresh copy each run: blockMesh writes constant/polyMesh into the case.
file(REMOVE_RECURSE "${CASE_DIR}")
file(MAKE_DIRECTORY "${CASE_DIR}")
file(COPY "${CASE_SOURCE}/" DESTINATION "${CASE_DIR}")

function(run_step name)
  execute_process(COMMAND "${FOAM_ENV}" ${ARGN} -case "${CASE_DIR}"
                  WORKING_DIRECTORY "${CASE_DIR}"
                  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
  file(WRITE "${CASE_DIR}/log.${name}" "${out}${err}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${name} failed (exit ${rc}); log ${CASE_DIR}/log.${name}:\n${out}\n${err}")
  endif()
  set(step_out "${out}" PARENT_SCOPE)
endfunction()

run_step(blockMesh blockMesh)
run_step(foamProbe "${FOAM_PROBE}")

string(REGEX MATCH "foamProbe: [^\n]*" line "${step_out}")
if(NOT line)
  message(FATAL_ERROR "foamProbe printed no 'foamProbe: ...' line:\n${step_out}")
endif()
message(STATUS "${line}")

function(field key out)
  if(NOT line MATCHES " ${key}=([^ ]+)")
    message(FATAL_ERROR "foamProbe line has no ${key}=: ${line}")
  endif()
  set(${out} "${CMAKE_MATCH_1}" PARENT_SCOPE)
endfunction()

set(failures "")
# CMake's if(LESS/GREATER) compares as double, so bounds are written out: value +- 1e-12 * value
# (relative tolerance: blockMesh places points by summing cell widths and the volume is a sum
# of 120 cell volumes, a few 1e-16 relative in all, 1.3e-15 observed; 1e-12 leaves room while a
# wrong mesh, block count or unit is off by far more).
function(expect_between key value lo hi)
  if(value LESS lo OR value GREATER hi)
    set(failures "${failures}\n  ${key}=${value}, expected in [${lo}, ${hi}]" PARENT_SCOPE)
  endif()
endfunction()

field(status status)
if(NOT status STREQUAL "ok")
  string(APPEND failures "\n  status=${status} (foamProbe's own checks, see its stderr)")
endif()

field(cells cells)
if(NOT cells EQUAL 120)  # 4 x 5 x 6 blocks
  string(APPEND failures "\n  cells=${cells}, expected 120")
endif()

field(volume volume)  # 0.1 x 0.2 x 0.3 m
expect_between(volume "${volume}" 0.005999999999994 0.006000000000006)

field(bbmin bbmin)
field(bbmax bbmax)
string(REPLACE "," ";" bbmin "${bbmin}")
string(REPLACE "," ";" bbmax "${bbmax}")
# Lower corner exactly 0 (absolute bound 1e-12 m), upper corner 0.1, 0.2, 0.3 m (relative 1e-12).
set(axes x y z)
set(max_lo 0.0999999999999 0.1999999999998 0.2999999999997)
set(max_hi 0.1000000000001 0.2000000000002 0.3000000000003)
foreach(i RANGE 2)
  list(GET axes ${i} axis)
  list(GET bbmin ${i} value)
  expect_between("bbmin.${axis}" "${value}" -1e-12 1e-12)
  list(GET bbmax ${i} value)
  list(GET max_lo ${i} lo)
  list(GET max_hi ${i} hi)
  expect_between("bbmax.${axis}" "${value}" ${lo} ${hi})
endforeach()

# Gauss' theorem: the volume-weighted mean of grad(x) is (1,0,0) up to round-off.
field(grad_mean_error grad_mean_error)
expect_between(grad_mean_error "${grad_mean_error}" 0 1e-9)

if(failures)
  message(FATAL_ERROR "foamProbe on the 4x5x6 box:${failures}\nline: ${line}")
endif()
message(STATUS "foam.probe_blockMesh: 120 cells, volume ${volume} m^3, grad check ok")
