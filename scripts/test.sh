#!/usr/bin/env bash
# Setup + configure + build + run the test suite (everything but the labels "slow" and "fuzz";
# scripts/fuzz.sh runs the fuzzers).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
BUILD_DIR="${WHIRL_BUILD_DIR:-build}"
ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$(nproc)" -LE "slow|fuzz" "$@"
