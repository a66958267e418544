# src/ballbar: ball-bar measurement of spindle thermal drift (seed 001) and circle-test diagnostics.
# Its own library on whirl::core and whirl::interp (the 840D sign convention of SD43900).
add_library(whirl_ballbar STATIC)
add_library(whirl::ballbar ALIAS whirl_ballbar)
target_link_libraries(whirl_ballbar PUBLIC whirl::core whirl_interp)
whirl_set_warnings(whirl_ballbar)
target_sources(whirl_ballbar PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/trilateration.cpp
  ${CMAKE_CURRENT_LIST_DIR}/drift.cpp
  ${CMAKE_CURRENT_LIST_DIR}/circle.cpp
  ${CMAKE_CURRENT_LIST_DIR}/simulate.cpp)
