#!/usr/bin/env bash
# Regenerates the shipped simulated tables (datasets/README.md). Usage: scripts/make_datasets.sh [whirl binary]
set -euo pipefail
cd "$(dirname "$0")/.."
WHIRL="${1:-${WHIRL_BUILD_DIR:-build}/whirl}"
"$WHIRL" dataset --count 20 --seed 1 --out datasets/whirling_train.csv
"$WHIRL" dataset --count 5 --seed 2 --out datasets/whirling_validation.csv
"$WHIRL" dataset --count 500 --seed 3 --out datasets/whirling_500.csv
