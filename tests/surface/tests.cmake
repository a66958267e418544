# Tests of src/surface (owned by the surface module).
whirl_add_gtest(test_surface SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/test_surface_fit.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_surface_choice.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_surface_report.cpp
  LIBS whirl::surface
  LABELS surface)
whirl_add_cli_test(cli_surface ${CMAKE_CURRENT_LIST_DIR}/cli_surface.sh)
