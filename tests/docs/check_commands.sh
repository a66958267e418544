#!/usr/bin/env bash
# The command documentation against the binary (tests/docs/commands_doc.py --check says what):
# args <whirl> <scratch dir> <source dir>.
set -u
exec python3 "$3/tests/docs/commands_doc.py" --whirl "$1" --src "$3" --check
