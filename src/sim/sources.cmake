# Sources of src/sim (owned by the sim module).
target_sources(whirl_core PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/screw.cpp
  ${CMAKE_CURRENT_LIST_DIR}/physics.cpp
  ${CMAKE_CURRENT_LIST_DIR}/features.cpp
  ${CMAKE_CURRENT_LIST_DIR}/simulator.cpp
  ${CMAKE_CURRENT_LIST_DIR}/dataset.cpp
)
