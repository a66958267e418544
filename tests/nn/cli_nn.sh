#!/usr/bin/env bash
# Smoke test of 'whirl train' and 'whirl predict': help, results, determinism, exit codes and the
# messages for bad input. Usage (CTest): cli_nn.sh <whirl> <scratch dir> <source dir>
set -uo pipefail
whirl="$1"; scratch="$2"; src="$3"
rm -rf "$scratch"; mkdir -p "$scratch"; cd "$scratch"
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
# expect <code> <stderr substring> -- command...: runs, checks exit code and stderr text.
expect() {
  local code="$1" text="$2"; shift 3
  "$@" > out.txt 2> err.txt; local rc=$?
  [ "$rc" -eq "$code" ] || fail "exit $rc (want $code): $* ; stderr: $(cat err.txt)"
  [ -z "$text" ] || grep -qF -- "$text" err.txt || fail "stderr lacks '$text': $* ; got: $(cat err.txt)"
}
data="$src/datasets/whirling_train.csv"
H="hardness_hrc,diameter_mm,pitch_mm,raceway_radius_mm,cutting_speed_m_min,max_elongation_um,settle_time_s"

# --help explains, with units
expect 0 "" -- "$whirl" train --help
grep -q "max_elongation_um \[um\]" out.txt || fail "train --help lacks target units"
expect 0 "" -- "$whirl" predict --help
grep -q "\[HRC\]" out.txt || fail "predict --help lacks units"

# train: writes a model, human summary on stdout, progress on stderr
expect 0 "" -- "$whirl" train --data "$data" --out m1.json --seed 3 --restarts 2
[ -s m1.json ] || fail "no model written"
grep -q "gamma" out.txt || fail "train summary lacks gamma"
grep -q "train: done" err.txt || fail "no progress on stderr"
grep -q '"error_space": "normalized"' m1.json || fail "model lacks error_space"
grep -q '"schema_version": 2' m1.json || fail "model lacks schema_version"
# same seed => byte-identical file; --json summary
expect 0 "" -- "$whirl" train --data "$data" --out m2.json --seed 3 --restarts 2 --json
cmp -s m1.json m2.json || fail "same seed gave different model files"
grep -q '"termination"' out.txt || fail "train --json lacks termination"
grep -q '"log_evidence"' out.txt || fail "train --json lacks log_evidence"

# hidden size by evidence and brnn's stopping rule by default, --trainbr-matlab = fixed
# 5-6-2 trained to MATLAB's criteria, same file for any thread count
grep -q '"hidden_selection": "hidden size [0-9]* of the highest log evidence' m1.json \
  || fail "default train lacks the evidence hidden-size choice"
grep -q '"change": 0.001' m1.json || fail "default train lacks brnn's change = 0.001"
expect 0 "" -- "$whirl" train --data "$data" --out ma.json --hidden auto
grep -q '"hidden_selection": "hidden size [0-9]* chosen by 5-fold' ma.json \
  || fail "--hidden auto lacks the CV hidden-size choice"
expect 1 "excludes --change" -- "$whirl" train --data "$data" --out x.json --trainbr-matlab --change 0.01
expect 0 "" -- "$whirl" train --data "$data" --out t1.json --seed 3 --restarts 2 --threads 1
expect 0 "" -- "$whirl" train --data "$data" --out t2.json --seed 3 --restarts 2 --threads 2
cmp -s t1.json t2.json || fail "--threads 1 and 2 gave different models"
expect 0 "" -- "$whirl" train --data "$data" --out mm.json --trainbr-matlab --json
grep -q '"layer_sizes": \[5, 6, 2\]\|"layer_sizes":\[5,6,2\]' out.txt \
  || grep -A4 '"layer_sizes"' out.txt | tr -d ' \n' | grep -q '\[5,6,2\]' || fail "--trainbr-matlab is not 5-6-2"
grep -q '"fit_time_ms"' out.txt || fail "train --json lacks fit_time_ms"
expect 1 "expected 'evidence', 'auto' or an integer" -- "$whirl" train --data "$data" --out x.json --hidden 6x
expect 1 "exclude each other" -- "$whirl" train --data "$data" --out x.json --trainbr-matlab --stop-by-cv
# --ard: one alpha per input's weights; the model file says so and keeps the 6 group alphas, or
# says why the evidence did not keep the ARD stage
expect 0 "" -- "$whirl" train --data "$data" --out ard.json --ard --threads 1
grep -q '"ard": true' ard.json || fail "--ard model lacks training.options.ard"
python3 -c '
import json, sys
s = json.load(open("ard.json"))["training_summary"]
sys.exit(not (len(s.get("ard_alpha", [])) == 6 or "ARD stage not kept" in s["message"]))' \
  || fail "--ard model has neither 6 ard_alpha values nor the reason"
expect 0 "" -- "$whirl" predict --model ard.json --input "$data"
expect 1 "excludes --ard" -- "$whirl" train --data "$data" --out x.json --trainbr-matlab --ard

# hidden sweep
expect 0 "" -- "$whirl" train --data "$data" --hidden-sweep 3..4 --folds 4
grep -q "cv_rms" out.txt || fail "sweep lacks cv columns"
[ "$(grep -cE '^ +[34] ' out.txt)" -eq 2 ] || fail "sweep should print 2 rows: $(cat out.txt)"
expect 1 "" -- "$whirl" train --data "$data" --hidden-sweep 3..4 --out x.json
expect 1 "hidden-sweep" -- "$whirl" train --data "$data" --hidden-sweep 5..2
expect 1 "--out" -- "$whirl" train --data "$data"

# predict one process (flags), a table, JSON, CSV output
expect 0 "" -- "$whirl" predict --model m1.json --hardness-hrc 62 --diameter-mm 80 --pitch-mm 10 \
  --raceway-radius-mm 5 --cutting-speed-m-min 180
grep -q "+-" out.txt || fail "predict table lacks +- std"
grep -q "max elongation \[um\]" out.txt || fail "predict table lacks units"
expect 0 "" -- "$whirl" predict --model m1.json --input "$src/datasets/whirling_validation.csv" \
  --out pred.csv
head -n 5 pred.csv | grep -q "^hardness_hrc,diameter_mm,pitch_mm,raceway_radius_mm,cutting_speed_m_min,max_elongation_um,max_elongation_std_um,settle_time_s,settle_time_std_s,outside_domain$" \
  || fail "predict --out header wrong: $(head -n 5 pred.csv)"
[ "$(grep -cvE '^(#|hardness)' pred.csv)" -eq "$(grep -cvE '^(#|hardness)' "$src/datasets/whirling_validation.csv")" ] \
  || fail "predict --out row count"
grep -q "mean absolute error" out.txt || fail "targets in --input not used for an error report"
# outside the domain: warning + JSON flag, still exit 0
expect 0 "outside the training domain" -- "$whirl" predict --model m1.json --hardness-hrc 62 \
  --diameter-mm 300 --pitch-mm 10 --raceway-radius-mm 5 --cutting-speed-m-min 180 --json
grep -q '"outside_domain": true' out.txt || fail "JSON lacks outside_domain flag"
grep -q '"diameter_mm"' out.txt || fail "JSON lacks the outside field name"
grep -q '"max_elongation_std_um"' out.txt || fail "JSON lacks std"
# many rows outside the domain: ONE summary warning line, the per-row list in --json
printf "hardness_hrc,diameter_mm,pitch_mm,raceway_radius_mm,cutting_speed_m_min\n" > far.csv
for d in 300 310 320 330 340; do printf "62,$d,10,5,180\n" >> far.csv; done
printf "62,80,10,5,999\n" >> far.csv
expect 0 "6 of 6 rows lie outside the training domain" -- "$whirl" predict --model m1.json \
  --input far.csv
[ "$(grep -c "outside the training domain" err.txt)" -eq 1 ] \
  || fail "predict should print one outside-domain line: $(cat err.txt)"
grep -q "diameter_mm in 5 rows, cutting_speed_m_min in 1 row" err.txt \
  || fail "summary lacks the per-input counts: $(cat err.txt)"
expect 0 "" -- "$whirl" predict --model m1.json --input far.csv --json
[ "$(grep -c '"outside_domain": true' out.txt)" -eq 6 ] || fail "JSON lacks per-row flags"
grep -q '"outside_domain_count": 6' out.txt || fail "JSON lacks outside_domain_count"

# targets that do not depend on the inputs (20 rows; inputs and targets uniform random,
# drawn independently: awk 'BEGIN{srand(7); ...}'): the evidence prefers a flat network, and train
# --family network says so on stderr and in --json; a table with structure gives no warning
{ echo "$H"; cat <<'ROWS'
49.738,54.719,10.926,2.859,102.045,55.148,359.757
40.639,44.063,5.553,4.107,117.875,57.644,348.930
57.779,26.556,7.155,5.151,257.740,50.666,325.953
41.068,33.637,10.098,2.064,152.274,53.637,345.565
40.718,22.896,6.816,4.091,288.077,57.741,344.252
59.012,31.559,12.335,5.930,278.106,57.888,330.559
59.598,42.131,8.248,5.476,243.433,55.403,339.393
50.117,44.279,5.891,4.237,289.579,55.989,334.516
44.185,58.505,8.347,2.981,107.009,55.162,346.081
59.509,31.616,10.056,5.704,215.871,52.390,354.515
49.398,21.115,9.179,3.799,216.227,57.427,319.120
45.966,31.322,14.752,5.217,278.001,50.643,321.805
56.758,46.530,14.387,2.189,225.179,52.734,317.542
53.219,51.585,5.604,4.545,116.001,55.659,333.745
53.187,52.199,9.710,2.517,266.569,58.889,334.741
48.280,45.265,13.977,4.849,282.933,58.729,330.987
56.093,57.489,13.799,4.570,220.095,58.185,341.385
44.527,23.676,14.821,5.549,276.305,50.425,331.421
59.231,44.337,5.861,4.484,182.680,55.571,345.007
44.925,37.839,8.291,4.641,115.521,52.268,322.351
ROWS
} > noise.csv
expect 0 "the network is nearly flat in max_elongation_um and settle_time_s" -- \
  "$whirl" train --data noise.csv --out noise.json --family network --json
grep -q '"warnings": \[$' out.txt || fail "train --json lacks the flat-network warning"
grep -q "nearly flat" out.txt || fail "train --json warning lacks its text"
expect 0 "" -- "$whirl" train --data "$data" --out m3.json --family network --json
grep -q '"warnings": \[\]' out.txt || fail "train --json warns on the shipped table"
! grep -q "nearly flat" err.txt || fail "train warned about a table with structure"

# targets linear in the inputs (20 rows, deterministic; elongation = 2 HRC + 0.5 D - 3 P
# + 100, settle = 0.8 v + 4 R + 50, +-0.6 of fixed 'noise'): the default's evidence picks the
# network without a hidden layer (--family network), and predict uses the file (truth at the probe: 190 um, 226 s)
awk 'BEGIN { print "'"$H"'"; for (i = 0; i < 20; i++) { h = 40 + (i * 7) % 20; d = 20 + (i * 13) % 40;
  p = 5 + (i * 3) % 10; r = 2 + (i * 11) % 4 + 0.5 * (i % 2); v = 100 + (i * 37) % 200;
  n = ((i * 7) % 5 - 2) * 0.3; printf "%g,%g,%g,%g,%g,%g,%g\n", h, d, p, r, v,
  2 * h + 0.5 * d - 3 * p + 100 + n, 0.8 * v + 4 * r + 50 - n } }' > linear.csv
expect 0 "" -- "$whirl" train --data linear.csv --out linear.json --family network
grep -q "network 5-2 (no hidden layer, linear; N = 12" out.txt || fail "linear table: $(head -1 out.txt)"
tr -d ' \n' < linear.json | grep -q '"layer_sizes":\[5,2\]' || fail "linear model file: not 5-2"
expect 0 "" -- "$whirl" train --data "$data" --out forced_linear.json --hidden 0 --restarts 2
grep -q "network 5-2 (no hidden layer, linear; N = 12" out.txt || fail "--hidden 0: $(head -1 out.txt)"
expect 0 "" -- "$whirl" predict --model linear.json --hardness-hrc 50 --diameter-mm 40 --pitch-mm 10 \
  --raceway-radius-mm 4 --cutting-speed-m-min 200 --json
grep -Eq '"max_elongation_um": 1(89\.[5-9]|90\.[0-4])' out.txt || fail "linear model: $(cat out.txt)"

# bad training tables: exit 1, message names file, line and column
printf "$H\n62,80,10,5,180,20,300\n62,80,x10,5,180,20,300\n" > cell.csv
printf "$H\n62,80,10,5,180,20,300\n62,nan,10,5,180,20,300\n" > nan.csv
printf "$H\n62,80,10,5,180,20,300\n62,80,10,5,inf,20,300\n" > inf.csv
printf "hardness_hrc,diameter_mm,pitch_mm,cutting_speed_m_min,max_elongation_um,settle_time_s\n62,80,10,180,20,300\n" > missing.csv
printf "$H,pitch_mm\n62,80,10,5,180,20,300,10\n" > dup.csv
printf "# only a comment\n$H\n" > empty.csv
printf "hardness_hrc,diameter_mm,pitch_mm,raceway_radius_mm,cutting_speed_m_min\n62,80,10,5,180\n63,81,11,6,190\n" > notarget.csv
expect 1 "cell.csv:3: column 3 ('pitch_mm'): 'x10'" -- "$whirl" train --data cell.csv --out bad.json
expect 1 "nan.csv:3: column 2 ('diameter_mm')" -- "$whirl" train --data nan.csv --out bad.json
expect 1 "inf.csv:3: column 5 ('cutting_speed_m_min')" -- "$whirl" train --data inf.csv --out bad.json
expect 1 "missing column 'raceway_radius_mm'" -- "$whirl" train --data missing.csv --out bad.json
expect 1 "dup.csv:1: duplicated column 'pitch_mm'" -- "$whirl" train --data dup.csv --out bad.json
expect 1 "empty.csv: table has no data rows" -- "$whirl" train --data empty.csv --out bad.json
expect 1 "missing column 'max_elongation_um'" -- "$whirl" train --data notarget.csv --out bad.json
expect 1 "" -- "$whirl" train --data does_not_exist.csv --out bad.json
expect 1 "does not exist" -- "$whirl" train --data "$data" --out no_such_dir/m.json
[ ! -e bad.json ] || fail "a failed train left bad.json behind"
expect 1 "integer in [0, 200]" -- "$whirl" train --data "$data" --out bad.json --hidden -1
[ ! -e bad.json ] || fail "a failed train left bad.json behind"
expect 1 "integer in [0, 200]" -- "$whirl" train --data "$data" --out bad.json --hidden 201
[ ! -e bad.json ] || fail "a failed train left bad.json behind"

# bad predict input
expect 1 "missing: --pitch-mm --raceway-radius-mm --cutting-speed-m-min" -- "$whirl" predict --model m1.json \
  --hardness-hrc 62 --diameter-mm 80
expect 1 "" -- "$whirl" predict --model m1.json --input "$src/datasets/whirling_validation.csv" --hardness-hrc 62
expect 1 "nan.csv:3" -- "$whirl" predict --model m1.json --input nan.csv
head -c 3000 m1.json > trunc.json
expect 1 "trunc.json" -- "$whirl" predict --model trunc.json --hardness-hrc 62 --diameter-mm 80 \
  --pitch-mm 10 --raceway-radius-mm 5 --cutting-speed-m-min 180
sed 's/"schema_version": 2/"schema_version": 7/' m1.json > v7.json
expect 1 "schema_version" -- "$whirl" predict --model v7.json --hardness-hrc 62 --diameter-mm 80 \
  --pitch-mm 10 --raceway-radius-mm 5 --cutting-speed-m-min 180
expect 1 "" -- "$whirl" predict --model m1.json --hardness-hrc 62 --diameter-mm -80 --pitch-mm 10 \
  --raceway-radius-mm 5 --cutting-speed-m-min 180

if [ "$fails" -ne 0 ]; then echo "$fails failure(s)" >&2; exit 1; fi
echo "ok: whirl train/predict smoke test"
