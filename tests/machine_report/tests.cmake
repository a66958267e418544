# Tests of src/lab/machine_report: the report of one screw and its combined 840D programs,
# replayed as the control runs them.
whirl_add_gtest(test_machine_report SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/test_machine_report.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_combined_nc.cpp)
