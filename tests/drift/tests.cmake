# Tests of src/drift (run files, Miao et al.'s selection, drift models, evaluation) and its CLI.
whirl_add_gtest(test_drift
  SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/test_selection.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_models.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_run_file.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_monitor.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_inputs.cpp
  LIBS Boost::headers)
whirl_add_cli_test(cli_drift ${CMAKE_CURRENT_LIST_DIR}/cli_drift.sh)
whirl_add_cli_test(cli_drift_monitor ${CMAKE_CURRENT_LIST_DIR}/cli_monitor.sh)
# The joint estimator from shop measurements (drift/joint.h).
whirl_add_gtest(test_drift_joint SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_joint.cpp)
