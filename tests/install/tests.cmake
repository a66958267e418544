# An install to a temporary prefix (cmake --install) from which 'whirl demo' runs elsewhere.
add_test(NAME install_demo
         COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/install_demo.sh ${PROJECT_BINARY_DIR}
                 ${CMAKE_CURRENT_BINARY_DIR}/scratch/install_demo ${PROJECT_SOURCE_DIR})
set_tests_properties(install_demo PROPERTIES LABELS "install;cli" TIMEOUT 300)
