# Tests of src/compare (owned by the compare module).
whirl_add_gtest(test_compare SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/test_metrics.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_iso3408.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_cut.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_compare.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_baselines.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_report_safety.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_curve_study.cpp
)
whirl_add_cli_test(cli_lead_report ${CMAKE_CURRENT_LIST_DIR}/cli_lead_report.sh)
whirl_add_cli_test(cli_compare ${CMAKE_CURRENT_LIST_DIR}/cli_compare.sh)
whirl_add_cli_test(cli_demo ${CMAKE_CURRENT_LIST_DIR}/cli_demo.sh)
