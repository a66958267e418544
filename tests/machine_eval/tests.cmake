# Tests of src/lab/machine_eval: the evaluation of both halves on the field world.
# The evaluation against the workpiece-only comparison, the report screw it keeps.
whirl_add_gtest(test_machine_eval SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_machine_eval.cpp)
# Shop training, causal application and the seeds summary.
whirl_add_gtest(test_machine_shop SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_shop.cpp)
# The field world's evaluation: no truth in training, no look-ahead, headlines over seeds.
whirl_add_gtest(test_field_eval SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_field_eval.cpp)
# The field world's export: the files give back what the evaluation sees.
whirl_add_gtest(test_field_export SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_export.cpp)
# The exact-truth ceiling of the machine half: a planted slope is learned by every feature set.
whirl_add_gtest(test_ceiling SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_ceiling.cpp)
