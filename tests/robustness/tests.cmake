# Bounded inputs, files a shop can trust. Unit tests of the limits and a CLI sweep of
# every bad input the issue lists (each a regression test).
whirl_add_gtest(test_robustness SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_limits.cpp
                LIBS whirl::compare)
whirl_add_cli_test(cli_bad_inputs ${CMAKE_CURRENT_LIST_DIR}/cli_bad_inputs.sh)
whirl_add_cli_test(cli_input_files ${CMAKE_CURRENT_LIST_DIR}/cli_input_files.sh)
whirl_add_cli_test(cli_outputs ${CMAKE_CURRENT_LIST_DIR}/cli_outputs.sh)
# Every numeric flag of every subcommand refuses nan, inf and 1e999 naming the flag (found by
# walking --help, so new flags are covered).
whirl_add_cli_test(cli_numeric_flags ${CMAKE_CURRENT_LIST_DIR}/cli_numeric_flags.sh)
