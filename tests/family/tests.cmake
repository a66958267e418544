# Tests of the family module: column transforms and the choice of the model family.
whirl_add_gtest(test_family SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/test_transform.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_linear.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_family.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_table_checks.cpp
  LABELS family)
# Development driver of scripts/bench_peers.py (--family-bench): not a test, not installed.
add_executable(family_bench ${CMAKE_CURRENT_LIST_DIR}/family_bench.cpp)
target_link_libraries(family_bench PRIVATE whirl::family)
whirl_set_warnings(family_bench)
target_compile_options(family_bench PRIVATE ${WHIRL_LIBRARY_OPTIMIZATION})
# Development driver: the practical-equivalence rule on bent power laws (docs/workpiece-history.md).
add_executable(bend_probe ${CMAKE_CURRENT_LIST_DIR}/bend_probe.cpp)
target_link_libraries(bend_probe PRIVATE whirl::family)
target_include_directories(bend_probe PRIVATE ${PROJECT_SOURCE_DIR}/tests)
whirl_set_warnings(bend_probe)
target_compile_options(bend_probe PRIVATE ${WHIRL_LIBRARY_OPTIMIZATION})
# Smoke test: the probe runs and prints its 12 rows under the header.
add_test(NAME bend_probe_runs
         COMMAND sh -c "test \"$($<TARGET_FILE:bend_probe> | wc -l)\" -eq 13")
set_tests_properties(bend_probe_runs PROPERTIES LABELS "family;cli")
