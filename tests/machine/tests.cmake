# Tests of src/machine and compare/machine_eval (issue 19).
whirl_add_gtest(test_machine SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/test_machine.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_combined_nc.cpp
  LIBS whirl::compare)
whirl_add_cli_test(cli_machine ${CMAKE_CURRENT_LIST_DIR}/cli_machine.sh)
