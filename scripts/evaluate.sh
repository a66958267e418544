#!/usr/bin/env bash
# Evaluation over many screws: the strategy comparison over the validation
# table and N random feasible screws with seeded disturbances; prints per-screw lines, the median
# and worst reduction of the accumulated lead error against the traditional rule, and the share of
# screws reaching ISO 3408-3 P3 and P5. Target: median reduction within 1000 mm >= 85 %.
# Usage: scripts/evaluate.sh [N random screws, default 40] [seed, default 1] [extra whirl evaluate args]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${WHIRL_BUILD_DIR:-build}"
if [[ ! -x "$BUILD_DIR/whirl" ]]; then scripts/build.sh; fi
n="${1:-40}"; seed="${2:-1}"; shift $(( $# > 2 ? 2 : $# ))
"$BUILD_DIR/whirl" evaluate --random "$n" --seed "$seed" --threads 2 "$@"
