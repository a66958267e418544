#!/usr/bin/env bash
# Smoke test of 'whirl drift nc' and 'whirl plan --with-drift-action': args <whirl> <scratch> <src>.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"
source "$SRC/tests/support/cli_common.sh"
M="$SRC/datasets/machines/example_840d.json"
S="$SRC/datasets/screws/reference_80x10x6000.json"

"$W" drift nc --help > "$D/help.txt" || fail "drift nc --help exits non-zero"
grep -q 'A_INA' "$D/help.txt" || fail "drift nc --help does not explain \$A_INA"
# A small run: two sensors warming, an error driven by both (2 um/K and -1 um/K) plus a wiggle.
awk 'BEGIN { print "# synthetic run for the smoke test"; print "time_min,t1_C,t2_C,ch1_um";
  for (k = 0; k < 200; k++) { t1 = 20 + 8 * (1 - exp(-k / 50)); t2 = 21 + 0.02 * k;
    printf "%d,%.4f,%.4f,%.4f\n", k, t1, t2, 2 * (t1 - 20) - (t2 - 21) + 0.05 * sin(k) } }' \
  > "$D/run.csv"
"$W" drift fit --run "$D/run.csv" --error ch1_um --sensors t1_C t2_C --out "$D/model.json" \
  > /dev/null || fail "drift fit"
"$W" drift nc --model "$D/model.json" --machine "$M" --nc "$D/drift.spf" \
  --reset-nc "$D/drift_reset.spf" --csv "$D/drift.csv" > "$D/out.txt" 2> "$D/nc.err" || fail "drift nc"
grep -q "^warning: machine profile .*example_840d.json is the shipped example" "$D/nc.err" ||
  fail "drift nc with the untouched example profile does not warn: $(cat "$D/nc.err")"
for f in drift.spf drift_reset.spf drift.csv; do [ -s "$D/$f" ] || fail "$f not written"; done
grep -q '^IDS=200 ' "$D/drift.spf" || fail "IDS range from the profile"
grep -q 'A_INA\[1\]' "$D/drift.spf" || fail "analog input of t1_C"
grep -q 'SA_TEMP_COMP_ABS_VALUE\[Z\]=.*\$AC_PARAM\[99\]' "$D/drift.spf" \
  || fail "the drift action must add the plan's K0 (workpiece_k0_param 99)"
grep -q '^M17' "$D/drift_reset.spf" || fail "reset program"
grep -Eq '[0-9]e-?[0-9]' "$D/drift.spf" "$D/drift.csv" && fail "exponent in a control file"
# Bad input: an unmapped sensor, a malformed --input; nothing written.
rm -f "$D/none.spf"
sed 's/"t2_C"/"t2_X"/' "$M" > "$D/machine_no_t2.json"
expect_fail "t2_C" "$W" drift nc --model "$D/model.json" --machine "$D/machine_no_t2.json" \
  --nc "$D/none.spf"
[ -e "$D/none.spf" ] && fail "a failed drift nc wrote a file"
expect_fail "INDEX:SCALE:OFFSET" "$W" drift nc --model "$D/model.json" --machine "$M" \
  --input "t1_C=3;rm" --nc "$D/none.spf"
# --input: physical bounds, the control's analog inputs (the profile's MD10300 = 8), known names.
for bad in "t1_C=3:1e-12:0/scale" "t1_C=3:0.1:1e308/offset" "t1_C=3:0.1:-1e9/offset" \
           "t1_C=9:0.1:0/MD10300" "t1_C=0:0.1:0/index" "t8_C=3:0.1:0/no input 't8_C'"; do
  expect_fail "${bad#*/}" "$W" drift nc --model "$D/model.json" --machine "$M" \
    --input "${bad%%/*}" --nc "$D/none.spf"
  grep -q -- "--input '${bad%%/*}'" "$D/err.txt" || fail "message does not name the --input: $(cat "$D/err.txt")"
done
[ -e "$D/none.spf" ] && fail "a refused --input wrote a file"
# The headers name the programs by their files and the control's limits they need.
"$W" drift nc --model "$D/model.json" --machine "$M" --nc "$D/DRIFT_ON.SPF" \
  --reset-nc "$D/DRIFT_OFF.SPF" > /dev/null || fail "drift nc with own names"
head -1 "$D/DRIFT_ON.SPF" | grep -q '^; DRIFT_ON: ' || fail "header does not name DRIFT_ON"
grep -q 'stop it with DRIFT_OFF' "$D/DRIFT_ON.SPF" || fail "header does not name DRIFT_OFF"
head -1 "$D/DRIFT_OFF.SPF" | grep -q '^; DRIFT_OFF: ' || fail "reset header"
grep -q 'MD10300 \$MN_FASTIO_ANA_NUM_INPUTS >= 2 (profile: 8)' "$D/DRIFT_ON.SPF" \
  || fail "header: MD10300 prerequisite"
grep -q 'MD28254 \$MC_MM_NUM_AC_PARAM >= [0-9]* (profile: 300)' "$D/DRIFT_ON.SPF" \
  || fail "header: MD28254 prerequisite"
expect_fail "one program" "$W" drift nc --model "$D/model.json" --machine "$M" \
  --nc "$D/DRIFT_ON.SPF" --reset-nc "$D/drift_on.spf"
expect_fail "program name" "$W" drift nc --model "$D/model.json" --machine "$M" \
  --nc "$D/1 drift.spf"
# One validation for every command: a profile that one refuses, the other refuses too.
for edit in 's/"workpiece_k0_param": 99/"workpiece_k0_param": 101/;workpiece_k0_param' \
            's/"sync_id_last": 240/"sync_id_last": 201/;sync_id_last' \
            's/"missing_alarm": 65000/"missing_alarm": 60000/;missing_alarm' \
            's/"md10300_analog_inputs": 8/"md10300_analog_inputs": 4/;MD10300'; do
  sed "${edit%;*}" "$M" > "$D/edited.json"
  expect_fail "${edit##*;}" "$W" drift nc --model "$D/model.json" --machine "$D/edited.json"
  grep -q "edited.json" "$D/err.txt" || fail "message does not name the profile"
  expect_fail "${edit##*;}" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
    --machine "$D/edited.json"
done
# The plan combined with it: K0 into $AC_PARAM[99], an alarm if the drift action is not active.
"$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 --machine "$M" --with-drift-action \
  --nc "$D/plan.spf" > /dev/null || fail "plan --with-drift-action"
grep -q 'DO \$AC_PARAM\[99\]=' "$D/plan.spf" || fail "combined plan must write K0 into AC_PARAM[99]"
grep -v '^;' "$D/plan.spf" | grep -q 'SA_TEMP_COMP_ABS_VALUE' && fail "combined plan writes SD43900"
grep -q '^SETAL(65000)' "$D/plan.spf" || fail "combined plan lacks the alarm"
# After every alarm (the plan's, and the drift program's for a plan left active) the program
# jumps to the label just before M17: nothing is changed whether or not the alarm stops it.
grep -q '^SETAL(65003)' "$D/drift.spf" || fail "drift program lacks the alarm for an active plan"
expect_jumps_to_end "$D/plan.spf"
expect_jumps_to_end "$D/drift.spf"
# --with-drift-action needs the profile's drift object.
python3 -c 'import json,sys; j=json.load(open(sys.argv[1])); del j["drift"]; json.dump(j, open(sys.argv[2], "w"))' \
  "$M" "$D/machine_nodrift.json" || fail "could not write the profile without its drift object"
grep -q '"drift"' "$D/machine_nodrift.json" && fail "the edited profile still has a drift object"
expect_fail "needs a 'drift' object" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
  --machine "$D/machine_nodrift.json" --with-drift-action
# Every model kind `drift fit` can write goes onto the control (issue 45: a time model crashed
# drift nc): each candidate family, the default, the dynamic kind; NC program and PLC table.
awk 'BEGIN { print "time_min,t1_C,t2_C,ch1_um";
  for (k = 0; k < 300; k++) { t1 = 20 + 8 * (1 - exp(-k / 50)) + 0.5 * sin(k / 9); t2 = 21 + 0.02 * k;
    printf "%d,%.4f,%.4f,%.4f\n", k, t1, t2, 9 * (1 - exp(-k / 70)) + 0.3 * (t1 - 20) + 0.05 * sin(k) } }' \
  > "$D/warm.csv"
for cand in auto sensors time time1 time2 sensors+time; do
  for kind in mlr dynamic; do
    tag="${cand/+/_}_$kind"
    "$W" drift fit --run "$D/warm.csv" --error ch1_um --candidates "$cand" --model "$kind" \
      --out "$D/m_$tag.json" > "$D/fit_$tag.txt" 2>&1 || fail "drift fit --candidates $cand --model $kind"
    "$W" drift nc --model "$D/m_$tag.json" --machine "$M" --nc "$D/KK_$tag.spf" \
      --csv "$D/k_$tag.csv" > "$D/nc_$tag.txt" 2>&1 \
      || fail "drift nc on --candidates $cand --model $kind: $(cat "$D/nc_$tag.txt")"
    [ -s "$D/KK_$tag.spf" ] && [ -s "$D/k_$tag.csv" ] || fail "drift nc wrote nothing for $tag"
    grep -Eq '[0-9]e-?[0-9]' "$D/KK_$tag.spf" "$D/k_$tag.csv" && fail "exponent in a control file ($tag)"
    if tr -d ' \n' < "$D/m_$tag.json" | grep -q '"elapsed_time_constants":\[[0-9]'; then
      grep -q '^k0_mm,elapsed_lag.*,elapsed,,,,,' "$D/k_$tag.csv" || fail "PLC row of elapsed time ($tag)"
      grep -q '\*(1-\$AC_PARAM\[' "$D/KK_$tag.spf" || fail "elapsed-time recursion in the NC ($tag)"
      grep -q "elapsed time is counted here" "$D/KK_$tag.spf" || fail "NC header on elapsed time ($tag)"
    fi
  done
done
tr -d ' \n' < "$D/m_time1_mlr.json" | grep -q '"elapsed_time_constants":\[[0-9]' \
  || fail "time1 without a time constant"
grep -q 'elapsed time is counted here' "$D/KK_time2_mlr.spf" || fail "time2 not put on the control"
# Elapsed time reads no analog input: --input elapsed=... is refused with the reason.
expect_fail "counted by the control" "$W" drift nc --model "$D/m_time1_mlr.json" --machine "$M" \
  --input elapsed=1:1:0 --nc "$D/none.spf"
# The simulated machine's runs at the default kind dynamic, with its own profile, --csv only.
"$W" machine sensors --out-dir "$D/sim" --idle 1 --cutting 1 > /dev/null 2>&1 || fail "machine sensors"
"$W" drift fit --cutting "$D/sim/cutting_1.csv" --error offset_um --model dynamic \
  --out "$D/sim_model.json" > /dev/null 2>&1 || fail "drift fit on the simulated machine"
"$W" drift nc --model "$D/sim_model.json" --machine "$SRC/datasets/machines/whirling_840d.json" \
  --csv "$D/sim.csv" > /dev/null 2>&1 || fail "drift nc --csv on the simulated machine's model"
[ -s "$D/sim.csv" ] || fail "the simulated machine's PLC table"
echo "ok"
