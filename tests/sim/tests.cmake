whirl_add_gtest(test_sim SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_sim.cpp)
whirl_add_gtest(test_features_drift SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_features_drift.cpp)
whirl_add_cli_test(sim_cli_simulate ${CMAKE_CURRENT_LIST_DIR}/cli_simulate.sh)
# Shipped tables against their regenerating command: within a relative 1e-6 with any compiler or
# flags, and byte for byte with the reference flags (WHIRL_EXACT_OUTPUTS). The 500 rows take
# ~10 s on 2 cores (both threads): part of the default run, so every shipped table is checked.
whirl_add_cli_test(sim_cli_shipped_tables ${CMAKE_CURRENT_LIST_DIR}/cli_shipped_tables.sh small
                   $<TARGET_FILE:numeric_diff> ${WHIRL_EXACT_OUTPUTS})
whirl_add_cli_test(sim_cli_shipped_500 ${CMAKE_CURRENT_LIST_DIR}/cli_shipped_tables.sh 500
                   $<TARGET_FILE:numeric_diff> ${WHIRL_EXACT_OUTPUTS})
