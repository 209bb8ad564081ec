# foam.superficial_inlet: the superficialVelocityInlet condition (libgrainflowFoamBCs.so) in
# real OpenFOAM programs, on a fresh copy of superficial_inlet_case:
#   1. blockMesh;
#   2. superficialInletCheck (serial) evaluates the condition against a non-uniform void
#      fraction and checks the inlet flux; its line must say status=ok;
#   3. decomposePar loads the library through the case's `libs (...)` entry, found on
#      LD_LIBRARY_PATH (set here). The inlet has no `value`, so without the library
#      decomposePar fails ("Essential entry 'value' missing", from OpenFOAM's generic patch
#      field); with it, the decomposed U holds the condition and the value U_s(0) = (0 0 0.2),
#      i.e. the documented fallback eps_b = 1 (no void-fraction field in decomposePar);
#   4. superficialInletCheck -parallel on 2 ranks re-reads the decomposed U (the condition's
#      own write() output) and repeats the checks with global sums.
#
#   cmake -DFOAM_ENV=scripts/foam_env.sh -DCHECK=bin/superficialInletCheck -DLIB_DIR=lib
#         -DMPIEXEC=mpiexec -DCASE_SOURCE=tests/foam/superficial_inlet_case -DCASE_DIR=<scratch>
#         -P superficial_inlet.cmake
foreach(var FOAM_ENV CHECK LIB_DIR MPIEXEC CASE_SOURCE CASE_DIR)
  if(NOT ${var})
    message(FATAL_ERROR "superficial_inlet.cmake: -D${var}=... is required")
  endif()
endforeach()

file(REMOVE_RECURSE "${CASE_DIR}")
file(MAKE_DIRECTORY "${CASE_DIR}")
file(COPY "${CASE_SOURCE}/" DESTINATION "${CASE_DIR}")

# OpenFOAM's libs entry dlopen()s the bare name: the loader finds it through LD_LIBRARY_PATH.
if("$ENV{LD_LIBRARY_PATH}" STREQUAL "")
  set(ENV{LD_LIBRARY_PATH} "${LIB_DIR}")
else()
  set(ENV{LD_LIBRARY_PATH} "${LIB_DIR}:$ENV{LD_LIBRARY_PATH}")
endif()

function(run_step name)
  execute_process(COMMAND "${FOAM_ENV}" ${ARGN} -case "${CASE_DIR}"
                  WORKING_DIRECTORY "${CASE_DIR}"
                  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
  file(WRITE "${CASE_DIR}/log.${name}" "${out}${err}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${name} failed (exit ${rc}); log ${CASE_DIR}/log.${name}:\n${out}\n${err}")
  endif()
  set(step_out "${out}${err}" PARENT_SCOPE)
endfunction()

set(failures "")

# Checks one superficialInletCheck line. The program checks (a)-(c) itself (status); the
# fluxes are checked here once more against the case's numbers: U_s,z = 0.2 and 0.4 m/s times
# A = 0.01 m^2, inflow negative, relative 1e-12 (see superficialInletCheck.C for the bound).
function(check_line name expected_nprocs)
  string(REGEX MATCH "superficialInletCheck: [^\n]*" line "${step_out}")
  if(NOT line)
    message(FATAL_ERROR "${name} printed no 'superficialInletCheck: ...' line:\n${step_out}")
  endif()
  message(STATUS "${name}: ${line}")
  set(f "")
  foreach(key status nprocs faces flux1 flux2)
    if(NOT line MATCHES " ${key}=([^ ]+)")
      message(FATAL_ERROR "${name}: the line has no ${key}=: ${line}")
    endif()
    set(${key} "${CMAKE_MATCH_1}")
  endforeach()
  if(NOT status STREQUAL "ok")
    string(APPEND f "\n  ${name}: status=${status} (its own checks, see log.${name})")
  endif()
  if(NOT nprocs EQUAL expected_nprocs)
    string(APPEND f "\n  ${name}: nprocs=${nprocs}, expected ${expected_nprocs}")
  endif()
  if(NOT faces EQUAL 16)  # 4 x 4 inlet faces
    string(APPEND f "\n  ${name}: faces=${faces}, expected 16")
  endif()
  if(flux1 LESS -0.002000000000002 OR flux1 GREATER -0.001999999999998)
    string(APPEND f "\n  ${name}: flux1=${flux1}, expected -0.002 m^3/s")
  endif()
  if(flux2 LESS -0.004000000000004 OR flux2 GREATER -0.003999999999996)
    string(APPEND f "\n  ${name}: flux2=${flux2}, expected -0.004 m^3/s")
  endif()
  set(failures "${failures}${f}" PARENT_SCOPE)
endfunction()

run_step(blockMesh blockMesh)

run_step(superficialInletCheck "${CHECK}")
check_line(superficialInletCheck 1)

run_step(decomposePar decomposePar)
if(step_out MATCHES "Could not load \"libgrainflowFoamBCs.so\"")
  string(APPEND failures "\n  decomposePar could not load libgrainflowFoamBCs.so "
                         "(LD_LIBRARY_PATH=$ENV{LD_LIBRARY_PATH}); see log.decomposePar")
endif()
foreach(proc 0 1)
  set(u_file "${CASE_DIR}/processor${proc}/0/U")
  if(NOT EXISTS "${u_file}")
    string(APPEND failures "\n  decomposePar wrote no ${u_file}")
    continue()
  endif()
  file(READ "${u_file}" u_text)
  string(REGEX MATCH "inlet[ \t\n]*{[^}]*}" inlet "${u_text}")
  if(NOT inlet MATCHES "type +superficialVelocityInlet;")
    string(APPEND failures "\n  processor${proc}/0/U: inlet is not superficialVelocityInlet:\n${inlet}")
  endif()
  # eps_b = 1 fallback at t = 0: U_s(0) = (0 0 0.2), written with 17 digits.
  if(NOT inlet MATCHES "value +uniform \\(0 0 0\\.2(0000000000000001)?\\);")
    string(APPEND failures
           "\n  processor${proc}/0/U: inlet value is not uniform (0 0 0.2) (fallback eps_b = 1):"
           "\n${inlet}")
  endif()
endforeach()

run_step(superficialInletCheck_parallel "${MPIEXEC}" -np 2 "${CHECK}" -parallel)
check_line(superficialInletCheck_parallel 2)

if(failures)
  message(FATAL_ERROR "foam.superficial_inlet:${failures}")
endif()
message(STATUS "foam.superficial_inlet: inlet flux = U_s.S (serial and 2 ranks), "
               "decomposePar loaded libgrainflowFoamBCs.so")
