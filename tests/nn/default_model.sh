#!/usr/bin/env bash
# Retraining with scripts/train_default.sh reproduces models/default.json byte for byte.
# Usage (CTest): default_model.sh <whirl> <scratch dir> <source dir>
set -euo pipefail
whirl="$1"; scratch="$2"; src="$3"
rm -rf "$scratch"; mkdir -p "$scratch"
WHIRL="$whirl" bash "$src/scripts/train_default.sh" "$scratch/default.json" > "$scratch/stdout" 2> "$scratch/stderr"
if ! cmp "$scratch/default.json" "$src/models/default.json"; then
  echo "FAIL: retrained model differs from models/default.json (dataset or trainer changed?" \
       "rerun scripts/train_default.sh and commit the model)" >&2
  diff <(head -c 2000 "$scratch/default.json") <(head -c 2000 "$src/models/default.json") >&2 || true
  exit 1
fi
echo "ok: models/default.json reproduced byte for byte"
