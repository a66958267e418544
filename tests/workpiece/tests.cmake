# Tests of the workpiece model: prediction, files (round trip, shipped network files), training.
whirl_add_gtest(test_workpiece SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_workpiece.cpp)
whirl_add_cli_test(workpiece_cli ${CMAKE_CURRENT_LIST_DIR}/workpiece_cli.sh)
