# Fuzz targets (tests/fuzz/*_fuzz.cpp) in the ordinary build: each is linked with
# replay_main.cpp into an executable that feeds it every file of its seed corpus,
# which includes every input that once crashed it. The libFuzzer build itself is
# tests/fuzz/CMakeLists.txt, driven by scripts/fuzz.sh.
set(_fuzz ${CMAKE_CURRENT_LIST_DIR})

add_executable(scene_parser_fuzz_replay ${_fuzz}/scene_parser_fuzz.cpp ${_fuzz}/replay_main.cpp)
target_link_libraries(scene_parser_fuzz_replay PRIVATE grainflow_scene grainflow_warnings)
target_compile_definitions(scene_parser_fuzz_replay PRIVATE GRAINFLOW_FUZZ_FILES_DIR="${_fuzz}/files")
add_test(NAME fuzz.scene_parser_corpus
         COMMAND scene_parser_fuzz_replay ${_fuzz}/corpus/scene)

add_executable(stl_reader_fuzz_replay ${_fuzz}/stl_reader_fuzz.cpp ${_fuzz}/replay_main.cpp)
target_link_libraries(stl_reader_fuzz_replay PRIVATE grainflow_engine grainflow_warnings)
add_test(NAME fuzz.stl_reader_corpus COMMAND stl_reader_fuzz_replay ${_fuzz}/corpus/stl)
set_tests_properties(fuzz.scene_parser_corpus fuzz.stl_reader_corpus PROPERTIES
                     PASS_REGULAR_EXPRESSION "replayed [0-9]+ inputs without a crash")

# A short real libFuzzer run of each target (15 s each after a one-time build of about a
# minute), when clang and its libFuzzer runtime are installed (Debian: clang,
# libclang-rt-14-dev). Label `fuzz`; `ctest -LE fuzz` leaves them out. Long runs:
# scripts/fuzz.sh 600 (docs/reliability.md, "Hostile input").
find_program(GRAINFLOW_CLANGXX NAMES clang++ clang++-14)
set(_libfuzzer_found FALSE)
if(GRAINFLOW_CLANGXX)
  execute_process(COMMAND ${GRAINFLOW_CLANGXX} --print-runtime-dir OUTPUT_VARIABLE _rt_dir
                  OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  file(GLOB _libfuzzer "${_rt_dir}/libclang_rt.fuzzer*.a")
  if(_libfuzzer)
    set(_libfuzzer_found TRUE)
  endif()
endif()
if(_libfuzzer_found)
  set(_fuzz_env "GRAINFLOW_FUZZ_BUILD_DIR=${PROJECT_BINARY_DIR}/fuzz;CXX=${GRAINFLOW_CLANGXX}")
  add_test(NAME fuzz.build COMMAND ${PROJECT_SOURCE_DIR}/scripts/fuzz.sh 0)
  set_tests_properties(fuzz.build PROPERTIES ENVIRONMENT "${_fuzz_env}" LABELS fuzz
                       FIXTURES_SETUP fuzz_build RESOURCE_LOCK fuzz PROCESSORS 2)
  foreach(target scene_parser stl_reader)
    add_test(NAME fuzz.${target}_libfuzzer
             COMMAND ${PROJECT_SOURCE_DIR}/scripts/fuzz.sh 15 ${target})
    set_tests_properties(fuzz.${target}_libfuzzer PROPERTIES ENVIRONMENT "${_fuzz_env}"
                         LABELS fuzz FIXTURES_REQUIRED fuzz_build RESOURCE_LOCK fuzz
                         TIMEOUT 120)
  endforeach()
else()
  message(STATUS "clang++ with libFuzzer not found: the fuzz.*_libfuzzer tests are skipped")
endif()
