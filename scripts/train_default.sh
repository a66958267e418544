#!/usr/bin/env bash
# Retrains the shipped model models/default.json from datasets/whirling_500.csv (the shop history,
# also the traditional rule's default history in compare/evaluate/demo) with the
# documented settings (--trainbr-matlab: 5-6-2 network, seed 1, 10 restarts, best log evidence kept; trainbr
# defaults otherwise). Setup-free: it only runs an already built whirl.
# Usage: scripts/train_default.sh [OUT]   (OUT defaults to models/default.json)
#   WHIRL=<path to whirl> overrides the binary (default: ${WHIRL_BUILD_DIR:-build}/whirl).
# The same binary, data and settings give a byte-identical file (tests/nn/default_model.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
WHIRL="${WHIRL:-${WHIRL_BUILD_DIR:-build}/whirl}"
OUT="${1:-models/default.json}"
if [ ! -x "$WHIRL" ]; then
  echo "train_default: '$WHIRL' not found; build first (scripts/build.sh) or set WHIRL" >&2
  exit 1
fi
"$WHIRL" train --data datasets/whirling_500.csv --out "$OUT" --trainbr-matlab --hidden 6 --seed 1 \
  --restarts 10
