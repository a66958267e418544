# Tests of src/product/fit (LM solver, curve models) and the fit/curve command line.
whirl_add_gtest(test_fit
  SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/test_levenberg_marquardt.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_arctan_curve.cpp)
whirl_add_cli_test(cli_fit ${CMAKE_CURRENT_LIST_DIR}/cli_fit.sh)
