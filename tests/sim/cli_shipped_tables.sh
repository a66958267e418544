#!/usr/bin/env bash
# The shipped simulated tables match what `whirl dataset` regenerates (datasets/README.md).
# Usage: bash cli_shipped_tables.sh <whirl> <scratch dir> <source dir> small|500 [<numeric_diff>]
# With numeric_diff (the default CTest run): every number within a relative 1e-6 (+ 1e-9 absolute)
# of the shipped one, so other compilers and flags (FMA under -march=x86-64-v3) pass. Without it
# (CTest label 'slow', *_exact): byte for byte, which holds only for the flags the tables were
# made with (GCC, CMAKE_BUILD_TYPE=Release, no -march/-ffast-math).
set -euo pipefail
WHIRL="$1"; SCRATCH="$2"; SRC="$3"; WHICH="${4:-small}"; NUMDIFF="${5:-}"
rm -rf "$SCRATCH"; mkdir -p "$SCRATCH"
same() {  # <expected> <actual>: data rows (header and numbers); comments may name other paths
  if [ -n "$NUMDIFF" ]; then
    "$NUMDIFF" --rel 1e-6 --abs 1e-9 --skip-comments "$1" "$2"
  else
    diff <(grep -v '^#' "$1") <(grep -v '^#' "$2")
  fi
}
check() {  # <count> <seed> <file>
  "$WHIRL" dataset --count "$1" --seed "$2" --out "$SCRATCH/$3" 2> /dev/null > /dev/null
  if ! same "$SRC/datasets/$3" "$SCRATCH/$3" > "$SCRATCH/diff.txt" 2>&1; then
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
