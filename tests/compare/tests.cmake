# Tests of src/lab/compare (owned by the compare module).
whirl_add_gtest(test_compare SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/test_cut.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_compare.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_baselines.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_report_safety.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_report_content.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_curve_study.cpp
)
whirl_add_cli_test(cli_compare ${CMAKE_CURRENT_LIST_DIR}/cli_compare.sh)
whirl_add_cli_test(cli_demo ${CMAKE_CURRENT_LIST_DIR}/cli_demo.sh)
# Every report rendered in headless Chromium (skipped, exit 77, when it is not installed).
whirl_add_cli_test(cli_report_render ${CMAKE_CURRENT_LIST_DIR}/cli_report_render.sh)
set_tests_properties(cli_report_render PROPERTIES SKIP_RETURN_CODE 77)
