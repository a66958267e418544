#!/usr/bin/env bash
# Smoke test of 'whirl machine': sensor files round-trip through 'whirl drift fit /
# predict', the evaluation runs and its machine-off figures equal the workpiece-only truth,
# bad input is refused with exit 1 and nothing written, the combined 840D programs are written by
# the existing combined mode.
set -u
W="$1"; D="$2"; S="$3"
rm -rf "$D"; mkdir -p "$D"
source "$S/tests/support/cli_common.sh"

"$W" machine --help > "$D/help.txt" || fail "machine --help"
"$W" machine evaluate --help > "$D/evaluate_help.txt" || fail "machine evaluate --help"
grep -q "\[um\]" "$D/evaluate_help.txt" || fail "evaluate --help names no unit"
"$W" machine sensors --out-dir "$D/runs" --idle 1 --cutting 2 > "$D/sensors.txt" || fail "sensors"
[ -f "$D/runs/idle_1.csv" ] && [ -f "$D/runs/cutting_2.csv" ] || fail "run files missing"
n=$(grep -v '^#' "$D/runs/cutting_1.csv" | head -n 1 | tr ',' '\n' | grep -c '_C$')
[ "$n" -ge 10 ] && [ "$n" -le 16 ] || fail "expected 10-16 sensors, got $n"
"$W" drift fit --cutting "$D/runs/cutting_1.csv" --error offset_um --candidates sensors --out "$D/offset.json" \
  > /dev/null 2>&1 || fail "drift fit on a sensor file"
"$W" drift predict --model "$D/offset.json" --run "$D/runs/cutting_2.csv" --json > "$D/pred.json" \
  2>/dev/null || fail "drift predict on a sensor file"
grep -q '"residual"' "$D/pred.json" || fail "prediction has no residual"

# Evaluation: JSON output, and with the machine off the machine strategy equals none.
"$W" machine evaluate --machines 1 --screws 2 --json > "$D/eval.json" 2>/dev/null || fail "evaluate"
"$W" machine evaluate --machines 1 --screws 2 --machine-off --json > "$D/off.json" 2>/dev/null \
  || fail "evaluate --machine-off"
python3 - "$D/off.json" "$D/eval.json" <<'PY' || fail "machine off: machine != none or both != workpiece"
import json, sys
s = json.load(open(sys.argv[1]))["summary"]["strategies"]
assert s["machine"] == s["none"], (s["machine"], s["none"])
assert s["both"] == s["workpiece"], (s["both"], s["workpiece"])
on = json.load(open(sys.argv[2]))["summary"]["strategies"]
assert on["none"] != s["none"]
PY

# Bad input: a typo in the machine file, a missing named file; nothing written.
sed 's/"motor_tau_min"/"motor_tau_mn"/' "$S/datasets/machines/whirling_thermal.json" > "$D/bad.json"
expect_fail "motor_tau_mn" "$W" machine sensors --machine-thermal "$D/bad.json" --out-dir "$D/none"
[ ! -e "$D/none" ] || fail "files written on bad input"
expect_fail "missing.json" "$W" machine sensors --machine-thermal "$D/missing.json" --out-dir "$D/none"

# Combined 840D programs with the existing combined mode: the plan writes its K0 into
# $AC_PARAM, the machine drift action (the offset model) is the single writer of SD43900.
P="$S/datasets/machines/example_840d.json"
sensors=$(python3 -c "import json,sys; print(' '.join(json.load(open(sys.argv[1]))['sensors']))" \
  "$D/offset.json") || fail "no sensors in offset.json"
[ -n "$sensors" ] || fail "offset.json names no sensor"
inputs=()
k=1
for s in $sensors; do
  inputs+=(--input "$s=$k:0.1:0"); k=$((k + 1))
done
"$W" plan --screw "$S/datasets/screws/reference_80x10x6000.json" --machine "$P" \
  --model "$S/models/default.json" --with-drift-action --nc "$D/PLAN.SPF" > "$D/plan.txt" 2>&1 || fail "plan --with-drift-action: $(cat "$D/plan.txt")"
"$W" drift nc --model "$D/offset.json" --machine "$P" "${inputs[@]}" --nc "$D/DRIFT.SPF" \
  > "$D/nc.txt" 2>&1 || fail "drift nc with the machine model: $(cat "$D/nc.txt")"
grep -q 'AC_PARAM' "$D/PLAN.SPF" || fail "plan does not hand its K0 over"
grep -q 'SA_TEMP_COMP_ABS_VALUE' "$D/DRIFT.SPF" || fail "drift action does not write SD43900"

# The machine's Z-screw slope on the control: with the simulated machine's profile the plan hands
# K0, slope and reference over and the drift action (offset + slope model) owns SD43900-43920.
W840="$S/datasets/machines/whirling_840d.json"
"$W" drift fit --cutting "$D/runs/cutting_1.csv" --error zscrew_per_1000_um --candidates sensors \
  --out "$D/zscrew.json" > /dev/null 2>&1 || fail "drift fit of the slope channel"
"$W" plan --screw "$S/datasets/screws/reference_80x10x6000.json" --machine "$W840" \
  --start-position-mm 5600 --model "$S/models/default.json" --with-drift-action \
  --nc "$D/PLAN2.SPF" > "$D/plan2.txt" 2>&1 || fail "plan with the slope handed over: $(cat "$D/plan2.txt")"
"$W" drift nc --model "$D/offset.json" --slope-model "$D/zscrew.json" --machine "$W840" \
  --reference start --nc "$D/DRIFT2.SPF" --reset-nc "$D/DRIFT2_RESET.SPF" --csv "$D/DRIFT2.csv" \
  > "$D/nc2.txt" 2>&1 || fail "drift nc --slope-model: $(cat "$D/nc2.txt")"
! grep -q 'SA_TEMP_COMP' "$D/PLAN2.SPF" || fail "the handed-over plan writes a setting datum itself"
grep -q 'SA_TEMP_COMP_SLOPE\[Z\]=\$AC_PARAM' "$D/DRIFT2.SPF" || fail "drift action does not own SD43910"
grep -q '^slope,' "$D/DRIFT2.csv" || fail "PLC table has no slope rows"
# A profile without drift.slope cannot take a slope model; nothing is written.
expect_fail "drift.slope" "$W" drift nc --model "$D/offset.json" --slope-model "$D/zscrew.json" \
  --machine "$P" "${inputs[@]}" --nc "$D/none.SPF"
[ ! -e "$D/none.SPF" ] || fail "program written on bad input"
# The report holds the combined programs of its screw.
"$W" machine evaluate --machines 1 --screws 1 --out-dir "$D/report" > /dev/null 2>&1 || fail "evaluate --out-dir"
for f in WHIRL_TEMP_COMP.SPF WHIRL_DRIFT_COMP.SPF WHIRL_DRIFT_COMP_RESET.SPF index.html; do
  [ -f "$D/report/$f" ] || fail "report lacks $f"
done
# The page quotes the drift action's output action: one IDS line, nothing after it (a label).
grep -q "output:</p><pre>IDS=[0-9]* [^<]*</pre>" "$D/report/index.html" \
  || fail "report: the drift action's output action is not one IDS line"
# The screw's own sensor log is a drift run file: a machine model evaluates on it.
"$W" drift predict --model "$D/offset.json" --run "$D/report/sensors.csv" --json > "$D/pred2.json" \
  2>/dev/null || fail "drift predict on the screw's log"
grep -q '"residual"' "$D/pred2.json" || fail "the screw's log has no offset_um channel"
# Scenarios: the field flags carry units in --help; a bad scenario name and a flag of the other
# world exit 1 naming the flag and the rule; a small field run gives the field rows only.
grep -A1 -- "--check-every-min" "$D/evaluate_help.txt" | grep -q "\[min\]" || fail "--check-every-min without [min]"
grep -A1 -- "--probe-noise-um" "$D/evaluate_help.txt" | grep -q "\[um\]" || fail "--probe-noise-um without [um]"
expect_fail "--scenarios" "$W" machine evaluate --scenarios productoin
expect_fail "production" "$W" machine evaluate --scenarios productoin
expect_fail "--screws: applies to the legacy world only" "$W" machine evaluate --scenarios production --screws 2
expect_fail "--train-runs: applies to the legacy world only" "$W" machine evaluate --scenarios duty-changes --train-runs 2
expect_fail "--test-days: applies to the field scenarios only" "$W" machine evaluate --scenarios legacy --test-days 2
expect_fail "--check-every-min" "$W" machine evaluate --scenarios production --check-every-min 0
"$W" machine evaluate --scenarios production --machines 1 --past-days 1 --test-days 1 --json \
  > "$D/field.json" 2> "$D/field_err.txt" || fail "field evaluate: $(cat "$D/field_err.txt")"
python3 - "$D/field.json" <<'PY' || fail "field evaluate: rows or screws wrong"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["schema"] == "whirl.machine_scenarios", j["schema"]
s = j["scenarios"][0]
assert s["scenario"] == "production"
rows = set(s["strategies"])
assert {"none", "traditional", "warmup", "schedule", "both_shop"} <= rows, rows
assert not ({"machine", "both", "both_idle", "both_monitor"} & rows), rows
assert s["strategies"]["none"]["screws"] >= 1
PY
echo "cli_machine: ok"
