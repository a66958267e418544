# Sources of src/gp (owned by the gp module): Gaussian-process regression (gp.h).
target_sources(whirl_core PRIVATE ${CMAKE_CURRENT_LIST_DIR}/gp.cpp)
