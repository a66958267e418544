#!/usr/bin/env bash
# Smoke test of the frictions a first user met in 'whirl drift': a UTF-8 byte-order mark before the
# time column keeps the column (minutes, or seconds converted); the events CSV of a run without
# time names its sample column once; 'fit' prints each coefficient with its unit (um/K for a
# temperature rise, um per rpm for a speed input, um for the intercept), not um/unit; a minutes
# flag on a run without recorded time is refused by name (its samples would be read as minutes).
# Args: <whirl> <scratch dir> <source dir>.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"
source "$SRC/tests/support/cli_common.sh"

# A deterministic run (awk): sensors a (fast rise A) and b (slow ramp B), spindle speed, error
# 2 A - 1.5 B + 0.001 rpm; time in the first column named by <time header>, scaled by <factor>.
make_run() {  # make_run <file> <time header> <factor>
  awk -v h="$2" -v f="$3" 'BEGIN {
    print h ",a_C,b_C,spindle_rpm,err_um";
    for (k = 0; k < 300; k++) {
      A = 8 * (1 - exp(-k / 30)); B = k / 40; r = (k < 250 ? 2000 : 0);
      printf "%g,%.4f,%.4f,%d,%.4f\n", k * f, 20 + A, 21 + B, r, 2 * A - 1.5 * B + 0.001 * r + 0.05 * sin(7 * k);
    }
  }' > "$1"
}
make_run "$D/min.csv" time_min 1
make_run "$D/s.csv" time_s 60
printf '\xef\xbb\xbf' | cat - "$D/min.csv" > "$D/bom_min.csv"
printf '\xef\xbb\xbf' | cat - "$D/s.csv" > "$D/bom_s.csv"
cut -d, -f2- "$D/min.csv" > "$D/notime.csv"

# 1. The BOM is not part of the first header: the time column is found, in minutes.
for f in bom_min bom_s; do
  "$W" drift fit --run "$D/$f.csv" --error err_um --sensors a_C,b_C --candidates sensors \
    --out "$D/m_$f.json" > "$D/fit_$f.txt" 2> "$D/fit_$f.err" || fail "fit $f: $(cat "$D/fit_$f.err")"
  grep -qi "no complete time column\|sample index" "$D/fit_$f.txt" "$D/fit_$f.err" &&
    fail "$f: the time column was not recognised: $(cat "$D/fit_$f.err")"
  python3 - "$D/m_$f.json" <<'PY' || fail "$f: model time unit"
import json, sys
m = json.load(open(sys.argv[1]))
m = m.get("model", m)
assert m["time_unit"] == "min", m["time_unit"]
PY
done

# 2. Events CSV of a run without time: one sample column, no duplicate.
"$W" drift fit --run "$D/notime.csv" --error err_um --sensors a_C,b_C --candidates sensors \
  --out "$D/m_notime.json" > /dev/null 2>&1 || fail "fit on a run without time"
"$W" drift monitor --model "$D/m_notime.json" --run "$D/notime.csv" --check-every-samples 60 \
  --threshold-um 0.01 --events "$D/events.csv" > /dev/null 2> "$D/events.err" ||
  fail "monitor --events: $(cat "$D/events.err")"
header=$(grep -v '^#' "$D/events.csv" | head -1)
[ "$(tr ',' '\n' <<< "$header" | sort | uniq -d)" = "" ] || fail "events header repeats a column: $header"
tr ',' '\n' <<< "$header" | grep -qx "sample" || fail "events header has no sample column: $header"

# 3. Units in the printed coefficients.
"$W" drift fit --run "$D/min.csv" --error err_um --sensors a_C,b_C --inputs spindle_rpm \
  --candidates sensors --out "$D/m_units.json" > "$D/fit_units.txt" 2> /dev/null || fail "fit with an input"
grep -q "um/unit" "$D/fit_units.txt" && fail "fit prints um/unit: $(cat "$D/fit_units.txt")"
grep -q "a_C.*\[um/K\]" "$D/fit_units.txt" || fail "fit prints no um/K for a_C: $(cat "$D/fit_units.txt")"
grep -q "spindle_rpm.*\[um/rpm\]" "$D/fit_units.txt" || fail "fit prints no um/rpm: $(cat "$D/fit_units.txt")"

# 4. A minutes flag on a run without recorded time is refused by name; the samples flag works.
for flag in --check-every-min --refit-every-min --start-min; do
  expect_fail "$flag" "$W" drift monitor --model "$D/m_notime.json" --run "$D/notime.csv" "$flag" 10
done
echo "OK"
