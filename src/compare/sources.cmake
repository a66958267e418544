# Sources of src/compare (owned by the compare module). Add files with target_sources(whirl_core PRIVATE ...).
target_sources(whirl_core PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/lead.cpp
  ${CMAKE_CURRENT_LIST_DIR}/metrics.cpp
  ${CMAKE_CURRENT_LIST_DIR}/iso3408.cpp
  ${CMAKE_CURRENT_LIST_DIR}/traditional.cpp
  ${CMAKE_CURRENT_LIST_DIR}/cut.cpp)
