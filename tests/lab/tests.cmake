# The lab's Python scripts (scripts/*.py: the published comparisons of docs/workpiece-model.md
# and docs/workpiece-history.md, docs/design.md, docs/machine-evaluation.md and
# docs/machine-history.md), each run end to end on a tiny case through
# build/whirl and build/tests/family_bench, their outputs checked for invariants and planted inputs
# for hand-computed figures (labels lab, cli; in the default run). lab_common.sh finds a python
# with numpy and fails when there is none; scikit-learn stays hidden, as on CI.
whirl_add_cli_test(lab_bench_peers ${CMAKE_CURRENT_LIST_DIR}/lab_bench_peers.sh
                   $<TARGET_FILE:family_bench>)
whirl_add_cli_test(lab_choice_diagnosis ${CMAKE_CURRENT_LIST_DIR}/lab_choice_diagnosis.sh
                   $<TARGET_FILE:family_bench>)
whirl_add_cli_test(lab_design_study ${CMAKE_CURRENT_LIST_DIR}/lab_design_study.sh)
whirl_add_cli_test(lab_grey_residuals ${CMAKE_CURRENT_LIST_DIR}/lab_grey_residuals.sh)
whirl_add_cli_test(lab_median_rule_noise ${CMAKE_CURRENT_LIST_DIR}/lab_median_rule_noise.sh)
