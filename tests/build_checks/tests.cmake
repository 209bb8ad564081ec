# Build-level checks (included by tests/CMakeLists.txt).

# build.sweep_same_operations: the contact sweep, however GRAINFLOW_AVX compiled it
# (CMakeLists.txt), contains no fused multiply-add, so every lane performs the same IEEE
# operations in an SSE2, AVX or AVX-512 build and the results agree to the last bit
# (docs/performance.md, "The AVX-512 sweep"). A fused multiply-add rounds once where a multiply
# and an add round twice; one would come from the compiler contracting an expression or from
# Eigen's products when it sees __FMA__. In an AVX-512 build the sweep must also use the
# registers AVX-512 adds (ymm16-ymm31), the reason for building it so.
add_test(NAME build.sweep_same_operations
         COMMAND ${CMAKE_COMMAND}
                 -DOBJDUMP=${CMAKE_OBJDUMP}
                 "-DOBJECTS=$<JOIN:$<TARGET_OBJECTS:grainflow_engine>,|>"
                 -DISA=${GRAINFLOW_SWEEP_ISA}
                 -P ${CMAKE_CURRENT_LIST_DIR}/sweep_same_operations.cmake)
set_tests_properties(build.sweep_same_operations PROPERTIES LABELS build TIMEOUT 120)
