# Tests of src/machine_eval: the evaluation of both halves, its report and the combined programs.
whirl_add_gtest(test_machine_eval SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/test_machine_eval.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_combined_nc.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_machine_report.cpp)
# Shop training, causal application, the legacy reproduction and the seeds summary.
whirl_add_gtest(test_machine_shop SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_shop.cpp)
# The field world's evaluation: no truth in training, no look-ahead, headlines over seeds.
whirl_add_gtest(test_field_eval SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_field_eval.cpp)
