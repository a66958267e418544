# Tests of src/product/lead (lead deviation, its metrics, the ISO 3408-3 class) and
# `whirl lead-report`.
whirl_add_gtest(test_lead SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/test_metrics.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_iso3408.cpp)
whirl_add_cli_test(cli_lead_report ${CMAKE_CURRENT_LIST_DIR}/cli_lead_report.sh)
