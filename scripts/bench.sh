#!/usr/bin/env bash
# Builds and runs every Google Benchmark target (Release), 5 repetitions, reporting medians.
# Usage: scripts/bench.sh [benchmark filter regex]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
BUILD_DIR="${WHIRL_BUILD_DIR:-build}"
filter="${1:-.}"
for b in "$BUILD_DIR"/bench/bench_*; do
  echo "== $(basename "$b")"
  "$b" --benchmark_filter="$filter" --benchmark_repetitions=5 \
       --benchmark_report_aggregates_only=true --benchmark_display_aggregates_only=true
done
