# Tests of src/lab/machine; the evaluation of both halves is tested in tests/machine_eval.
whirl_add_gtest(test_machine SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_machine.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_blank.cpp ${CMAKE_CURRENT_LIST_DIR}/test_world_parts.cpp)
whirl_add_cli_test(cli_machine ${CMAKE_CURRENT_LIST_DIR}/cli_machine.sh)
# scripts/grey_acceptance.sh: arguments only (the table takes minutes).
whirl_add_cli_test(cli_grey_acceptance ${CMAKE_CURRENT_LIST_DIR}/cli_grey_acceptance.sh)
# The field world (exact thermal network, sensors, the shop day, scenarios).
whirl_add_gtest(test_network SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_network.cpp)
whirl_add_gtest(test_sensors SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_sensors.cpp)
whirl_add_gtest(test_day SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_day.cpp)
# whirl machine export (files drift fit reads) and machine ceiling (the exact-truth regression).
whirl_add_cli_test(cli_machine_export ${CMAKE_CURRENT_LIST_DIR}/cli_machine_export.sh)
