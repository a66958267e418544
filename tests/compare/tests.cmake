# Tests of src/compare (owned by the compare module).
whirl_add_gtest(test_compare SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/test_metrics.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_iso3408.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_cut.cpp
  LABELS compare)
