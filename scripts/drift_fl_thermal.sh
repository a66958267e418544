#!/usr/bin/env bash
# Machine thermal drift on real measurements: FL_THERMAL (../shared/data/fl_thermal, MIT), the
# source's chronological split (first 60 % train, next 20 % test) with test MAE per channel beside
# the source's own random forest / XGBoost / seq2seq figures, and the cross-run table of its speed
# programme cut into runs. Deterministic (the network's seed is fixed).
# Usage: scripts/drift_fl_thermal.sh [out dir (default build/drift_fl_thermal)]
# Environment: WHIRL_FL_THERMAL (path of data.csv), WHIRL_BIN (default build/whirl).
set -euo pipefail
cd "$(dirname "$0")/.."
DATA="${WHIRL_FL_THERMAL:-../shared/data/fl_thermal/data.csv}"
W="${WHIRL_BIN:-build/whirl}"
OUT="${1:-build/drift_fl_thermal}"
if [ ! -f "$DATA" ]; then
  echo "FL_THERMAL data not found at $DATA (set WHIRL_FL_THERMAL): skipped" >&2
  exit 0
fi
mkdir -p "$OUT"
echo "== source's results (its README; test MAE um): ch1 RF 6.456 XGB 5.611 seq2seq 3.561;"
echo "   ch3 RF 7.330 XGB 6.039 seq2seq 3.704; ch5 RF 12.440 XGB 9.535 seq2seq 4.284"
echo "== whirl: hold-out, at most 4 sensors from Miao et al.'s selection on the training rows"
"$W" drift holdout --log "$DATA" --channels ch1_um,ch3_um,ch5_um --max-sensors 4 \
  --inputs spindle_rpm --out-dir "$OUT/holdout" | tee "$OUT/holdout.txt"
"$W" drift holdout --log "$DATA" --channels ch1_um,ch3_um,ch5_um --max-sensors 4 \
  --inputs spindle_rpm --json > "$OUT/holdout.json" 2> /dev/null
echo "== the same with the class count by cross-validation (--classes cv, training rows only)"
"$W" drift holdout --log "$DATA" --channels ch1_um,ch3_um,ch5_um --max-sensors 4 \
  --inputs spindle_rpm --no-network --classes cv 2> /dev/null | tee "$OUT/holdout_cv.txt"
echo "== sensitivity of the dynamic model to the lag search's cross-validation (test MAE um)"
for cv in "" "--leave-block-out" "--folds 10" "--leave-block-out --folds 10" "--max-lags 1"; do
  printf '%-30s' "${cv:-forward, 5 folds (default)}"
  "$W" drift holdout --log "$DATA" --channels ch1_um,ch3_um,ch5_um --no-network $cv 2> /dev/null |
    awk '$2 == "dynamic" { printf " %s %s", $1, $3 } END { print "" }'
done
echo "== speed programme cut into runs at every spindle start"
"$W" drift split --log "$DATA" --out-dir "$OUT/runs"
for ch in ch1_um ch3_um ch5_um; do
  for model in mlr dynamic; do
    echo "-- $ch, $model, errors taken from each run's start (Miao et al.'s table: the sensor model)"
    "$W" drift crossval --idle "$OUT"/runs/data_*.csv --error "$ch" --max-sensors 4 --model "$model" \
      --candidates sensors --error-zero run-start 2> /dev/null
  done
done
"$W" drift report --train-idle "$OUT"/runs/data_1.csv "$OUT"/runs/data_2.csv "$OUT"/runs/data_3.csv \
  --idle "$OUT"/runs/data_*.csv --error ch1_um --max-sensors 4 --model dynamic --out-dir "$OUT/report_ch1" \
  2> /dev/null
echo "== the default's choice at other split points: scripts/drift_fl_thermal_splits.sh"
echo "reports: $OUT/holdout/index.html, $OUT/report_ch1/index.html"
