#!/usr/bin/env bash
# Builds the libFuzzer harnesses of every loader with clang (ASan + UBSan) in build-fuzz and runs
# each for SECONDS (default 60) over its seeds and its committed corpus (tests/fuzz/corpus/<h>);
# a crash, sanitizer report, leak, hang, an exception other than InputError or a refusal that
# names no rule stops with the reproducer path. New inputs go to build-fuzz/tests/fuzz_scratch/<h>.
# Needs clang (Debian 'clang'; not part of scripts/setup.sh, the default test run does not need
# it: it replays the committed corpora as the CTests corpus_<h>).
# Usage: scripts/fuzz.sh [SECONDS] [HARNESS...]   e.g. scripts/fuzz.sh 300 model screw
#        scripts/fuzz.sh merge [HARNESS...]       adds to tests/fuzz/corpus/<h> only the inputs
#                                                 of the last runs that reach new code (-merge=1)
set -euo pipefail
cd "$(dirname "$0")/.."
MODE=run
if [ "${1:-}" = merge ]; then MODE=merge; shift; fi
SECONDS_EACH=60
if [ "$MODE" = run ]; then SECONDS_EACH="${1:-60}"; shift || true; fi
HARNESSES=("$@")
FAILED=()
[ ${#HARNESSES[@]} -eq 0 ] && HARNESSES=(csv process_table curve screw model workpiece_model lead \
  iso_table drift_run drift_model machine_profile ballbar surface)
command -v clang++ > /dev/null || { echo "fuzz: clang++ not found (apt-get install clang)" >&2; exit 1; }
BUILD="${WHIRL_FUZZ_BUILD_DIR:-build-fuzz}"
launcher=()
command -v ccache > /dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
CC=clang CXX=clang++ cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DWHIRL_WITH_TORCH=OFF \
  -DWHIRL_BUILD_BENCHMARKS=OFF "${launcher[@]}" > /dev/null
cmake --build "$BUILD" -j "$(nproc)" --target $(printf 'fuzz_%s ' "${HARNESSES[@]}")
seeds_of() {  # the shipped files of the harness's kind (read only; new inputs go to the scratch)
  case "$1" in
    csv|process_table) echo datasets ;;
    screw) echo datasets/screws ;;
    model) echo models ;;
    workpiece_model) echo models tests/fuzz/seeds/workpiece_model ;;
    iso_table) echo datasets/standards ;;
    curve|lead|drift_run|drift_model|ballbar|surface) echo "tests/fuzz/seeds/$1" ;;
    machine_profile) echo datasets/machines tests/interp/data ;;
  esac
}
for h in "${HARNESSES[@]}"; do
  scratch="$BUILD/tests/fuzz_scratch/$h"; corpus="tests/fuzz/corpus/$h"
  mkdir -p "$scratch" "$corpus"
  if [ "$MODE" = merge ]; then
    # Only inputs that reach code the seeds and the committed corpus do not reach: the base (seeds
    # and corpus, named by content) is merged with the scratch; what is new goes to the corpus.
    base=$(mktemp -d)
    # shellcheck disable=SC2046
    find $(seeds_of "$h") "$corpus" -type f -size -64k | while read -r f; do
      cp "$f" "$base/$(sha1sum < "$f" | cut -c1-40)"; done
    before=$(ls "$base")
    "$BUILD/tests/fuzz_$h" -set_cover_merge=1 -use_counters=0 -max_len=16384 -timeout=10 \
      -rss_limit_mb=2048 \
      "$base" "$scratch" 2>&1 | tail -n 1
    for f in "$base"/*; do
      grep -qx "$(basename "$f")" <<< "$before" || cp "$f" "$corpus/"
    done
    rm -rf "$base"
    echo "fuzz: $h corpus now $(ls "$corpus" | wc -l) inputs, $(du -sh "$corpus" | cut -f1)" >&2
    continue
  fi
  echo "fuzz: $h for $SECONDS_EACH s" >&2
  # shellcheck disable=SC2046
  "$BUILD/tests/fuzz_$h" -max_total_time="$SECONDS_EACH" -max_len=16384 -timeout=10 \
    -rss_limit_mb=2048 -artifact_prefix="$BUILD/fuzz_$h-" "$scratch" $(seeds_of "$h") "$corpus" ||
    FAILED+=("$h")  # the others still run; the reproducer is named above
done
[ "$MODE" = merge ] && exit 0
if [ ${#FAILED[@]} -gt 0 ]; then
  echo "fuzz: findings in ${FAILED[*]} (reproducers: $BUILD/fuzz_<harness>-crash-*)" >&2
  exit 1
fi
echo "fuzz: no finding in ${HARNESSES[*]}" >&2
