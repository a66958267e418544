# Sources of interp/. Add files with target_sources(whirl_interp PRIVATE ...).
target_sources(whirl_interp PRIVATE ${CMAKE_CURRENT_LIST_DIR}/empty_unit.cpp)
