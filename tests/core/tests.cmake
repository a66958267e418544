whirl_add_gtest(test_core SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/test_csv.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_files.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_safe_output.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_file_safety.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_json_fields.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_numbers.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_random.cpp)

whirl_add_cli_test(cli_terminal ${CMAKE_CURRENT_LIST_DIR}/cli_terminal.sh)
