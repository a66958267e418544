# Tests of the gp module (Gaussian-process regression) and of the BFGS minimizer it uses
# (core/bfgs.h; its tests can move to tests/core when the core tests are reorganized).
whirl_add_gtest(test_gp SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/test_bfgs.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_gp.cpp
  LABELS gp)
