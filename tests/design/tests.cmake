# Tests of the design of which screws to measure: invariants of the designs and the variance
# update (test_design), the command line in both modes and its errors (design_cli).
whirl_add_gtest(test_design SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_design.cpp
                LIBS whirl::design whirl::workpiece whirl::family whirl::gp)
whirl_add_cli_test(design_cli ${CMAKE_CURRENT_LIST_DIR}/design_cli.sh)
