# Tests of the nn module: network, trainbr, model file, command line (train, predict).
whirl_add_gtest(test_nn SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/test_network.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_trainbr.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_model.cpp
  LABELS nn)
