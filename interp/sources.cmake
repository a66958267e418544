# Sources of interp/ (compensation points and SINUMERIK 840D setting data).
target_sources(whirl_interp PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/breakpoints.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sinumerik.cpp
  ${CMAKE_CURRENT_LIST_DIR}/machine_profile.cpp
  ${CMAKE_CURRENT_LIST_DIR}/drift_action.cpp
)
