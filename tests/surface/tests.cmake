# Tests of src/surface (owned by the surface module).
set(WHIRL_SURFACE_TESTS
  ${CMAKE_CURRENT_LIST_DIR}/test_surface_fit.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_surface_choice.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_surface_report.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_per_point.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_surface_inputs.cpp)
if(EXISTS ${PROJECT_SOURCE_DIR}/src/drift/model.h)
  list(APPEND WHIRL_SURFACE_TESTS ${CMAKE_CURRENT_LIST_DIR}/test_drift_adapter.cpp)
endif()
whirl_add_gtest(test_surface SOURCES ${WHIRL_SURFACE_TESTS} LIBS whirl::surface LABELS surface)
whirl_add_cli_test(cli_surface ${CMAKE_CURRENT_LIST_DIR}/cli_surface.sh)
