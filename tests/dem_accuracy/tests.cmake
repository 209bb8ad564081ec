# accuracy_cost.dem_short: the short DEM accuracy-versus-cost sweeps
# (benchmarks/accuracy_cost/run.sh --short): time step, Hooke's v_char, skin, contact effects on
# small beds, then the report script on their tables. Passes when every error falls as its knob
# is refined, positions do not depend on the skin beyond round-off, and an unnamed contact slot
# changes nothing. Timings are recorded, not checked.
add_test(NAME accuracy_cost.dem_short
         COMMAND bash ${PROJECT_SOURCE_DIR}/benchmarks/accuracy_cost/run.sh --short
                 ${CMAKE_CURRENT_BINARY_DIR}/accuracy_cost_dem_short)
set_tests_properties(accuracy_cost.dem_short PROPERTIES
  ENVIRONMENT "GRAINFLOW_BUILD_DIR=${PROJECT_BINARY_DIR};${GRAINFLOW_MPIEXEC_ENV}"
  LABELS "accuracy_cost"
  TIMEOUT 120)
