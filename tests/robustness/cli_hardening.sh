#!/usr/bin/env bash
# What a hostile or careless user tried on the newer surfaces (issue 45), each a regression test:
# output manifests that would make whirl delete a user's file, a profile value that switched the
# control checks off, duplicate JSON keys, raw library messages from model files, unbounded
# times, day lists and run counts, and a deprecated flag given twice.
# Args: <whirl> <scratch dir> <source dir>.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"; cd "$D"
source "$SRC/tests/support/cli_common.sh"
# KEEP_GOING=1: report every failing check instead of stopping at the first (for an older build).
if [ -n "${KEEP_GOING:-}" ]; then fail() { echo "FAIL: $*"; }; fi
PROFILE="$SRC/datasets/machines/example_840d.json"
S="$SRC/datasets/screws/reference_80x10x6000.json"
json_set() {  # json_set <in> <out> <python statement on j> [argument, sys.argv[3]]
  python3 -c "import json,sys; j=json.load(open(sys.argv[1])); $3; json.dump(j, open(sys.argv[2], 'w'))" \
    "$1" "$2" "${@:4}" || fail "json_set $*"
}
no_raw_message() { grep -q 'json.exception' "$D/err.txt" && fail "raw library message: $(cat "$D/err.txt")"; return 0; }

# --- Output manifests (item 6): whirl replaces only what it can prove it wrote ------------------
"$W" machine sensors --out-dir d1 --idle 1 --cutting 1 > /dev/null || fail "machine sensors"
echo "my notes" > d1/notes.txt
# whirl's own manifest with notes.txt added, by name only (as version 1 listed files) or with a
# made-up hash: either way notes.txt is not provably whirl's, so it is neither removed nor replaced.
for forged in '"notes.txt"' '{"name": "notes.txt", "sha256": "'"$(printf '0%.0s' $(seq 64))"'"}'; do
  json_set d1/.whirl-output.json d1/.whirl-output.json "j['files'].append(json.loads(sys.argv[3]))" "$forged"
  expect_fail "notes.txt" "$W" machine sensors --out-dir d1 --idle 1 --cutting 1
  expect_fail "notes.txt" "$W" machine sensors --out-dir d1 --idle 2 --cutting 1
  [ "$(cat d1/notes.txt)" = "my notes" ] || fail "a forged manifest made whirl delete notes.txt"
  json_set d1/.whirl-output.json d1/.whirl-output.json "j['files'].pop()"
done
mkdir d2 && mkdir d2/.whirl-stage-999999-0 && echo "mine" > d2/.whirl-stage-999999-0/thesis.tex
expect_fail "thesis.tex" "$W" machine sensors --out-dir d2 --idle 1 --cutting 1
[ "$(cat d2/.whirl-stage-999999-0/thesis.tex)" = "mine" ] || fail "a staging-named folder deleted"
"$W" machine sensors --out-dir d3 --idle 1 --cutting 1 > /dev/null || fail "machine sensors d3"
mkdir d3/photos && echo "jpeg" > d3/photos/screw.jpg
expect_fail "photos" "$W" machine sensors --out-dir d3 --idle 1 --cutting 1
[ "$(cat d3/photos/screw.jpg)" = "jpeg" ] || fail "a foreign sub-directory was touched"
echo "edited" > d3/idle_1.csv
rm -r d3/photos
expect_fail "idle_1.csv.*changed since" "$W" machine sensors --out-dir d3 --idle 1 --cutting 1
[ "$(cat d3/idle_1.csv)" = "edited" ] || fail "an edited output was replaced"

# --- The control's limits (item 3): no profile value switches the checks off -------------------
json_set "$PROFILE" md.json "j['control']['md10300_analog_inputs'] = -1; j['control']['md28250_sync_elements'] = 5; j['control']['md28254_ac_params'] = 50"
expect_fail "md.json.*md10300_analog_inputs.*MD10300" "$W" plan --max-elongation-um 20 \
  --settle-time-s 300 --screw "$S" --machine md.json --nc PLAN.SPF --reset-nc PLAN_RESET.SPF

# --- JSON files (item 7): a key given twice is refused with its path ---------------------------
python3 - "$PROFILE" dup.json <<'EOF' || fail "dup.json"
import sys
text = open(sys.argv[1]).read()
open(sys.argv[2], "w").write(text.replace('"md32760": 0.01', '"md32760": 0.01, "md32760": 0.1', 1))
EOF
grep -q '"md32760": 0.01, "md32760": 0.1' dup.json || fail "the duplicate was not planted"
expect_fail "dup.json.*'md32760' is given twice" "$W" plan --max-elongation-um 20 \
  --settle-time-s 300 --screw "$S" --machine dup.json --nc PLAN.SPF --reset-nc PLAN_RESET.SPF

# --- Drift model files (item 7): the key and the rule, never the library's message -------------
"$W" drift fit --cutting d3/cutting_1.csv --error offset_um --candidates sensors --out m.json \
  > /dev/null 2>&1 || fail "drift fit"
json_set m.json m_sensors.json "j['sensors'] = [5]"
json_set m.json m_kind.json "j['kind'] = 3"
json_set m.json m_training.json "j['training']['samples'] = 'many'"
json_set m.json m_coef.json "j['linear']['coefficients'][1] = 'x'"
json_set m.json m_features.json "j['features'] = {}"
for c in "m_sensors.json:'sensors'\[0\] must be a string" "m_kind.json:'kind' must be a string" \
         "m_training.json:'samples'" "m_coef.json:'coefficients'\[1\] must be a number" \
         "m_features.json:'features' must be an array"; do
  expect_fail "${c#*:}" "$W" drift predict --model "${c%%:*}" --run d3/cutting_1.csv
  grep -q "${c%%:*}" err.txt || fail "the file is not named: $(cat err.txt)"
  no_raw_message
done

# --- Times and other columns (item 7): bounded in every command that reads runs ---------------
python3 - <<'EOF' || fail "time files"
rows = open("d3/cutting_1.csv").read().splitlines()
data = [r for r in rows if r and not r.startswith("#")]
head, body = data[0], data[1:]
bad = [r + ("," + ("0" if i % 10 == 0 else "1000")) for i, r in enumerate(body[:40])]
head = head + ",spindle_rpm"
cells = bad[-1].split(",")
cells[0] = "1e300"  # the last time: it still increases, so only the bound refuses it
bad[-1] = ",".join(cells)
open("t300.csv", "w").write("\n".join([head] + bad) + "\n")
cols = head.split(",")
tagged = [c if c != "offset_um" else "p1_x0_y0_um" for c in cols]
tagged = [c if c != "zscrew_per_1000_um" else "p2_x100_y0_um" for c in tagged]
open("t300_points.csv", "w").write("\n".join([",".join(tagged)] + bad) + "\n")
EOF
expect_fail "t300.csv:.*time_min.*1e+300.*outside" "$W" drift predict --model m.json --run t300.csv
expect_fail "t300.csv:.*time_min.*outside" "$W" drift split --log t300.csv --out-dir sp
expect_fail "t300.csv:.*time_min.*outside" "$W" drift report --train-cutting d3/cutting_1.csv \
  --run t300.csv --error offset_um --out-dir rep
expect_fail "t300_points.csv:.*time_min.*outside" "$W" surface points --run t300_points.csv --time-min 1

# --- Bounds of drift monitor --day and drift split (item 7, 4) ---------------------------------
days=(); for _ in $(seq 367); do days+=(--day d3/cutting_1.csv); done
expect_fail "367 day files.*at most 366" "$W" drift monitor --model m.json "${days[@]}"
awk 'BEGIN { print "time_min,a_C,spindle_rpm"; for (k = 0; k < 10001; k++) { print 2*k ",20,0"; print 2*k+1 ",20,1000" } }' > starts.csv
expect_fail "starts.csv.*spindle_rpm.*10001 times.*at most 10000" "$W" drift split --log starts.csv --out-dir sp

# --- A deprecated flag given twice names itself (item 7) ---------------------------------------
expect_fail "--save-r: given more than once.*--save-r-first" "$W" plan --save-r 90 --save-r 91
expect_fail "--check-every: given more than once" "$W" drift monitor --model m.json \
  --run d3/cutting_1.csv --check-every 5 --check-every 6
grep -q "error: : " err.txt && fail "a nameless message: $(cat err.txt)"
echo "cli_hardening: ok"
