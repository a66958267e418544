#!/usr/bin/env bash
# Smoke test of 'whirl machine export' and 'whirl machine ceiling': the export's day logs are run
# files 'whirl drift fit' and 'drift predict' accept, the truth is in files named as such, the
# README says where the files came from; 'drift fit-grey' fits from its records.json; bad input
# is refused with exit 1 and nothing written; the ceiling prints its table with every feature set
# and estimator.
set -u
W="$1"; D="$2"; S="$3"
rm -rf "$D"; mkdir -p "$D"
source "$S/tests/support/cli_common.sh"

"$W" machine export --help > "$D/export_help.txt" || fail "machine export --help"
grep -q "\[W/(m^2 K)\]" "$D/export_help.txt" || fail "export --help names no unit"
"$W" machine export --out-dir "$D/x" --past-days 1 --test-days 1 --seed 3 \
  --blank-contact-std-k 0.3 > "$D/export.txt" || fail "machine export"
for f in README.md days.csv records.csv records.json cuts.csv truth_cuts.csv day+000_test.csv \
  truth_day+000_test.csv; do
  [ -f "$D/x/$f" ] || fail "export: $f missing"
done
grep -q "whirl machine export --out-dir DIR --scenario production --seed 3" "$D/x/README.md" \
  || fail "README without the command"
grep -q "blank-contact-std-k 0.3" "$D/x/README.md" || fail "README without the world's flags"
grep -q "^# TRUTH" "$D/x/truth_cuts.csv" || fail "truth file not marked as truth"
grep -v '^#' "$D/x/day+000_test.csv" | head -n 1 | grep -q "blank_contact_C" \
  || fail "no contact reading in the log"
if grep -v '^#' "$D/x"/day*_*.csv | head -n 1 | grep -q "_true"; then fail "truth in a day log"; fi
idle=$(ls "$D/x"/day-*_warmup_test.csv | head -n 1)
hist=$(ls "$D/x"/day-*_history.csv | head -n 1)
"$W" drift fit --idle "$idle" --cutting "$hist" --error check_ring_um --candidates sensors \
  --out "$D/model.json" > /dev/null 2> "$D/fit_err.txt" || fail "drift fit on exported logs: $(cat "$D/fit_err.txt")"
"$W" drift predict --model "$D/model.json" --run "$D/x/day+000_test.csv" --json > "$D/pred.json" \
  2> /dev/null || fail "drift predict on an exported test day"
grep -q '"residual"' "$D/pred.json" || fail "prediction has no residual"
"$W" drift fit-grey --records "$D/x/records.json" \
  --spec "$S/datasets/machines/field_grey_box_spec.json" --out "$D/grey.json" > /dev/null \
  2> "$D/grey_err.txt" || fail "drift fit-grey on the exported records: $(cat "$D/grey_err.txt")"
# The same with duty inputs (the control's signals of the exported logs): fitted and printed; a
# duty input the logs lack is named.
sed 's/"blank_sensor": "ambient_C",/"blank_sensor": "ambient_C", "offset_duty": ["ring_load_pct"], "slope_duty": ["z_speed_mm_min"],/' \
  "$S/datasets/machines/field_grey_box_spec.json" > "$D/spec_duty.json"
grep -q offset_duty "$D/spec_duty.json" || fail "the duty spec was not made"
"$W" drift fit-grey --records "$D/x/records.json" --spec "$D/spec_duty.json" \
  --out "$D/grey_duty.json" > "$D/grey_duty.txt" 2> "$D/grey_err.txt" \
  || fail "drift fit-grey with duty inputs: $(cat "$D/grey_err.txt")"
grep -q "ring_load_pct .*duty input" "$D/grey_duty.txt" || fail "fit-grey prints no duty input"
grep -q '"slope_duty"' "$D/grey_duty.json" || fail "the model file has no slope_duty"
sed 's/z_speed_mm_min/z_speeed/' "$D/spec_duty.json" > "$D/spec_bad.json"
expect_fail "z_speeed" "$W" drift fit-grey --records "$D/x/records.json" \
  --spec "$D/spec_bad.json" --out "$D/grey_bad.json"
[ ! -e "$D/grey_bad.json" ] || fail "fit-grey wrote a model on bad input"
# Writing again into its own folder works; bad input writes nothing.
"$W" machine export --out-dir "$D/x" --past-days 1 --test-days 1 --seed 3 > /dev/null \
  || fail "export again into its own folder"
[ ! -e "$D/x/truth_cuts.csv.tmp" ] || fail "temporary left behind"
expect_fail "--scenario" "$W" machine export --out-dir "$D/none" --scenario productoin
expect_fail "--test-shift-of" "$W" machine export --out-dir "$D/none" --test-shift-of a,b
expect_fail "--blank-contact-std-k" "$W" machine export --out-dir "$D/none" --blank-contact-std-k 5
expect_fail "--machine-index" "$W" machine export --out-dir "$D/none" --machine-index 20
[ ! -e "$D/none" ] || fail "files written on bad input"

"$W" machine ceiling --help > "$D/ceiling_help.txt" || fail "machine ceiling --help"
grep -q "\[um\]" "$D/ceiling_help.txt" || fail "ceiling --help names no unit"
"$W" machine ceiling --machines 1 --past-days 2 --test-days 1 --estimator-past-days 1 \
  --row-step-min 5 > "$D/ceiling.txt" || fail "machine ceiling"
grep -q "| production |" "$D/ceiling.txt" || fail "ceiling: no production row"
for c in none time+duty joint absolute +blank +contact grey "best sensor-free"; do
  grep -q -- "$c" "$D/ceiling.txt" || fail "ceiling: no column $c"
done
expect_fail "--estimator-past-days" "$W" machine ceiling --past-days 2 --estimator-past-days 3
echo "ok"
