# Sources of src/drift (owned by the drift module): run files, seed 000's sensitive points, drift
# models (MLR, dynamic lags, Bayesian-regularized network), cross-run evaluation, report.
find_package(Boost 1.71 REQUIRED)  # header-only Boost.Math: the F distribution's quantile
target_link_libraries(whirl_core PRIVATE Boost::headers)
target_sources(whirl_core PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/run_file.cpp
  ${CMAKE_CURRENT_LIST_DIR}/selection.cpp
  ${CMAKE_CURRENT_LIST_DIR}/regression.cpp
  ${CMAKE_CURRENT_LIST_DIR}/model.cpp
  ${CMAKE_CURRENT_LIST_DIR}/fit.cpp
  ${CMAKE_CURRENT_LIST_DIR}/evaluation.cpp
  ${CMAKE_CURRENT_LIST_DIR}/documents.cpp
  ${CMAKE_CURRENT_LIST_DIR}/report.cpp)
target_sources(whirl_core PRIVATE ${CMAKE_CURRENT_LIST_DIR}/monitor.cpp ${CMAKE_CURRENT_LIST_DIR}/monitor_report.cpp)  # issue 14
