#!/usr/bin/env bash
# Smoke test of 'whirl machine' (the field world): the day logs round-trip through 'whirl drift
# fit / predict', the evaluation runs with the field rows only, bad input and the retired legacy
# flags are refused with exit 1 and nothing written, the report holds the combined 840D programs
# of the models a shop can train, and the products' combined mode writes such programs by hand.
set -u
W="$1"; D="$2"; S="$3"
rm -rf "$D"; mkdir -p "$D"
source "$S/tests/support/cli_common.sh"

"$W" machine --help > "$D/help.txt" || fail "machine --help"
"$W" machine evaluate --help > "$D/evaluate_help.txt" || fail "machine evaluate --help"
grep -q "\[um\]" "$D/evaluate_help.txt" || fail "evaluate --help names no unit"
"$W" machine sensors --help > "$D/sensors_help.txt" || fail "machine sensors --help"
grep -A1 -- "--probe-z-mm" "$D/sensors_help.txt" | grep -q "\[mm" || fail "--probe-z-mm without [mm]"
"$W" machine sensors --out-dir "$D/runs" --idle 1 --cutting 2 > "$D/sensors.txt" || fail "sensors"
[ -f "$D/runs/idle_1.csv" ] && [ -f "$D/runs/cutting_2.csv" ] || fail "run files missing"
[ ! -e "$D/runs/cutting_3.csv" ] || fail "more production days than asked for"
n=$(grep -v '^#' "$D/runs/cutting_1.csv" | head -n 1 | tr ',' '\n' | grep -c '_C$')
[ "$n" -ge 10 ] && [ "$n" -le 16 ] || fail "expected 10-16 sensors, got $n"
grep -v '^#' "$D/runs/cutting_1.csv" | head -n 1 | grep -q "offset_um" || fail "no offset_um channel"
grep -q "^#.*displacement sensor on the check ring" "$D/runs/cutting_1.csv" \
  || fail "the files do not say what offset_um is"
"$W" drift fit --cutting "$D/runs/cutting_1.csv" --error offset_um --candidates sensors --out "$D/offset.json" \
  > /dev/null 2>&1 || fail "drift fit on a day log"
"$W" drift predict --model "$D/offset.json" --run "$D/runs/cutting_2.csv" --json > "$D/pred.json" \
  2>/dev/null || fail "drift predict on a day log"
grep -q '"residual"' "$D/pred.json" || fail "prediction has no residual"
"$W" machine sensors --out-dir "$D/runs_json" --idle 0 --cutting 1 --json > "$D/sensors.json" \
  || fail "sensors --json"
python3 - "$D/sensors.json" <<'PY' || fail "sensors --json: files or states wrong"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["schema"] == "whirl.machine_sensors", j
assert [f["state"] for f in j["files"]] == ["cutting"], j["files"]
PY

# Bad input: an unknown scenario, the retired legacy world's flags; nothing written.
expect_fail "--scenario\|productoin" "$W" machine sensors --scenario productoin --out-dir "$D/none"
expect_fail "--machine: applied to the legacy machine world, which was retired" \
  "$W" machine sensors --machine "$S/datasets/machines/example_840d.json" --out-dir "$D/none"
expect_fail "--machine-off: applied to the legacy machine world" \
  "$W" machine sensors --machine-off --out-dir "$D/none"
[ ! -e "$D/none" ] || fail "files written on bad input"
for flag in "--screws 2" "--train-runs 2" "--machine-off" "--drift-model mlr" "--monitor-every-min 30"; do
  # shellcheck disable=SC2086
  expect_fail "${flag%% *}: applied to the legacy machine world" "$W" machine evaluate $flag
done

# Combined 840D programs with the product's combined mode: the plan writes its K0 into
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

# The report: the combined programs of its screw, of the models a shop can train (the drift
# action reads the sensor model), each machine datum once in the box.
"$W" machine evaluate --machines 1 --test-days 1 --past-days 2 --out-dir "$D/report" \
  > /dev/null 2> "$D/report_err.txt" || fail "evaluate --out-dir: $(cat "$D/report_err.txt")"
for f in WHIRL_TEMP_COMP.SPF WHIRL_DRIFT_COMP.SPF WHIRL_DRIFT_COMP_RESET.SPF index.html; do
  [ -f "$D/report/$f" ] || fail "report lacks $f"
done
grep -q "^; \(model\|mixed line of 2 components\): .*trained only from shop measurements" \
  "$D/report/WHIRL_DRIFT_COMP.SPF" \
  || fail "the report's drift program is not the shop-trained model's"
[ "$(grep -c "<li>MD28254" "$D/report/index.html")" = 1 ] || fail "MD28254 not listed once"
[ "$(grep -c "<li>MD32750" "$D/report/index.html")" = 1 ] || fail "MD32750 not listed once"
# The page quotes the drift action's output action: one IDS line, nothing after it (a label).
grep -A1 "output:</p>$" "$D/report/index.html" | grep -q "^<pre>IDS=[0-9]* [^<]*</pre>$" \
  || fail "report: the drift action's output action is not one IDS line"
# On a record of 20 production days (>= 20 lead days: both_grey takes every sensor) the report's
# programs are the grey box's, every sensor on both channels, written with no warning: the default
# profile's drift IDs hold its drift action (issue 41; the largest such action is checked in
# tests/machine_report/test_machine_report.cpp).
"$W" machine evaluate --scenarios production --machines 1 --test-days 1 --past-days 20 --seed 7 \
  --out-dir "$D/report_long" > /dev/null 2> "$D/report_long_err.txt" ||
  fail "evaluate --out-dir on 20 days: $(cat "$D/report_long_err.txt")"
grep -q "warning" "$D/report_long_err.txt" && fail "20 days: $(cat "$D/report_long_err.txt")"
grep -q "^; model: .* from 13 sensors, file grey box (both_grey)" \
  "$D/report_long/WHIRL_DRIFT_COMP.SPF" || fail "20 days: the drift program is not both_grey's"
grep -q "^; slope model: .* from 13 sensors$" "$D/report_long/WHIRL_DRIFT_COMP.SPF" ||
  fail "20 days: the drift program's slope is not every sensor's"
# Since the fourteenth round's adoption both_grey's programs on a short record are the
# grey_short_mix line's: on 5 past days of duty changes (seed 3: the fitted weight below 1) the
# report's drift action is the mixed line of the grey box and the sensor-free rule. With
# --grey-without-short-mix --grey-candidates the programs are the grey box's and the mix's drift
# action is written beside them (WHIRL_DRIFT_MIX), its PLC rows tagged by component and weight,
# with no warning (the largest such action against the default profile:
# tests/machine_report/test_machine_report.cpp).
"$W" machine evaluate --scenarios duty-changes --machines 1 --test-days 1 --past-days 5 --seed 3 \
  --out-dir "$D/report_mix_default" > /dev/null 2> "$D/report_mix_default_err.txt" ||
  fail "evaluate --out-dir (mix default): $(cat "$D/report_mix_default_err.txt")"
grep -q "^; mixed line of 2 components: .*file grey box (both_grey) mixed with" \
  "$D/report_mix_default/WHIRL_DRIFT_COMP.SPF" || fail "default: both_grey's program is not the mix"
[ -f "$D/report_mix_default/WHIRL_DRIFT_MIX.SPF" ] && fail "default: a second mix program"
"$W" machine evaluate --scenarios duty-changes --machines 1 --test-days 1 --past-days 5 --seed 3 \
  --grey-without-short-mix --grey-candidates --out-dir "$D/report_mix" > /dev/null \
  2> "$D/report_mix_err.txt" ||
  fail "evaluate --grey-candidates --out-dir: $(cat "$D/report_mix_err.txt")"
grep -q "warning" "$D/report_mix_err.txt" && fail "mix: $(cat "$D/report_mix_err.txt")"
for f in WHIRL_DRIFT_MIX.SPF WHIRL_DRIFT_MIX_RESET.SPF WHIRL_DRIFT_MIX_PLC.csv; do
  [ -f "$D/report_mix/$f" ] || fail "report lacks $f"
done
grep -q "^; mixed line of 2 components" "$D/report_mix/WHIRL_DRIFT_MIX.SPF" ||
  fail "mix: the drift program is not a mixed line"
grep -q "^; component 2, w = 0\.[0-9]*: model dynamic of k0_um from 0 sensors" \
  "$D/report_mix/WHIRL_DRIFT_MIX.SPF" || fail "mix: the rule's component is missing"
grep -q "^component,weight,output,feature," "$D/report_mix/WHIRL_DRIFT_MIX_PLC.csv" &&
  grep -q "^2,0\.[0-9]*,k0_mm,intercept," "$D/report_mix/WHIRL_DRIFT_MIX_PLC.csv" ||
  fail "mix: the PLC rows are not tagged by component and weight"
cmp -s "$D/report_mix/WHIRL_DRIFT_COMP_RESET.SPF" "$D/report_mix/WHIRL_DRIFT_MIX_RESET.SPF" &&
  fail "mix: the reset program does not carry its own name"
grep -q "grey_short_mix on the control" "$D/report_mix/index.html" || fail "mix: page lacks it"
# The screw's control log is a drift run file: a machine model evaluates on it.
"$W" drift predict --model "$D/offset.json" --run "$D/report/sensors.csv" --json > "$D/pred2.json" \
  2>/dev/null || fail "drift predict on the screw's log"
# Scenarios: the flags carry units in --help; a bad scenario name exits 1 naming the flag and
# the names; a small run gives the field rows only.
grep -A1 -- "--check-every-min" "$D/evaluate_help.txt" | grep -q "\[min\]" || fail "--check-every-min without [min]"
grep -A1 -- "--probe-noise-um" "$D/evaluate_help.txt" | grep -q "\[um\]" || fail "--probe-noise-um without [um]"
expect_fail "--scenarios" "$W" machine evaluate --scenarios productoin
expect_fail "production" "$W" machine evaluate --scenarios productoin
expect_fail "legacy" "$W" machine evaluate --scenarios legacy
expect_fail "--check-every-min" "$W" machine evaluate --scenarios production --check-every-min 0
"$W" machine evaluate --scenarios production --machines 1 --past-days 1 --test-days 1 --json \
  > "$D/field.json" 2> "$D/field_err.txt" || fail "field evaluate: $(cat "$D/field_err.txt")"
python3 - "$D/field.json" <<'PY' || fail "field evaluate: rows or screws wrong"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["schema"] == "whirl.machine_scenarios", j["schema"]
s = j["scenarios"][0]
assert s["scenario"] == "production"
rows = list(s["strategies"])
want = ["none", "traditional", "workpiece", "class", "table", "nearest", "warmup", "schedule",
        "lead_slope", "machine_shop", "both_shop", "both_shop_monitor", "both_grey"]
assert sorted(rows) == sorted(want), rows
assert s["strategies"]["none"]["screws"] >= 1
PY
# --slope-through-lags-only (issue 41's opt-in candidate) reaches both_grey only: every other
# row of the same run comes out equal.
grep -q -- "--slope-through-lags-only" "$D/evaluate_help.txt" || fail "--help lacks --slope-through-lags-only"
"$W" machine evaluate --scenarios production --machines 1 --past-days 1 --test-days 1 --json \
  --slope-through-lags-only > "$D/field_lags.json" 2> "$D/field_err.txt" ||
  fail "field evaluate --slope-through-lags-only: $(cat "$D/field_err.txt")"
python3 - "$D/field.json" "$D/field_lags.json" <<'PY' || fail "--slope-through-lags-only moved another row"
import json, sys
a, b = (json.load(open(f))["scenarios"][0]["strategies"] for f in sys.argv[1:])
assert sorted(a) == sorted(b), (sorted(a), sorted(b))
for name in a:
    assert name == "both_grey" or a[name] == b[name], name
PY
# --grey-five-sensors (the grey box before the eleventh round) changes nothing on a record of
# fewer than 20 lead days (one past day): every row, both_grey's included, comes out equal
# (tests/machine_eval/test_shop.cpp plants the long record where it does change both_grey).
grep -q -- "--grey-five-sensors" "$D/evaluate_help.txt" || fail "--help lacks --grey-five-sensors"
"$W" machine evaluate --scenarios production --machines 1 --past-days 1 --test-days 1 --json \
  --grey-five-sensors > "$D/field_five.json" 2> "$D/field_err.txt" ||
  fail "field evaluate --grey-five-sensors: $(cat "$D/field_err.txt")"
python3 - "$D/field.json" "$D/field_five.json" <<'PY' || fail "--grey-five-sensors moved a row"
import json, sys
a, b = (json.load(open(f))["scenarios"][0]["strategies"] for f in sys.argv[1:])
assert a == b, sorted(k for k in a if a[k] != b.get(k))
PY
# --offset-candidates (issue 41's seventh round) adds the two opt-in rows, sensor rows, after
# the table's, in the same run: every other row comes out equal.
grep -q -- "--offset-candidates" "$D/evaluate_help.txt" || fail "--help lacks --offset-candidates"
"$W" machine evaluate --scenarios production --machines 1 --past-days 1 --test-days 1 --json \
  --offset-candidates > "$D/field_k0.json" 2> "$D/field_err.txt" ||
  fail "field evaluate --offset-candidates: $(cat "$D/field_err.txt")"
python3 - "$D/field.json" "$D/field_k0.json" <<'PY' || fail "--offset-candidates: rows wrong"
import json, sys
a, b = (json.load(open(f))["scenarios"][0]["strategies"] for f in sys.argv[1:])
assert sorted(b) == sorted(list(a) + ["grey_warmup_k0", "grey_mean_k0"]), sorted(b)
for name in a:
    assert a[name] == b[name], name
for name in ("grey_warmup_k0", "grey_mean_k0"):
    assert b[name]["uses_sensors"] and b[name]["screws"] == a["both_grey"]["screws"], name
PY
# --grey-candidates (the eighth to fourteenth rounds) adds its rows after the seventh round's,
# in the same run: every other row, the seventh round's included, comes out equal; grey_guarded
# is the row of the model it chose (grey_guarded_choice per machine) to the digit, and
# grey_sensors_by_days both_grey's (one past day: fewer than 20 lead days).
grep -q -- "--grey-candidates" "$D/evaluate_help.txt" || fail "--help lacks --grey-candidates"
"$W" machine evaluate --scenarios production --machines 1 --past-days 1 --test-days 1 --json \
  --grey-candidates > "$D/field_gc.json" 2> "$D/field_err.txt" ||
  fail "field evaluate --grey-candidates: $(cat "$D/field_err.txt")"
python3 - "$D/field_k0.json" "$D/field_gc.json" <<'PY' || fail "--grey-candidates: rows wrong"
import json, sys
a = json.load(open(sys.argv[1]))["scenarios"][0]["strategies"]
gc = json.load(open(sys.argv[2]))["scenarios"][0]
b = gc["strategies"]
assert sorted(b) == sorted(list(a) + ["grey_all_sensors", "grey_sensors_by_days",
                                      "grey_short_prior", "grey_short_offset_as_read",
                                      "grey_short_offset_one_lag", "grey_guarded",
                                      "grey_short_mix", "grey_short_mix_fixed"]), sorted(b)
for name in a:
    assert a[name] == b[name], name
for name in ("grey_all_sensors", "grey_sensors_by_days", "grey_short_prior",
             "grey_short_offset_as_read", "grey_short_offset_one_lag", "grey_guarded",
             "grey_short_mix", "grey_short_mix_fixed"):
    assert b[name]["uses_sensors"] and b[name]["screws"] == a["both_grey"]["screws"], name
# grey_fit: what both_grey's fit chose on the machine (one past day: one lead day), from its grids.
fit = gc["runs"][0]["grey_fit"]
assert len(fit) == 1 and fit[0]["lead_days"] == 1, fit
assert fit[0]["prior_strength"] in (1e-3, 1e-2, 1e-1, 1.0), fit
assert fit[0]["blank_tau_min"] in (30, 60, 120, 240), fit
assert all(t in (10, 20, 40, 80, 160, 320) for t in fit[0]["time_constants_min"]), fit
chosen = gc["runs"][0]["grey_guarded_choice"]
assert len(chosen) == 1 and chosen[0] in ("both_grey", "warmup", "schedule"), chosen
# The grey box's line alone is grey_sensors_by_days' (one past day: fewer than 20 lead days);
# since the fourteenth round's adoption both_grey is grey_short_mix's line, to the digit.
keep = {"both_grey": "grey_sensors_by_days"}
for key in ("accumulated_total_median_um", "accumulated_1000_median_um", "share_reaching_p5"):
    assert b["grey_guarded"][key] == b[keep.get(chosen[0], chosen[0])][key], (key, chosen)
    assert b["grey_short_mix"][key] == a["both_grey"][key], key
# grey_short_mix (the fourteenth round): the grey box's weight per machine, within [0.5, 1].
mix = gc["runs"][0]["grey_short_mix_weight"]
assert len(mix) == 1 and 0.5 <= mix[0] <= 1, mix
PY
# --grey-without-short-mix (the opt-out): both_grey is the grey box's line alone again
# (grey_sensors_by_days' row, the default before the adoption), every other row as with the
# default, the mix's weight the same.
"$W" machine evaluate --scenarios production --machines 1 --past-days 1 --test-days 1 --json \
  --grey-candidates --grey-without-short-mix > "$D/field_gc_out.json" 2> "$D/field_err.txt" ||
  fail "field evaluate --grey-without-short-mix: $(cat "$D/field_err.txt")"
python3 - "$D/field_gc.json" "$D/field_gc_out.json" <<'PY' || fail "--grey-without-short-mix wrong"
import json, sys
gc = json.load(open(sys.argv[1]))["scenarios"][0]
out = json.load(open(sys.argv[2]))["scenarios"][0]
a, b = gc["strategies"], out["strategies"]
assert sorted(a) == sorted(b)
for name in a:
    if name != "both_grey":
        assert a[name] == b[name], name
for key in ("accumulated_total_median_um", "accumulated_1000_median_um", "share_reaching_p5"):
    assert b["both_grey"][key] == b["grey_sensors_by_days"][key], key
assert gc["runs"][0]["grey_short_mix_weight"] == out["runs"][0]["grey_short_mix_weight"]
if gc["runs"][0]["grey_short_mix_weight"][0] < 1:
    assert a["both_grey"] != b["both_grey"], "the mix must move both_grey below w = 1"
PY
echo "cli_machine: ok"
