# Sources of src/compare (owned by the compare module). Add files with target_sources(whirl_core PRIVATE ...).
target_sources(whirl_core PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/lead.cpp
  ${CMAKE_CURRENT_LIST_DIR}/metrics.cpp
  ${CMAKE_CURRENT_LIST_DIR}/iso3408.cpp
  ${CMAKE_CURRENT_LIST_DIR}/traditional.cpp
  ${CMAKE_CURRENT_LIST_DIR}/cut.cpp
  ${CMAKE_CURRENT_LIST_DIR}/compare.cpp
  ${CMAKE_CURRENT_LIST_DIR}/evaluate.cpp
  ${CMAKE_CURRENT_LIST_DIR}/report.cpp)
# compare drives the 840D plan (interp/), which is its own library linked to whirl_core: link it
# back (CMake resolves the cycle of the two static libraries) and see its headers ("interp/x.h").
target_link_libraries(whirl_core PUBLIC whirl_interp)
