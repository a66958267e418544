# Tests of src/product/ballbar (trilateration, drift, circle diagnostics, simulation) and its command line.
whirl_add_gtest(test_ballbar
  SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/test_trilateration.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_drift.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_circle.cpp
  LIBS whirl::synthetic)
whirl_add_cli_test(cli_ballbar ${CMAKE_CURRENT_LIST_DIR}/cli_ballbar.sh)
