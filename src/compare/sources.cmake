# src/compare: lead deviation, ISO 3408-3 metrics, traditional rule, comparison, evaluation, report.
# Its own library on top of the core (nn, sim, fit) and interp (the 840D plan it applies), so the
# dependencies run one way: core <- interp <- compare <- whirl.
add_library(whirl_compare STATIC)
add_library(whirl::compare ALIAS whirl_compare)
target_link_libraries(whirl_compare PUBLIC whirl::core whirl_interp)
whirl_set_warnings(whirl_compare)
target_sources(whirl_compare PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/lead.cpp
  ${CMAKE_CURRENT_LIST_DIR}/metrics.cpp
  ${CMAKE_CURRENT_LIST_DIR}/iso3408.cpp
  ${CMAKE_CURRENT_LIST_DIR}/traditional.cpp
  ${CMAKE_CURRENT_LIST_DIR}/cut.cpp
  ${CMAKE_CURRENT_LIST_DIR}/compare.cpp
  ${CMAKE_CURRENT_LIST_DIR}/evaluate.cpp
  ${CMAKE_CURRENT_LIST_DIR}/scenarios.cpp
  ${CMAKE_CURRENT_LIST_DIR}/report.cpp
  ${CMAKE_CURRENT_LIST_DIR}/plan_document.cpp
  ${CMAKE_CURRENT_LIST_DIR}/machine_eval.cpp
  ${CMAKE_CURRENT_LIST_DIR}/machine_report.cpp
  ${CMAKE_CURRENT_LIST_DIR}/machine_nc.cpp)
