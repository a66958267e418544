# Sources of src/sim (owned by the sim module).
target_sources(whirl_core PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/screw.cpp
)
