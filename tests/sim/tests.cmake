whirl_add_gtest(test_sim SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_sim.cpp)
whirl_add_gtest(test_features_drift SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_features_drift.cpp)
whirl_add_cli_test(sim_cli_simulate ${CMAKE_CURRENT_LIST_DIR}/cli_simulate.sh)
# Shipped tables against their regenerating command: within a relative 1e-6 by default (any
# compiler or flags), byte for byte under the label 'slow' (the flags they were made with).
whirl_add_cli_test(sim_cli_shipped_tables ${CMAKE_CURRENT_LIST_DIR}/cli_shipped_tables.sh small
                   $<TARGET_FILE:numeric_diff>)
whirl_add_cli_test(sim_cli_shipped_500 ${CMAKE_CURRENT_LIST_DIR}/cli_shipped_tables.sh 500
                   $<TARGET_FILE:numeric_diff>)
whirl_add_cli_test(sim_cli_shipped_tables_exact ${CMAKE_CURRENT_LIST_DIR}/cli_shipped_tables.sh small)
whirl_add_cli_test(sim_cli_shipped_500_exact ${CMAKE_CURRENT_LIST_DIR}/cli_shipped_tables.sh 500)
set_property(TEST sim_cli_shipped_tables_exact sim_cli_shipped_500_exact APPEND PROPERTY LABELS slow)
# ~10 s on 2 cores (500 rows over both threads): part of the default run, so every shipped table
# is checked against its regenerating command.
