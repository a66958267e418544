# Tests of interp/ (breakpoints, 840D setting data, writers) and the plan command line.
whirl_add_gtest(test_interp
  SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/test_breakpoints.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_sinumerik.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_nc_replay.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_drift_action.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_grey_action.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_machine_profile.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_control_requirements.cpp
)
whirl_add_cli_test(cli_plan ${CMAKE_CURRENT_LIST_DIR}/cli_plan.sh)
whirl_add_cli_test(cli_drift_nc ${CMAKE_CURRENT_LIST_DIR}/cli_drift_nc.sh)
