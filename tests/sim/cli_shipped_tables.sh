#!/usr/bin/env bash
# The shipped simulated tables match what `whirl dataset` regenerates (datasets/README.md).
# Usage: bash cli_shipped_tables.sh <whirl> <scratch dir> <source dir> small|500
set -euo pipefail
WHIRL="$1"; SCRATCH="$2"; SRC="$3"; WHICH="${4:-small}"
rm -rf "$SCRATCH"; mkdir -p "$SCRATCH"
check() {  # <count> <seed> <file>
  "$WHIRL" dataset --count "$1" --seed "$2" --out "$SCRATCH/$3" 2> /dev/null > /dev/null
  # Compare the data rows (header and numbers) exactly; comments may name other paths.
  if ! diff <(grep -v '^#' "$SRC/datasets/$3") <(grep -v '^#' "$SCRATCH/$3") > "$SCRATCH/diff.txt"; then
    head -20 "$SCRATCH/diff.txt" >&2
    echo "FAIL: datasets/$3 differs from 'whirl dataset --count $1 --seed $2'" >&2
    exit 1
  fi
}
if [ "$WHICH" = "500" ]; then
  check 500 3 whirling_500.csv
else
  check 20 1 whirling_train.csv
  check 5 2 whirling_validation.csv
  grep -q '^# *regenerate: whirl dataset --count 20 --seed 1' "$SRC/datasets/whirling_train.csv"
fi
echo "ok"
