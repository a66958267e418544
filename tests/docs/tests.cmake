# Documentation checks (labels docs, cli): relative links of README.md and docs/*.md resolve, the
# README stays within 260 lines and names the commands .ci/run relies on (check_docs.sh says how).
add_test(NAME docs_links COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/check_docs.sh ${PROJECT_SOURCE_DIR})
set_tests_properties(docs_links PROPERTIES LABELS "docs;cli" TIMEOUT 60)
# Every `whirl ...` in README.md and docs/*.md uses flags the binary has, and docs/commands.md's
# option table is the binary's (tests/docs/commands_doc.py).
whirl_add_cli_test(docs_commands ${CMAKE_CURRENT_LIST_DIR}/check_commands.sh)
# A newcomer's path: README.md's steps 1-5 run as written on generated files of one's own
# (scripts/newcomer.sh says what fails it).
whirl_add_cli_test(newcomer ${PROJECT_SOURCE_DIR}/scripts/newcomer.sh)
# The validation errors models/README.md quotes are the binary's (check_model_figures.sh).
whirl_add_cli_test(docs_model_figures ${CMAKE_CURRENT_LIST_DIR}/check_model_figures.sh)
