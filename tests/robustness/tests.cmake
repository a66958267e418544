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
# One command-line grammar: units in decimal flag names, --out a file and --out-dir a folder,
# --json on every computing command, one help line per command, unknown commands named with the
# closest match, and each deprecated old spelling still working with its one-line notice.
whirl_add_cli_test(cli_grammar ${CMAKE_CURRENT_LIST_DIR}/cli_grammar.sh)
# Issue 45: output manifests, the control's limits, duplicate keys, model-file messages, time and
# count bounds, a deprecated flag given twice (each a regression test of a finding).
whirl_add_cli_test(cli_hardening ${CMAKE_CURRENT_LIST_DIR}/cli_hardening.sh)
# Every model a command writes (drift fit, train, surface fit/points, ballbar drift) handed to
# every command that takes a model file: accepted or refused by name, never a signal.
whirl_add_cli_test(cli_model_roundtrip ${CMAKE_CURRENT_LIST_DIR}/cli_model_roundtrip.sh)
