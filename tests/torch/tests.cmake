# LibTorch cross-check tests: only when the whirl::torch target exists (find_package(Torch)).
if(TARGET whirl::torch)
  whirl_add_gtest(test_torch SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_torch.cpp)

  # Writes a small model and its table for the CLI smoke tests (no simulator, no `whirl train`).
  add_executable(torch_make_model ${CMAKE_CURRENT_LIST_DIR}/make_model.cpp)
  target_link_libraries(torch_make_model PRIVATE whirl::nn)
  target_include_directories(torch_make_model PRIVATE ${CMAKE_CURRENT_LIST_DIR})
  target_compile_options(torch_make_model PRIVATE ${WHIRL_TEST_OPTIMIZATION})
  whirl_set_warnings(torch_make_model)

  whirl_add_cli_test(cli_crosscheck ${CMAKE_CURRENT_LIST_DIR}/cli_crosscheck.sh
                     $<TARGET_FILE:torch_make_model>)
  whirl_add_cli_test(cli_export ${CMAKE_CURRENT_LIST_DIR}/cli_export.sh
                     $<TARGET_FILE:torch_make_model>)
endif()
