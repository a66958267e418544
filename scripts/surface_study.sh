#!/usr/bin/env bash
# Surface study: cubic polynomial vs B-spline on the documented synthetic fields
# (src/lab/synthetic/surface.h) over many noise seeds, through the command line only:
#   whirl surface synth --field F --noise-um S --seed k, then whirl surface compare --json,
# and the 840D line of the noise-free smooth and bump fields. Prints, per setting, the mean
# leave-one-out RMS of both methods on the common points, how often the B-spline is lower, how
# often the oscillation note is raised.
# Usage: scripts/surface_study.sh [seeds, default 20]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${WHIRL_BUILD_DIR:-build}"
if [[ ! -x "$BUILD_DIR/whirl" ]]; then scripts/build.sh; fi
whirl="$PWD/$BUILD_DIR/whirl"
seeds="${1:-20}"
tmp="$(mktemp -d)"; trap 'rm -rf "$tmp"' EXIT
study() {  # study <label> <synth args...>
  local label="$1"; shift
  for ((k = 1; k <= seeds; ++k)); do
    "$whirl" surface synth "$@" --seed "$k" --out "$tmp/p.csv" > /dev/null
    "$whirl" surface compare --points "$tmp/p.csv" --json > "$tmp/c$k.json"
  done
  python3 - "$label" "$tmp" "$seeds" <<'PY'
import json, sys
label, tmp, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
cs = [json.load(open(f"{tmp}/c{k}.json")) for k in range(1, n + 1)]
cub = sum(c["cubic"]["loo_common"]["rms_um"] for c in cs) / n
bsp = sum(c["bspline"]["loo_common"]["rms_um"] for c in cs) / n
wins = sum(c["bspline"]["loo_common"]["rms_um"] < c["cubic"]["loo_common"]["rms_um"] for c in cs)
osc = sum(c["cubic_oscillates"] for c in cs)
print(f"{label:44s} LOO RMS cubic {cub:5.2f} um, B-spline {bsp:5.2f} um; "
      f"B-spline lower {wins:2d}/{n}; oscillation note {osc:2d}/{n}")
PY
}
echo "leave-one-out on the common points (9 x 7 grid over 800 x 500 mm, $seeds noise seeds):"
study "smooth, noise 1 um"            --field smooth --noise-um 1
study "smooth, noise 2 um"            --field smooth --noise-um 2
study "bump 15 um, noise 1 um (default)" --field bump
study "bump 15 um, noise 1.5 um"      --field bump --noise-um 1.5
study "bump 15 um, noise 2 um"        --field bump --noise-um 2
study "bump 20 um, noise 2 um, 11 x 9 grid" --field bump --bump-um 20 --noise-um 2 --nx 11 --ny 9
echo
echo "840D line along X over the whole table (noise-free fields, cubic / B-spline surface):"
for field in smooth bump; do
  "$whirl" surface synth --field "$field" --noise-um 0 --out "$tmp/$field.csv" > /dev/null
  for method in cubic bspline; do
    "$whirl" surface fit --points "$tmp/$field.csv" --method "$method" --out "$tmp/s.json" > /dev/null
    for along in x y; do
      "$whirl" surface line --surface "$tmp/s.json" --along "$along" --json > "$tmp/l.json"
      python3 - "$field" "$method" "$along" "$tmp/l.json" <<'PY'
import json, sys
field, method, along, path = sys.argv[1:]
l = json.load(open(path))
print(f"  {field:6s} {method:7s} along {along}: error max {l['error_max_abs_um']:5.1f} / RMS "
      f"{l['error_rms_um']:5.1f} um; left by SD43900 alone {l['offset_only_max_abs_um']:5.1f} / "
      f"{l['offset_only_rms_um']:4.1f} um; left by the line {l['uncorrected_max_abs_um']:5.1f} / "
      f"{l['uncorrected_rms_um']:4.1f} um (SD43910 {l['sd43910']:.3e})")
PY
    done
  done
done
