# Sources of src/machine (issue 19): machine thermal errors of the whirling machine and its virtual
# temperature sensors (run files in the drift format).
target_sources(whirl_core PRIVATE ${CMAKE_CURRENT_LIST_DIR}/machine.cpp)
# The evaluation of both halves and its report belong to whirl::compare (defined before this file
# is included); listed here so compare/sources.cmake, which other work edits, stays untouched.
target_sources(whirl_compare PRIVATE ${PROJECT_SOURCE_DIR}/src/compare/machine_eval.cpp
                                     ${PROJECT_SOURCE_DIR}/src/compare/machine_report.cpp)
