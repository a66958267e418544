# Sources of src/nn (owned by the nn module): the 5-6-2 network, trainbr, model file, selection.
target_sources(whirl_core PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/network.cpp
  ${CMAKE_CURRENT_LIST_DIR}/trainbr.cpp
  ${CMAKE_CURRENT_LIST_DIR}/dense_kernels.cpp
  ${CMAKE_CURRENT_LIST_DIR}/model.cpp
  ${CMAKE_CURRENT_LIST_DIR}/selection.cpp)
