# Checks the compiled contact sweep (see tests.cmake): no fused multiply-add, and in an
# AVX-512 build the upper ymm registers in use.
#   cmake -DOBJDUMP=objdump -DOBJECTS="a.o|b.o|..." -DISA=SSE2|AVX|AVX512 -P sweep_same_operations.cmake
if(NOT OBJDUMP)
  message(FATAL_ERROR "no objdump (CMAKE_OBJDUMP is empty): install binutils")
endif()
string(REPLACE "|" ";" objects "${OBJECTS}")
list(FILTER objects INCLUDE REGEX "contact_sweep\\.cpp\\.o(bj)?$")
list(LENGTH objects n)
if(NOT n EQUAL 1)
  message(FATAL_ERROR "expected one contact_sweep object among the engine's objects, found ${n}")
endif()
execute_process(COMMAND ${OBJDUMP} -d --no-show-raw-insn ${objects}
                OUTPUT_VARIABLE asm ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${OBJDUMP} -d ${objects} failed (${rc}): ${err}")
endif()
string(LENGTH "${asm}" size)
if(size LESS 100000)
  message(FATAL_ERROR "${objects}: ${size} characters of disassembly; expected the whole sweep")
endif()

# vfmadd132pd, vfnmsub231sd, vfmaddsub213ps, ...: every FMA3 and AVX-512 fused form.
string(REGEX MATCHALL "[\t ]vf(n?m(add|sub)|maddsub|msubadd)[0-9]+[ps][sdh]" fused "${asm}")
list(LENGTH fused n_fused)
if(n_fused GREATER 0)
  # The function that holds the first one: the last symbol header before it.
  list(GET fused 0 first)
  string(FIND "${asm}" "${first}" at)
  string(SUBSTRING "${asm}" 0 ${at} before)
  string(FIND "${before}" ">:\n" header_end REVERSE)
  string(SUBSTRING "${before}" 0 ${header_end} before)
  string(FIND "${before}" "<" header_start REVERSE)
  math(EXPR header_start "${header_start} + 1")
  string(SUBSTRING "${before}" ${header_start} -1 where)
  string(SUBSTRING "${where}" 0 160 where)  # the mangled name, shortened
  message(FATAL_ERROR "${objects}: ${n_fused} fused multiply-add instruction(s), the first in "
                      "${where}; the sweep would round differently from the SSE2 build. "
                      "Keep -ffp-contract=off and __FMA__ undefined for it (CMakeLists.txt, "
                      "GRAINFLOW_SWEEP_FLAGS)")
endif()

string(REGEX MATCHALL "%ymm(1[6-9]|2[0-9]|3[01])" upper "${asm}")
list(LENGTH upper n_upper)
if(ISA STREQUAL "AVX512" AND n_upper EQUAL 0)
  message(FATAL_ERROR "${objects}: built for AVX-512 (GRAINFLOW_AVX) but uses none of ymm16-ymm31")
endif()
if(NOT ISA STREQUAL "AVX512" AND n_upper GREATER 0)
  message(FATAL_ERROR "${objects}: built for ${ISA} but uses ymm16-ymm31, which need AVX-512")
endif()
message(STATUS "${objects} (${ISA}): no fused multiply-add; ${n_upper} uses of ymm16-ymm31")
