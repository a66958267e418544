# Sources of src/family (owned by the family module): column transforms and the choice of the
# workpiece model's family (network or Gaussian process) by cross-validated error.
target_sources(whirl_core PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/transform.cpp
  ${CMAKE_CURRENT_LIST_DIR}/linear.cpp
  ${CMAKE_CURRENT_LIST_DIR}/family.cpp)
