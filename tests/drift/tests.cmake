# Tests of src/product/drift (run files, Miao et al.'s selection, drift models, evaluation) and its CLI.
whirl_add_gtest(test_drift
  SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/test_selection.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_models.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_run_file.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_monitor.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_inputs.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_zero_time.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_choice.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_stream.cpp
  LIBS Boost::headers)
whirl_add_cli_test(cli_drift ${CMAKE_CURRENT_LIST_DIR}/cli_drift.sh)
whirl_add_cli_test(cli_drift_monitor ${CMAKE_CURRENT_LIST_DIR}/cli_monitor.sh)
# A first user's frictions: BOM before the time column, events header, coefficient units, minutes
# flags on a run without time.
whirl_add_cli_test(cli_drift_frictions ${CMAKE_CURRENT_LIST_DIR}/cli_frictions.sh)
# The joint estimator from shop measurements (drift/joint.h).
whirl_add_gtest(test_drift_joint SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_joint.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_grey_box.cpp)
# The grey box fitted from measurement records and written for the 840D (drift fit-grey,
# drift nc --grey-model).
whirl_add_cli_test(cli_fit_grey ${CMAKE_CURRENT_LIST_DIR}/cli_fit_grey.sh)
# The FL_THERMAL target's settings chosen before the test window (needs ../shared; exit 77: skipped):
# 3 settings in the default run, the script's whole grid of 8 under the label slow.
whirl_add_cli_test(cli_fl_thermal_moonshot ${CMAKE_CURRENT_LIST_DIR}/cli_fl_moonshot.sh quick)
whirl_add_cli_test(cli_fl_thermal_moonshot_full ${CMAKE_CURRENT_LIST_DIR}/cli_fl_moonshot.sh full)
set_tests_properties(cli_fl_thermal_moonshot cli_fl_thermal_moonshot_full PROPERTIES SKIP_RETURN_CODE 77)
set_property(TEST cli_fl_thermal_moonshot_full APPEND PROPERTY LABELS slow)
# Development driver: the choice between the sensor and the elapsed-time models on planted logs
# (tuning: tests/drift/planted_logs.h; confirmation: the field machine).
add_executable(choice_study ${CMAKE_CURRENT_LIST_DIR}/choice_study.cpp)
target_link_libraries(choice_study PRIVATE whirl::machine)
target_include_directories(choice_study PRIVATE ${PROJECT_SOURCE_DIR}/tests)
whirl_set_warnings(choice_study)
target_compile_options(choice_study PRIVATE ${WHIRL_LIBRARY_OPTIMIZATION})
# The issue-38 table script on a synthetic FL_THERMAL-shaped log (no shared data needed).
whirl_add_cli_test(cli_fl_thermal_splits ${CMAKE_CURRENT_LIST_DIR}/cli_fl_splits.sh)
# The choice study driver runs (one seed of the tuning set) and prints its summary.
add_test(NAME choice_study_runs
         COMMAND sh -c "$<TARGET_FILE:choice_study> tuning --seeds 1 --quiet | grep -q '^all '")
set_tests_properties(choice_study_runs PROPERTIES LABELS "drift;cli")
