#!/usr/bin/env bash
# Smoke test of 'whirl plan': args <whirl> <scratch dir> <source dir>.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"
source "$SRC/tests/support/cli_common.sh"
S="$SRC/datasets/screws/reference_80x10x6000.json"
M="$SRC/datasets/machines/example_840d.json"
POS=(--start-position-mm 0 --machine-offset-mm -850)

"$W" plan --help > "$D/help.txt" || fail "plan --help exits non-zero"
grep -q "SD43910" "$D/help.txt" || fail "plan --help does not explain SD43910"
grep -q -- "--save-r-first" "$D/help.txt" || fail "plan --help lacks --save-r-first"

# From given features: all three outputs, consistent with each other.
"$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 --machine "$M" --out "$D/plan.json" \
  --csv "$D/plan.csv" --nc "$D/plan.spf" --reset-nc "$D/reset.spf" > "$D/plan.txt" 2> "$D/plan.err" || fail "plan"
# The untouched example profile is named as illustrative (issue 44 item 5); a profile the user
# made their own (renamed) is not.
grep -q "^warning: machine profile .*example_840d.json is the shipped example" "$D/plan.err" ||
  fail "plan with the untouched example profile does not warn: $(cat "$D/plan.err")"
sed 's/"name": "[^"]*"/"name": "WM-7 hall 2"/' "$M" > "$D/own_profile.json"
"$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 --machine "$D/own_profile.json" \
  --out "$D/own_plan.json" > /dev/null 2> "$D/own.err" || fail "plan with an own profile"
grep -q "warning" "$D/own.err" && fail "plan warns about an own profile: $(cat "$D/own.err")"
for f in plan.json plan.csv plan.spf reset.spf; do [ -s "$D/$f" ] || fail "$f not written"; done
grep -q '"schema": "whirl.plan"' "$D/plan.json" || fail "plan JSON schema"
grep -q '"uniform_point_count"' "$D/plan.json" || fail "plan JSON uniform count"
grep -q "MD32750 \$MA_TEMP_COMP_TYPE = 3" "$D/plan.spf" || fail "NC header"
segments=$(grep -v '^#' "$D/plan.csv" | tail -n +2 | grep -vc '^restore')
actions=$(grep -c '^ID=' "$D/plan.spf")
# One action per segment (the first at the thread start) plus the restore at the thread end, IDs
# from the profile's range.
[ "$actions" -eq $((segments + 1)) ] || fail "$segments segments but $actions synchronized actions"
grep -q "^ID=100 " "$D/plan.spf" || fail "IDs do not start at the profile's sync_id_first"
[ "$(grep -c '^CANCEL(' "$D/plan.spf")" -eq 50 ] || fail "the ID range 100..149 is not cancelled"
grep -q '^CANCEL(149)' "$D/reset.spf" || fail "reset program does not cancel the range"
grep -q "R90=\$SA_TEMP_COMP_ABS_VALUE" "$D/plan.spf" || fail "found values not saved"
grep -q "^M17" "$D/plan.spf" || fail "no M17"
grep -Eq '[0-9]e-?[0-9]' "$D/plan.csv" "$D/plan.spf" && fail "exponent in a control file"
grep -q '^restore,.*,saved,saved,saved$' "$D/plan.csv" || fail "PLC table lacks the restore row"
grep -q ">=" "$D/plan.spf" || fail "direction +1 must compare with >="
# The sign follows the direction: -1 gives 'add' by itself; an inconsistent --sign is refused.
"$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 --machine "$M" --direction -1 \
  --nc "$D/minus.spf" > /dev/null || fail "plan direction -1"
grep -q "<=" "$D/minus.spf" || fail "direction -1 must compare with <="
grep -q "sign: add" "$D/minus.spf" || fail "direction -1 must give sign add"
expect_fail "--sign subtract contradicts direction -1" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
  --machine "$M" --direction -1 --sign subtract
"$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 --machine "$M" --direction -1 \
  --control-dk subtracted --sign subtract > /dev/null || fail "consistent explicit sign refused"
# No machine positions, no plan.
expect_fail "start-position-mm" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250
expect_fail "machine-offset-mm" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
  --start-position-mm 0
"$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 "${POS[@]}" > /dev/null \
  || fail "plan with explicit positions"

# Synchronized-action IDs come from the profile or explicit flags, never a default 1..255 (the
# program cancels its whole range, the machine builder's actions too); a flag that contradicts
# the profile is refused, naming both.
expect_fail "no synchronized-action IDs" "$W" plan --screw "$S" --max-elongation-um 30 \
  --settle-time-s 250 "${POS[@]}" --nc "$D/noids.spf"
[ -e "$D/noids.spf" ] && fail "program written without an ID range"
expect_fail "go together" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
  "${POS[@]}" --sync-id-first 120 --nc "$D/noids.spf"
"$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 "${POS[@]}" --sync-id-first 120 \
  --sync-id-last 160 --save-r-first 40 --nc "$D/ids.spf" > /dev/null || fail "plan with explicit IDs"
[ "$(grep -c '^CANCEL(' "$D/ids.spf")" -eq 41 ] || fail "explicit range 120..160 not cancelled"
grep -Eq '^(CANCEL\(|ID=)([0-9]|[1-9][0-9]|1[01][0-9]|16[1-9]|1[7-9][0-9]|2[0-9][0-9])[^0-9]' \
  "$D/ids.spf" && fail "an ID outside 120..160 is touched"
# R parameters likewise (the program saves what it finds in the user's R parameters): from the
# profile or --save-r-first, never a default R90..R93; a contradicting flag is refused below.
expect_fail "no R parameters" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
  "${POS[@]}" --sync-id-first 120 --sync-id-last 160 --nc "$D/nor.spf"
grep -q -- "--save-r-first" "$D/err.txt" || fail "the message does not name --save-r-first"
expect_fail "no R parameters" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
  "${POS[@]}" --sync-id-first 120 --sync-id-last 160 --reset-nc "$D/nor.spf"
[ -e "$D/nor.spf" ] && fail "program written without R parameters"
used_r=$(grep -v '^;' "$D/ids.spf" | grep -Eo '(^|[^A-Z_$])\$?R[0-9]+' | grep -Eo '[0-9]+$' | sort -un | tr '\n' ' ')
[ "$used_r" = "40 41 42 43 " ] || fail "--save-r-first 40 must use R40..R43 only, uses: $used_r"
expect_fail "sync_id_first 100" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
  --machine "$M" --sync-id-first 1 --nc "$D/override.spf"
grep -q -- "--sync-id-first 1 contradicts the machine profile" "$D/err.txt" \
  || fail "the message does not name the flag: $(cat "$D/err.txt")"
expect_fail "sync_id_last 149" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
  --machine "$M" --sync-id-last 255
expect_fail "save_r_first 90" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
  --machine "$M" --save-r-first 10
expect_fail "start_alarm 65004" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
  --machine "$M" --start-alarm 65100
"$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 --machine "$M" --sync-id-first 100 \
  --sync-id-last 149 > /dev/null || fail "flags equal to the profile's refused"

# The start: the program refuses (alarm from the profile) unless the axis stands before the
# thread start, and says so in its header; the control's limits it needs are named.
grep -q '^IF \$AA_IM\[Z\]<-5600.0000 GOTOF ' "$D/plan.spf" || fail "no start check"
grep -q '^SETAL(65004)' "$D/plan.spf" || fail "the profile's start_alarm is not raised"
grep -q 'alarm 65004 (axis at or past the thread start' "$D/plan.spf" || fail "header: start alarm"
grep -q 'MD28250 \$MC_MM_NUM_SYNC_ELEMENTS' "$D/plan.spf" || fail "header: MD28250"
# After every alarm the program jumps to its end (the label just before M17), so it changes
# nothing whether or not the alarm stops the program.
expect_jumps_to_end "$D/plan.spf"
expect_jumps_to_end "$D/ids.spf"
# The part program writes setting data only to give back what an aborted run saved (from R).
grep -E '^\$SA_TEMP_COMP_' "$D/plan.spf" | grep -qvE '=R[0-9]+$' &&
  fail "the part program writes a plan value before motion"

# Program names: the headers name the files' stems; names a control refuses are refused, and
# so is one program given twice (same file by another path, or names differing only in case).
"$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 --machine "$M" \
  --nc "$D/MY_COMP.SPF" --reset-nc "$D/MY_UNDO.SPF" > /dev/null || fail "plan with own names"
head -1 "$D/MY_COMP.SPF" | grep -q '^; MY_COMP: ' || fail "header does not name MY_COMP"
grep -q 'call MY_UNDO after' "$D/MY_COMP.SPF" || fail "header does not name MY_UNDO"
head -1 "$D/MY_UNDO.SPF" | grep -q '^; MY_UNDO: .*aborted MY_COMP run' || fail "reset header"
grep -q 'WHIRL_TEMP_COMP' "$D/MY_COMP.SPF" "$D/MY_UNDO.SPF" && fail "another program named"
for bad in "1 my comp.spf" "my comp.spf" "WHIRL-COMP.SPF" "A_VERY_LONG_PROGRAM_NAME_X.SPF"; do
  expect_fail "program name" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
    --machine "$M" --nc "$D/$bad"
  [ -e "$D/$bad" ] && fail "'$bad' written"
done
mkdir -p "$D/real" && ln -sfn real "$D/link"
(cd "$D" && expect_fail "same file\|one program" "$W" plan --screw "$S" --max-elongation-um 30 \
  --settle-time-s 250 --machine "$M" --nc AB.SPF --reset-nc ./AB.SPF) || exit 1
[ -e "$D/AB.SPF" ] && fail "AB.SPF written although given twice"
expect_fail "same file\|one program" "$W" plan --screw "$S" --max-elongation-um 30 \
  --settle-time-s 250 --machine "$M" --nc "$D/real/AB.SPF" --reset-nc "$D/link/AB.SPF"
expect_fail "one program" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
  --machine "$M" --nc "$D/AB.SPF" --reset-nc "$D/real/ab.spf"
# Any two outputs naming one file by different paths are refused (canonical paths compared).
(cd "$D" && expect_fail "same file\|given twice" "$W" plan --screw "$S" --max-elongation-um 30 \
  --settle-time-s 250 --machine "$M" --out P.json --csv ./P.json) || exit 1
[ -e "$D/P.json" ] && fail "P.json written although given twice"
# Bad machine profile: the message names the file and the key.
sed 's/"direction": 1/"direction": 2/' "$M" > "$D/bad_machine.json"
expect_fail "bad_machine.json" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
  --machine "$D/bad_machine.json"
sed 's/"sync_id_first": 200/"sync_id_frist": 200/' "$M" > "$D/typo_machine.json"
expect_fail "sync_id_frist" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
  --machine "$D/typo_machine.json"
# A tighter tolerance needs more points.
"$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 --machine "$M" --tolerance-um 0.1 \
  --csv "$D/tight.csv" > /dev/null || fail "plan tight"
tight=$(grep -v '^#' "$D/tight.csv" | tail -n +2 | grep -vc '^restore')
[ "$tight" -gt "$segments" ] || fail "tolerance 0.1 gave $tight segments, 0.5 gave $segments"

# Bad input: negative tolerance, a slope cap below the plan's slopes (nothing overwritten).
cp "$D/plan.json" "$D/plan.before"
expect_fail "tolerance-um" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
  --machine "$M" --tolerance-um -1
expect_fail "MD32760" "$W" plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 --machine "$M" \
  --md32760 1e-6 --out "$D/plan.json"
cmp -s "$D/plan.json" "$D/plan.before" || fail "failed plan overwrote the previous file"
expect_fail "either" "$W" plan --screw "$S"

# With a model: train a small one on the shipped table, then plan inside and outside its domain.
[ -f "$SRC/datasets/whirling_train.csv" ] || fail "the shipped training table is missing"
"$W" train --data "$SRC/datasets/whirling_train.csv" --out "$D/m.json" --epochs 200 \
  > /dev/null 2>&1 || fail "train"
"$W" plan --model "$D/m.json" --screw "$S" --machine "$M" --json > "$D/model_plan.json" \
  || fail "plan --model"
grep -q '"max_elongation_std_um"' "$D/model_plan.json" || fail "plan JSON lacks the std"
sed 's/"diameter_mm": 80.0/"diameter_mm": 130.0/' "$S" > "$D/big.json"
expect_fail "allow-extrapolation" "$W" plan --model "$D/m.json" --screw "$D/big.json" --machine "$M"
"$W" plan --model "$D/m.json" --screw "$D/big.json" --machine "$M" --allow-extrapolation \
  > /dev/null 2> "$D/warn.txt" \
  || fail "plan --allow-extrapolation: $(cat "$D/warn.txt")"
grep -q "warning" "$D/warn.txt" || fail "no extrapolation warning"
"$W" curve --model "$D/m.json" --screw "$S" --out "$D/model_curve.csv" > /dev/null || fail "curve --model"
expect_fail "allow-extrapolation" "$W" curve --model "$D/m.json" --screw "$D/big.json"
echo "ok"
