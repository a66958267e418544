# src/surface: thermal error over the worktable (seed 003): cubic polynomial and B-spline surfaces,
# the choice between them, the 840D per-axis line, synthetic fields, the HTML map, per-point models.
# Its own library on core and interp (the 840D sign and MD32760 conventions): core <- interp <- surface.
add_library(whirl_surface STATIC)
add_library(whirl::surface ALIAS whirl_surface)
target_link_libraries(whirl_surface PUBLIC whirl::core whirl_interp)
whirl_set_warnings(whirl_surface)
target_sources(whirl_surface PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/points.cpp
  ${CMAKE_CURRENT_LIST_DIR}/cubic.cpp
  ${CMAKE_CURRENT_LIST_DIR}/bspline.cpp
  ${CMAKE_CURRENT_LIST_DIR}/surface.cpp
  ${CMAKE_CURRENT_LIST_DIR}/choice.cpp
  ${CMAKE_CURRENT_LIST_DIR}/line840d.cpp
  ${CMAKE_CURRENT_LIST_DIR}/synthetic.cpp
  ${CMAKE_CURRENT_LIST_DIR}/report.cpp
  ${CMAKE_CURRENT_LIST_DIR}/per_point.cpp)
# Per-point models from the drift module (issue 13), once src/drift is in the tree.
if(EXISTS ${CMAKE_CURRENT_LIST_DIR}/../drift/model.h)
  target_sources(whirl_surface PRIVATE ${CMAKE_CURRENT_LIST_DIR}/drift_adapter.cpp)
  target_compile_definitions(whirl_surface PUBLIC WHIRL_HAVE_DRIFT=1)
else()
  message(STATUS "whirl: src/drift not in the tree: surface per-point models from drift disabled")
endif()
