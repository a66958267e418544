#!/usr/bin/env bash
# Setup + build + run the whole whirl pipeline on the shipped defaults.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
BUILD_DIR="${WHIRL_BUILD_DIR:-build}"
"$BUILD_DIR/whirl" demo "$@"
