# ParaView's XDMF reader on the contact network (output.contacts): a pile run with `grain` on
# 2 ranks, then pvbatch checks every time's lines and cell arrays against the HDF5 files
# (about 10 s). Skipped (exit 77) where pvbatch is not installed.
add_test(NAME grain.contact_network_paraview
         COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/run_check.sh $<TARGET_FILE:grain>
                 ${MPIEXEC_EXECUTABLE} ${PROJECT_BINARY_DIR}/test_output/contact_network_paraview)
set_tests_properties(grain.contact_network_paraview
                     PROPERTIES ENVIRONMENT "${GRAINFLOW_MPIEXEC_ENV}" TIMEOUT 120 PROCESSORS 2
                                SKIP_RETURN_CODE 77 LABELS "mpi;paraview")
