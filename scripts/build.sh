#!/usr/bin/env bash
# Configures and builds whirl (Release by default) into ./build. Usage: scripts/build.sh [extra cmake args]
# A new build directory uses Ninja when it is installed (scripts/setup.sh installs it): it compiles
# a module's files while the libraries below it still link, which keeps both cores busy.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${WHIRL_BUILD_DIR:-build}"
generator=()
if [ ! -f "$BUILD_DIR/CMakeCache.txt" ] && command -v ninja > /dev/null; then generator=(-G Ninja); fi
cmake -S . -B "$BUILD_DIR" "${generator[@]}" -DCMAKE_BUILD_TYPE="${CMAKE_BUILD_TYPE:-Release}" "$@"
cmake --build "$BUILD_DIR" -j "$(nproc)"
