# Sources of src/machine (issue 19): machine thermal errors of the whirling machine and its virtual
# temperature sensors (run files in the drift format). The evaluation of both halves, its report
# and the combined programs are in whirl::compare (compare/sources.cmake).
target_sources(whirl_core PRIVATE ${CMAKE_CURRENT_LIST_DIR}/machine.cpp)
