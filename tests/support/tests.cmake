# Test tools shared by the module tests.
# numeric_diff: text files equal up to a stated tolerance on numbers (reproduction tests).
add_executable(numeric_diff ${CMAKE_CURRENT_LIST_DIR}/numeric_diff.cpp)
target_compile_features(numeric_diff PRIVATE cxx_std_17)
whirl_set_warnings(numeric_diff)
