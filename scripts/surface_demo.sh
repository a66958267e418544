#!/usr/bin/env bash
# Demo of the worktable surface on the documented synthetic fields: writes the
# smooth and the bump field (seed 1), fits the cubic and the B-spline to each with an HTML page per
# fit (map with the measured points, cubic-vs-B-spline choice, 840D line per axis), prints the
# choice and the 840D line along X.
# Usage: scripts/surface_demo.sh [out dir, default whirl-surface-demo]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${WHIRL_BUILD_DIR:-build}"
if [[ ! -x "$BUILD_DIR/whirl" ]]; then scripts/build.sh; fi
whirl="$PWD/$BUILD_DIR/whirl"
out="${1:-whirl-surface-demo}"
mkdir -p "$out"
for field in smooth bump; do
  "$whirl" surface synth --field "$field" --seed 1 --out "$out/$field.csv"
  echo "== $field field: cubic or B-spline?"
  "$whirl" surface compare --points "$out/$field.csv"
  for method in cubic bspline; do
    "$whirl" surface fit --points "$out/$field.csv" --method "$method" \
      --out "$out/${field}_$method.json" --report "$out/${field}_$method" > /dev/null
  done
  echo "== $field field, B-spline surface: 840D line along X"
  "$whirl" surface line --surface "$out/${field}_bspline.json" --along x --axis X
done
echo "pages: $out/*/index.html"
