# Tests of src/surface (owned by the surface module).
whirl_add_gtest(test_surface SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/test_surface_fit.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_surface_choice.cpp
  LIBS whirl::surface
  LABELS surface)
