# The structure of the code: the include graph and the CMake links against the layer order
# (layer_order.sh), and a check that the script catches each kind of wrong edge.
add_test(NAME layer_order COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/layer_order.sh ${PROJECT_SOURCE_DIR})
add_test(NAME layer_order_catches
         COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/layer_order_catches.sh ${PROJECT_SOURCE_DIR}
                 ${CMAKE_CURRENT_BINARY_DIR}/scratch/layer_order_catches)
set_tests_properties(layer_order layer_order_catches PROPERTIES LABELS "structure;lint" TIMEOUT 120)
