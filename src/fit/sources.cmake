# Sources of src/fit (owned by the fit module): the LM solver and the elongation-curve models.
target_sources(whirl_core PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/levenberg_marquardt.cpp
  ${CMAKE_CURRENT_LIST_DIR}/arctan_curve.cpp
  ${CMAKE_CURRENT_LIST_DIR}/curve_fit.cpp
  ${CMAKE_CURRENT_LIST_DIR}/simulated_fits.cpp
)
