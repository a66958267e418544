# Tests of src/machine (issue 19); the evaluation of both halves is tested in tests/machine_eval.
whirl_add_gtest(test_machine SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_machine.cpp)
whirl_add_cli_test(cli_machine ${CMAKE_CURRENT_LIST_DIR}/cli_machine.sh)
