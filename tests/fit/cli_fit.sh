#!/usr/bin/env bash
# Smoke test of 'whirl curve' and 'whirl fit': args <whirl> <scratch dir> <source dir>.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"
source "$SRC/tests/support/cli_common.sh"

"$W" fit --help > "$D/help.txt" || fail "fit --help"
grep -q "elongation_um" "$D/help.txt" || fail "fit --help does not explain the columns"
"$W" curve --help > "$D/curve_help.txt" || fail "curve --help"
grep -q "\[um\]" "$D/curve_help.txt" || fail "curve --help has no units"

# A curve from given features, then its fit: the arctan model recovers L, t_s, k and p.
"$W" curve --max-elongation-um 30 --settle-time-s 250 --shape-k 4 --time-exponent 0.8 --duration-s 900 \
  --out "$D/c.csv" \
  || fail "curve --out"
head -1 "$D/c.csv" | grep -q "^#" || fail "curve CSV has no provenance comment"
grep -q "^time_s,elongation_um" "$D/c.csv" || fail "curve CSV header"
"$W" fit --curve "$D/c.csv" > "$D/fit.txt" || fail "fit --curve"
grep -q "best fit (smallest RMS residual): arctan" "$D/fit.txt" || fail "arctan is not best: $(cat "$D/fit.txt")"
"$W" fit --curve "$D/c.csv" --json > "$D/fit.json" || fail "fit --json"
grep -q '"best_model": "arctan"' "$D/fit.json" || fail "fit --json best model"
# k fitted with all parameters free is 4 within 1 %: read it from the JSON.
k=$(tr -d ' \n' < "$D/fit.json" | grep -o '"shape_k":[0-9.e+-]*' | head -1 | cut -d: -f2)
awk -v k="$k" 'BEGIN { exit !(k > 3.96 && k < 4.04) }' || fail "fitted k = $k, expected 4"
p=$(tr -d ' \n' < "$D/fit.json" | grep -o '"time_exponent":[0-9.e+-]*' | head -1 | cut -d: -f2)
awk -v p="$p" 'BEGIN { exit !(p > 0.79 && p < 0.81) }' || fail "fitted p = $p, expected 0.8"
grep -q "p = 0.8" "$D/c.csv" || fail "curve CSV comment does not give p"
# The row for table.csv is printed: the features (not a free fit's L, t_s), equal to the JSON's.
python3 - "$D/fit.json" "$D/fit.txt" <<'PY' || fail "fit --curve: no table.csv row of the features: $(cat "$D/fit.txt")"
import json, sys
f = json.load(open(sys.argv[1]))["features"]
lines = open(sys.argv[2]).read().splitlines()
i = lines.index("hardness_hrc,diameter_mm,pitch_mm,raceway_radius_mm,cutting_speed_m_min,max_elongation_um,settle_time_s")
row = lines[i + 1].split(",")
assert abs(float(row[5]) - f["max_elongation_um"]) < 1e-4 and abs(float(row[6]) - f["settle_time_s"]) < 1e-2, row
assert "go into table.csv" in open(sys.argv[2]).read()
PY
grep -Eq "::|kDefault" "$D/help.txt" && fail "fit --help names internals: $(grep -E '::|kDefault' "$D/help.txt")"
# A logger's clock (time 1000 s at the start of the cut): the features count from the first
# sample, and so do the models (they were fitted on absolute time: R^2 below 0).
awk -F, -v OFS=, '/^#/ || /^time_s/ { print; next } { print $1 + 1000, $2 }' "$D/c.csv" > "$D/clock.csv"
"$W" fit --curve "$D/clock.csv" --json > "$D/clock.json" 2> "$D/clock.err" || fail "fit clock: $(cat "$D/clock.err")"
grep -q "time starts at 1000 s" "$D/clock.err" || fail "clock: no warning: $(cat "$D/clock.err")"
python3 - "$D/fit.json" "$D/clock.json" <<'PY' || fail "clock.csv: the fits differ from c.csv's"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert a["features"]["settle_time_s"] == b["features"]["settle_time_s"], (a["features"], b["features"])
assert b["shape_with_features_fixed"]["r_squared"] > 0.99, b["shape_with_features_fixed"]
arctan = lambda j: next(m for m in j["models"] if m["model"] == "arctan")
assert b["fit_window_s"][0] == 0, b["fit_window_s"]
assert abs(arctan(a)["r_squared"] - arctan(b)["r_squared"]) < 1e-6, (arctan(a), arctan(b))
PY
# A record too short for its settle time: the warning says how long to log.
"$W" curve --max-elongation-um 30 --settle-time-s 250 --duration-s 300 --out "$D/short.csv" || fail "short curve"
"$W" fit --curve "$D/short.csv" > /dev/null 2> "$D/short.err" || fail "fit short"
grep -q "at least twice the settle time" "$D/short.err" || fail "short record: $(cat "$D/short.err")"
# Its numbers are message numbers (6 significant digits, core/numbers.h MessageNumber), not a
# file's round-trip digits (L = 15.77392385154572 um).
grep -Eq "[0-9]{7}" "$D/short.err" && fail "short record: round-trip digits in the warning: $(cat "$D/short.err")"
"$W" fit --curve "$D/short.csv" --json > "$D/short.json" 2> /dev/null || fail "fit short --json"
grep -Eq '"criterion": "[^"]*[0-9]{7}' "$D/short.json" && fail "round-trip digits in the criterion: $(grep criterion "$D/short.json")"
expect_fail "time-exponent" "$W" curve --max-elongation-um 3 --settle-time-s 100 --time-exponent 1.2

# Bad curves: a gap, non-increasing time, a missing file.
printf 'time_s,elongation_um\n0,0\n1,1\n2,2\n3,3\n4,4\n5,5\n100,6\n' > "$D/gap.csv"
expect_fail "gap" "$W" fit --curve "$D/gap.csv"
printf 'time_s,elongation_um\n0,0\n1,1\n1,2\n2,3\n' > "$D/dup.csv"
expect_fail "increas" "$W" fit --curve "$D/dup.csv"
expect_fail "none.csv" "$W" fit --curve "$D/none.csv"
expect_fail "--curve" "$W" fit
# curve: negative elongation and half-given features are rejected.
expect_fail "--max-elongation-um" "$W" curve --max-elongation-um -3 --settle-time-s 100
expect_fail "together" "$W" curve --max-elongation-um 3
echo "ok"
