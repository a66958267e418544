#!/usr/bin/env bash
# Smoke test of `whirl simulate`: exit codes, outputs, and clear messages for bad screw files.
# Usage: bash cli_simulate.sh <whirl> <scratch dir> <source dir>
set -euo pipefail
WHIRL="$1"; SCRATCH="$2"; SRC="$3"
rm -rf "$SCRATCH"; mkdir -p "$SCRATCH"
REF="$SRC/datasets/screws/reference_80x10x6000.json"
fail() { echo "FAIL: $*" >&2; exit 1; }

"$WHIRL" simulate --help | grep "duration-s" > /dev/null || fail "--help lacks --duration-s"
"$WHIRL" simulate --screw "$REF" --duration-s 600 --out "$SCRATCH/curve.csv" > "$SCRATCH/out.txt"
grep -q "max_elongation_um" "$SCRATCH/out.txt" || fail "no features printed"
head -1 "$SCRATCH/curve.csv" | grep -q '^#' || fail "curve has no provenance comment"
grep -q '^time_s,elongation_um$' "$SCRATCH/curve.csv" || fail "curve header"
rows=$(grep -vc '^#' "$SCRATCH/curve.csv")
[ "$rows" -eq 602 ] || fail "expected 601 samples + header, got $rows lines"
"$WHIRL" simulate --screw "$REF" --duration-s 300 --no-disturbances --json > "$SCRATCH/out.json"
grep -q '"settle_time_s"' "$SCRATCH/out.json" || fail "json lacks settle_time_s"

expect_error() {  # <file> <needle>
  if "$WHIRL" simulate --screw "$1" --duration-s 60 > /dev/null 2> "$SCRATCH/err.txt"; then
    fail "accepted $1"
  fi
  grep -q "$2" "$SCRATCH/err.txt" || { cat "$SCRATCH/err.txt" >&2; fail "message lacks '$2'"; }
}
sed 's/"pitch_mm": 10.0/"pitch_mm": 10.0, "pich_mm": 3/' "$REF" > "$SCRATCH/typo.json"
expect_error "$SCRATCH/typo.json" "unknown key 'pich_mm'"
sed 's/"raceway_radius_mm": 3.7/"raceway_radius_mm": 6.5/' "$REF" > "$SCRATCH/ball.json"
expect_error "$SCRATCH/ball.json" "ball too large"
sed 's/"thread_length_mm": 5100.0/"thread_length_mm": 5900.0/' "$REF" > "$SCRATCH/long.json"
expect_error "$SCRATCH/long.json" "thread_length_mm"
head -c 100 "$REF" > "$SCRATCH/trunc.json"
expect_error "$SCRATCH/trunc.json" "not valid JSON"
if "$WHIRL" simulate --screw "$SCRATCH/missing.json" 2> /dev/null; then fail "missing file accepted"; fi
# Nothing half-written on failure.
[ ! -e "$SCRATCH/none.csv" ] || fail "unexpected file"
"$WHIRL" simulate --screw "$SCRATCH/ball.json" --out "$SCRATCH/none.csv" 2> /dev/null && fail "accepted"
[ ! -e "$SCRATCH/none.csv" ] || fail "curve written for a bad screw"
echo "ok"
