#!/usr/bin/env bash
# Smoke test of 'whirl drift monitor': args <whirl> <scratch dir> <source dir>.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"
source "$SRC/tests/support/cli_common.sh"

# Synthetic runs (awk, deterministic): sensors a (fast rise A) and b (slow ramp B); error =
# 2 A - 1.5 B, and from minute <change> on 3 A - 1.5 B + 4 (a planted change of the machine).
make_run() {  # make_run <file> <samples> <change minute>
  awk -v n="$2" -v c="$3" 'BEGIN {
    print "# synthetic monitored run for tests/drift/cli_monitor.sh (change at minute " c ")";
    print "time_min,a_C,b_C,err_um";
    for (k = 0; k < n; k++) {
      t = k; A = 8 * (1 - exp(-t / 30)); B = t / 40;
      e = (t >= c ? 3 * A - 1.5 * B + 4 : 2 * A - 1.5 * B) + 0.1 * sin(7 * k);
      printf "%d,%.4f,%.4f,%.4f\n", t, 20 + A, 21 + B, e;
    }
  }' > "$1"
}
make_run "$D/train.csv" 200 100000
make_run "$D/it's \"<script>run.csv" 600 250
H="$D/it's \"<script>run.csv"

"$W" drift monitor --help > "$D/help.txt" || fail "monitor --help"
for u in "\[min" "\[um\]" "patent" "bayes" "offset" "--check-every-min" "--refit-samples"; do
  grep -q -- "$u" "$D/help.txt" || fail "monitor --help lacks $u"
done
"$W" drift fit --run "$D/train.csv" --error err_um --sensors a_C,b_C --out "$D/m.json" > /dev/null 2>&1 \
  || fail "fit"

"$W" drift monitor --model "$D/m.json" --run "$H" --check-every-min 60 --threshold-um 1 \
  --refit-samples 4 --refit-every-min 10 --timeline "$D/timeline.csv" --events "$D/events.csv" \
  --out-dir "$D/report" > "$D/monitor.txt" 2> "$D/monitor_err.txt" || fail "monitor: $(cat "$D/monitor_err.txt")"
for rule in none static patent bayes offset; do
  grep -q "^$rule " "$D/monitor.txt" || fail "no row for $rule: $(cat "$D/monitor.txt")"
done
# The planted change is flagged: the patent rule recalibrates and beats the static model.
awk 'NF >= 9 && $1 == "static" { s = $2 } NF >= 9 && $1 == "patent" { p = $2; r = $7 }
     END { exit !(r >= 1 && p < s / 2) }' "$D/monitor.txt" \
  || fail "patent did not recover the change: $(cat "$D/monitor.txt")"
grep -q "^time_min,measured_um,static_um,patent_um,bayes_um,offset_um,static_residual_um" \
  "$D/timeline.csv" || fail "timeline header: $(grep -v '^#' "$D/timeline.csv" | head -1)"
[ "$(grep -vc '^#' "$D/timeline.csv")" -eq 601 ] || fail "timeline row count"
grep -q "^patent,update," "$D/events.csv" || fail "events CSV has no patent update"
grep -q "^patent,check,.*,0,check at .*invalid" "$D/events.csv" || fail "events CSV has no invalid check"
[ -f "$D/report/index.html" ] || fail "no report"
grep -q "<script>" "$D/report/index.html" && fail "run name not escaped in the report"
grep -q "&lt;script&gt;" "$D/report/index.html" || fail "run name missing from the report"
if command -v gnuplot > /dev/null; then
  [ -s "$D/report/monitor.png" ] || fail "no plot: $(cat "$D/report/gnuplot.log" 2> /dev/null)"
fi

"$W" drift monitor --model "$D/m.json" --run "$H" --threshold-um 1 --update bayes --json \
  > "$D/monitor.json" 2> /dev/null || fail "monitor --json"
python3 - "$D/monitor.json" <<'EOF' || fail "monitor --json content"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["schema"] == "whirl.drift_monitor", j["schema"]
rules = [s["rule"] for s in j["strategies"]]
assert rules == ["static", "bayes"], rules
b = j["strategies"][1]
assert b["recalibrations"] >= 1 and b["stop_min"] == b["measurements"] * 1.0
assert any(e["kind"] == "update" and "coefficients" in e for e in b["events"])
EOF
# The default bayes update adds the drift variance estimated from the checks and says so in its
# events; --no-drift-estimate leaves it out (the prior is --prior-scale x Cov(b) alone).
"$W" drift monitor --model "$D/m.json" --run "$H" --threshold-um 1 --update bayes \
  --events "$D/ev_drift.csv" > /dev/null 2>&1 || fail "monitor with the drift estimate"
"$W" drift monitor --model "$D/m.json" --run "$H" --threshold-um 1 --update bayes \
  --no-drift-estimate --events "$D/ev_nodrift.csv" > /dev/null 2>&1 || fail "--no-drift-estimate"
grep -q "^bayes,update,.*maximum likelihood" "$D/ev_drift.csv" ||
  fail "default bayes update does not state the drift estimate: $(grep update "$D/ev_drift.csv")"
grep -q "maximum likelihood" "$D/ev_nodrift.csv" && fail "--no-drift-estimate still estimates the drift"
grep -q "^bayes,update," "$D/ev_nodrift.csv" || fail "--no-drift-estimate: no bayes update"

# Bad input: nothing written, exit 1 with a message naming the rule.
expect_fail "score" "$W" drift monitor --model "$D/m.json" --run "$H" --score-rows 0.8,0.6 \
  --timeline "$D/bad.csv"
[ -e "$D/bad.csv" ] && fail "timeline written on failure"
expect_fail "check-every-min" "$W" drift monitor --model "$D/m.json" --run "$H" --check-every-min 0
sed 's/err_um/other_um/' "$D/train.csv" > "$D/noerr.csv"
expect_fail "err_um" "$W" drift monitor --model "$D/m.json" --run "$D/noerr.csv"
"$W" drift fit --run "$D/train.csv" --error err_um --sensors a_C,b_C --model network --epochs 20 \
  --out "$D/net.json" > /dev/null || fail "fit network"
expect_fail "network" "$W" drift monitor --model "$D/net.json" --run "$H"
echo "OK"
