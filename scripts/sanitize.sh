#!/usr/bin/env bash
# Builds whirl and its tests with AddressSanitizer and UndefinedBehaviorSanitizer in build-asan
# (GCC by default; CXX=clang++ for clang) and runs the default test suite there (every label but
# "slow" and "fuzz"; the corpus replays corpus_<harness> included). Any sanitizer report fails the
# test that triggered it: the CLI tests run build-asan/whirl, so every command they call is checked.
# LibTorch stays off (it is not built with the sanitizers). Takes long (about 3 times the normal
# build and a slower suite); run it in the background:
#   nohup scripts/sanitize.sh > sanitize.log 2>&1 &
# Usage: scripts/sanitize.sh [extra ctest args, e.g. -R OutputDir]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD="${WHIRL_ASAN_BUILD_DIR:-build-asan}"
FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
generator=()
if [ ! -f "$BUILD/CMakeCache.txt" ] && command -v ninja > /dev/null; then generator=(-G Ninja); fi
launcher=()
command -v ccache > /dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
# RelWithDebInfo: optimized like the product, with line numbers in the reports (and the shipped
# tables' reproduction tests compare within their tolerance, not byte for byte).
cmake -S . -B "$BUILD" "${generator[@]}" "${launcher[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DWHIRL_WITH_TORCH=OFF -DWHIRL_BUILD_BENCHMARKS=OFF \
  -DCMAKE_CXX_FLAGS="$FLAGS" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" > /dev/null
cmake --build "$BUILD" -j "$(nproc)"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# The suite under the sanitizers is slower: tests without a timeout of their own get 900 s.
ctest --test-dir "$BUILD" -j "$(nproc)" -LE "slow|fuzz" --timeout 900 --output-on-failure "$@"
echo "sanitize: the default suite passed under AddressSanitizer and UBSan ($BUILD)" >&2
