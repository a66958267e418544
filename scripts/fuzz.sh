#!/usr/bin/env bash
# Builds the libFuzzer harnesses of every loader with clang (ASan + UBSan) in build-fuzz and runs
# each for SECONDS (default 60) over its seed corpus; a crash, sanitizer report, leak, hang or an
# exception other than InputError stops with the reproducer path. Needs clang (Debian 'clang';
# not part of scripts/setup.sh, the default test run does not need it).
# Usage: scripts/fuzz.sh [SECONDS] [HARNESS...]   e.g. scripts/fuzz.sh 300 model screw
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_EACH="${1:-60}"; shift || true
HARNESSES=("$@")
[ ${#HARNESSES[@]} -eq 0 ] && HARNESSES=(csv process_table curve screw model lead iso_table drift_run \
  drift_model machine_profile ballbar surface)
command -v clang++ > /dev/null || { echo "fuzz: clang++ not found (apt-get install clang)" >&2; exit 1; }
BUILD="${WHIRL_FUZZ_BUILD_DIR:-build-fuzz}"
CC=clang CXX=clang++ cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DWHIRL_WITH_TORCH=OFF \
  -DWHIRL_BUILD_BENCHMARKS=OFF > /dev/null
cmake --build "$BUILD" -j "$(nproc)" --target $(printf 'fuzz_%s ' "${HARNESSES[@]}")
seeds_of() {  # the shipped files of the harness's kind (read only; new inputs go to the corpus)
  case "$1" in
    csv|process_table) echo datasets ;;
    screw) echo datasets/screws ;;
    model) echo models ;;
    iso_table) echo datasets/standards ;;
    curve|lead|drift_run|drift_model|ballbar|surface) echo "tests/fuzz/seeds/$1" ;;
    machine_profile) echo datasets/machines ;;
  esac
}
for h in "${HARNESSES[@]}"; do
  corpus="$BUILD/tests/fuzz_corpus/$h"; mkdir -p "$corpus"
  echo "fuzz: $h for $SECONDS_EACH s" >&2
  "$BUILD/tests/fuzz_$h" -max_total_time="$SECONDS_EACH" -max_len=8192 -timeout=10 \
    -rss_limit_mb=2048 -artifact_prefix="$BUILD/fuzz_$h-" "$corpus" "$(seeds_of "$h")"
done
echo "fuzz: no finding in ${HARNESSES[*]}" >&2
