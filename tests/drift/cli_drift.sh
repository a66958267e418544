#!/usr/bin/env bash
# Smoke test of 'whirl drift': args <whirl> <scratch dir> <source dir>.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"
source "$SRC/tests/support/cli_common.sh"

# Synthetic runs (awk, deterministic): two latent temperatures A (fast rise) and B (slow ramp),
# sensors a1,a2 follow A, b1,b2 follow B, c1 is a third shape; error = 2 A - 1.5 B (+ idle/cut
# offset scale). Written with a provenance comment.
make_run() {  # make_run <file> <gain> <phase>
  awk -v g="$2" -v p="$3" 'BEGIN {
    print "# synthetic drift run for the CLI smoke test (tests/drift/cli_drift.sh), gain " g;
    print "time_min,a1_C,a2_C,b1_C,b2_C,c1_C,err_um,spindle_rpm";
    for (k = 0; k < 240; k++) {
      t = k; A = g * 8 * (1 - exp(-t / 13)); B = g * t / 40; C = 2 * sin(t / 15 + p);
      n = 0.01 * sin(7 * k + p);
      printf "%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%d\n", t, 20 + A + n, 21 + 0.7 * A - n, 20 + B + n,
        22 + 1.3 * B, 20 + C, 2 * A - 1.5 * B + 0.05 * sin(3 * k), (k < 200 ? 1000 : 0);
    }
  }' > "$1"
}
make_run "$D/idle1.csv" 1.0 0.0
make_run "$D/idle2.csv" 0.8 1.0
make_run "$D/cut1.csv" 1.4 2.0
make_run "$D/it's \"<script>x.csv" 1.1 0.5

"$W" drift --help > "$D/help.txt" || fail "drift --help"
for c in select fit predict crossval holdout split report; do
  "$W" drift $c --help > "$D/help_$c.txt" || fail "drift $c --help"
done
grep -q "degC" "$D/help_fit.txt" || fail "fit --help has no units"
grep -q "\[um\]" "$D/help_predict.txt" || fail "predict --help has no units"
grep -q -- "--lag-grid-min FLOAT:> 0 min" "$D/help_fit.txt" && grep -q "lag time constants \[min\]" \
  "$D/help_fit.txt" || fail "fit --help does not give the lag unit"

# select: the two sensor groups (and c1) are found; JSON too.
"$W" drift select --idle "$D/idle1.csv" --error err_um --classes margin > "$D/select.txt" || fail "select"
grep -q "chosen sensors" "$D/select.txt" || fail "select prints no choice"
grep -q "lambda" "$D/select.txt" || fail "select prints no lambda levels"
"$W" drift select --idle "$D/idle1.csv" --error err_um --classes margin --json > "$D/select.json" || fail "select --json"
grep -q '"chosen_sensors"' "$D/select.json" || fail "select --json"
grep -q '"grey_grades"' "$D/select.json" || fail "select --json grades"
# --classes cv: the count by cross-validation, every candidate's score in the JSON.
"$W" drift select --idle "$D/idle1.csv" "$D/idle2.csv" --error err_um --classes cv --json \
  > "$D/select_cv.json" || fail "select --classes cv"
grep -q '"class_count_scores"' "$D/select_cv.json" || fail "select --classes cv lists no scores"
grep -q 'leave one run out' "$D/select_cv.json" || fail "select --classes cv: no rule in the JSON"

# fit (mlr, dynamic, network) and predict: the per-sample compensation CSV.
for m in mlr dynamic network; do
  "$W" drift fit --idle "$D/idle1.csv" --idle "$D/idle2.csv" --error err_um --model $m --epochs 100 \
    --out "$D/$m.json" > "$D/fit_$m.txt" || fail "fit --model $m: $(cat "$D/fit_$m.txt")"
  grep -q '"format": "whirl-drift-model"' "$D/$m.json" || fail "$m model file"
  grep -q '"reference_C"' "$D/$m.json" || fail "$m model has no reference temperatures"
done
"$W" drift fit --idle "$D/idle1.csv" --error err_um --json --out "$D/m.json" > "$D/fit.json" || fail "fit --json"
grep -q '"coefficients"' "$D/fit.json" || fail "fit --json has no coefficients"
# A production week (--day ...) writes what --out-dir, --timeline and --events name (issue 44
# item 2: the multi-day replay exited 0 and wrote nothing).
"$W" drift monitor --model "$D/mlr.json" --day "$D/idle2.csv" --day "$D/cut1.csv" --threshold-um 1 \
  --out-dir "$D/week" --timeline "$D/week_t.csv" --events "$D/week_e.csv" > /dev/null \
  2> "$D/week_err.txt" || fail "monitor --day: $(cat "$D/week_err.txt")"
for f in "$D/week/index.html" "$D/week_t.csv" "$D/week_e.csv"; do
  [ -s "$f" ] || fail "monitor --day did not write $f"
done
grep -v '^#' "$D/week_t.csv" | head -1 | grep -q "^day," || fail "week timeline has no day column"
"$W" drift predict --model "$D/mlr.json" --run "$D/cut1.csv" --out "$D/pred.csv" > "$D/pred.txt" \
  2> "$D/pred_err.txt" || fail "predict"
grep -q "^time_min,predicted_um,compensation_um,std_um,measured_um,residual_um" "$D/pred.csv" \
  || fail "prediction CSV header: $(grep -v '^#' "$D/pred.csv" | head -1)"
[ "$(grep -vc '^#' "$D/pred.csv")" -eq 241 ] || fail "prediction CSV row count"
grep -q "training range" "$D/pred_err.txt" || fail "no extrapolation warning for a hotter run"
"$W" drift predict --model "$D/dynamic.json" --run "$D/idle2.csv" --json > "$D/pred.json" || fail "predict --json"
grep -q '"residual"' "$D/pred.json" || fail "predict --json residual"

# crossval with states, split, holdout.
"$W" drift crossval --idle "$D/idle1.csv" "$D/idle2.csv" --cutting "$D/cut1.csv" --error err_um \
  > "$D/cv.txt" || fail "crossval"
grep -q "idle on cutting" "$D/cv.txt" || fail "crossval groups: $(cat "$D/cv.txt")"
"$W" drift crossval --idle "$D/idle1.csv" "$D/idle2.csv" --error err_um --json > "$D/cv.json" || fail "crossval --json"
grep -q '"mlr_all_sensors"' "$D/cv.json" || fail "crossval --json baseline"
"$W" drift split --log "$D/idle1.csv" --out-dir "$D/split" > /dev/null || fail "split"
[ -f "$D/split/idle1_1.csv" ] || fail "split wrote no run file"
"$W" drift holdout --log "$D/idle1.csv" --no-network --json > "$D/ho.json" || fail "holdout"
grep -q '"method": "dynamic"' "$D/ho.json" || fail "holdout methods"

# report with a hostile run name: escaped in HTML, never markup.
"$W" drift report --train-idle "$D/idle1.csv" --run "$D/it's \"<script>x.csv" --error err_um \
  --classes margin --out-dir "$D/report" > /dev/null 2> "$D/rep_err.txt" || fail "report: $(cat "$D/rep_err.txt")"
[ -f "$D/report/index.html" ] || fail "report has no index.html"
grep -q "<script>" "$D/report/index.html" && fail "run name reached the HTML unescaped"
grep -q "&lt;script&gt;x" "$D/report/index.html" || fail "escaped run name missing"
if command -v gnuplot > /dev/null; then  # the hostile name reached gnuplot's titles safely
  ls "$D/report/"*script*_prediction.png > /dev/null 2>&1 || fail "no plot for the hostile run name"
  # a relative --out-dir (gnuplot runs inside the report directory)
  (cd "$D" && "$W" drift report --train-idle idle1.csv --error err_um --out-dir rel > /dev/null 2>&1) \
    || fail "report with a relative --out-dir"
  [ -f "$D/rel/idle1_prediction.png" ] || fail "relative --out-dir: plot not rendered"
fi

# report --json: the model, each run's residual against no compensation, the page's path.
"$W" drift report --train-idle "$D/idle1.csv" --run "$D/cut1.csv" --error err_um --out-dir "$D/rj" \
  --json > "$D/report.json" 2> /dev/null || fail "report --json"
python3 - "$D/report.json" "$D/rj/index.html" <<'EOF2' || fail "report --json content: $(head -c 400 "$D/report.json")"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["schema"] == "whirl.drift_report", j["schema"]
assert j["index_html"] == sys.argv[2], j["index_html"]
assert j["model"]["error_column"] == "err_um", j["model"]
runs = j["runs"]
assert [r["run"] for r in runs] == ["cut1"], runs
assert runs[0]["residual"]["rmse_um"] < runs[0]["no_compensation"]["rmse_um"], runs[0]
EOF2

# --candidates on every command that fits (issue 38): report, crossval and holdout's fit row.
"$W" drift report --train-idle "$D/idle1.csv" --run "$D/cut1.csv" --error err_um --candidates time \
  --out-dir "$D/rt" --json > "$D/rt.json" 2> /dev/null || fail "report --candidates time"
python3 - "$D/rt.json" <<'EOF2' || fail "report --candidates time: $(head -c 400 "$D/rt.json")"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["model"]["sensors"] == [], j["model"]
assert [c["name"] for c in j["candidates"]] == ["time1", "time2"], j["candidates"]
EOF2
grep -q "candidates (validation RMSE" "$D/rt/index.html" || fail "report page lacks the candidates"
grep -q "previous run" "$D/rt/index.html" || fail "report page lacks the previous-run baseline"
"$W" drift report --train-idle "$D/idle1.csv" --error err_um --candidates sensors --out-dir "$D/rs" \
  --json > "$D/rs.json" 2> /dev/null || fail "report --candidates sensors"
grep -q '"time1"' "$D/rs.json" && fail "report --candidates sensors scored a time model"
"$W" drift crossval --idle "$D/idle1.csv" "$D/idle2.csv" --error err_um --candidates time \
  > "$D/cvt.txt" 2> /dev/null || fail "crossval --candidates time"
grep -q "candidates time" "$D/cvt.txt" || fail "crossval does not say its candidates"
grep -q "elapsed time (tau" "$D/cvt.txt" || fail "crossval --candidates time: no time model"
"$W" drift holdout --log "$D/idle1.csv" --no-network --candidates time --json > "$D/hot.json" \
  2> /dev/null || fail "holdout --candidates time"
python3 - "$D/hot.json" <<'EOF2' || fail "holdout fit row: $(head -c 400 "$D/hot.json")"
import json, sys
rows = {r["method"]: r for r in json.load(open(sys.argv[1]))["results"]}
assert rows["fit"]["test"]["mae_um"] == rows["time"]["test"]["mae_um"], rows["fit"]
EOF2
expect_fail "candidates" "$W" drift report --train-idle "$D/idle1.csv" --error err_um \
  --candidates nonsense --out-dir "$D/never"

# Bad input: clear errors, nothing written.
printf 'time_min,a_C,err_um\n0,20,0\n1,abc,1\n' > "$D/bad.csv"
expect_fail "bad.csv:3" "$W" drift fit --run "$D/bad.csv" --error err_um --out "$D/never.json"
[ -e "$D/never.json" ] && fail "a model was written on failure"
expect_fail "no thermal-error" "$W" drift select --run "$D/idle1.csv" --error ch9_um
expect_fail "not a drift model" "$W" drift predict --model "$D/select.json" --run "$D/idle1.csv"
expect_fail "classes" "$W" drift select --run "$D/idle1.csv" --error err_um --classes 99
# Issue 43: a generated long log (scripts/make_long_log.py) through the streamed commands;
# --progress prints on stderr only (stdout stays JSON), the report plots the decimated rows.
python3 "$SRC/scripts/make_long_log.py" --rows 20000 --out "$D/long.csv" || fail "make_long_log.py"
"$W" drift fit --run "$D/long.csv" --error ch1_um --out "$D/long.json" --progress --json \
  > "$D/long_fit.json" || fail "fit on the long log"
python3 -m json.tool "$D/long_fit.json" > /dev/null || fail "fit --json --progress: stdout is not JSON"
"$W" drift predict --model "$D/long.json" --run "$D/long.csv" --out "$D/long_pred.csv" --progress \
  > /dev/null || fail "predict on the long log"
[ "$(grep -vc '^#' "$D/long_pred.csv")" = 20001 ] || fail "predict did not write every row"
"$W" drift split --log "$D/long.csv" --out-dir "$D/long_split" --json --progress \
  > "$D/long_split.json" || fail "split of the long log"
python3 - "$D/long_split.json" <<'EOF2' || fail "split rows do not add up to the log"
import json, sys
assert sum(r["samples"] for r in json.load(open(sys.argv[1]))["runs"]) == 20000
EOF2
"$W" drift report --train-run "$D/long.csv" --run "$D/long.csv" --error ch1_um \
  --out-dir "$D/long_rep" --json --progress > "$D/long_rep.json" 2> "$D/long_rep_err.txt" \
  || fail "report on the long log: $(tail -3 "$D/long_rep_err.txt")"
[ "$(grep -vc '^#' "$D/long_rep/long_plot.csv")" -lt 20001 ] || fail "the plot rows are not decimated"
[ "$(grep -vc '^#' "$D/long_rep/long_prediction.csv")" = 20001 ] || fail "report: not every row in the CSV"
python3 - "$D/long_rep.json" <<'EOF2' || fail "report --json --progress: $(head -c 300 "$D/long_rep.json")"
import json, sys
j = json.load(open(sys.argv[1]))  # stdout stays JSON with --progress
assert j["runs"][0]["samples"] == 20000, j["runs"][0]
b = j["baselines"]["runs"][0]
assert b["time_only_mae_um"] is not None and b["model_mae_um"] is not None, b
EOF2
echo "ok"
