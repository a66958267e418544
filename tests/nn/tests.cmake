# Tests of the nn module: network, trainbr, model file, command line (train, predict).
whirl_add_gtest(test_nn SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/test_network.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_trainbr.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_model.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_parallel_nn.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_ard.cpp
  LIBS whirl::sim)
whirl_add_cli_test(cli_nn ${CMAKE_CURRENT_LIST_DIR}/cli_nn.sh)
# Retrains models/default.json with scripts/train_default.sh (~2 s) and compares its predictions
# within a relative 1e-4 (any compiler or flags), and the file byte for byte with the reference
# flags (WHIRL_EXACT_OUTPUTS).
whirl_add_cli_test(nn_default_model ${CMAKE_CURRENT_LIST_DIR}/default_model.sh
                   $<TARGET_FILE:numeric_diff> ${WHIRL_EXACT_OUTPUTS})
# Coverage of the predictive intervals on a generated 200-row hold-out (~10 s).
whirl_add_gtest(test_calibration SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_calibration.cpp
                LIBS whirl::sim)
