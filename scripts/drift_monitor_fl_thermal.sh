#!/usr/bin/env bash
# On-line check and recalibration (Liu et al.'s check-bar patent) on real measurements: FL_THERMAL
# (../shared/data/fl_thermal, MIT). Train on the log up to the end of its first 4-hour running
# block (1250 rpm), monitor the rest with check-bar measurements every 1, 2 and 4 h; MAE per
# channel and rule over the monitored part and over the source's test window (rows 60-80 %), with
# the share of time the checks stop the machine. Deterministic (no noise draws unless NOISE_UM).
# Usage: scripts/drift_monitor_fl_thermal.sh [out dir (default build/drift_monitor_fl_thermal)]
# Environment: WHIRL_FL_THERMAL (data.csv), WHIRL_BIN (build/whirl), MODEL (mlr|dynamic, default
# mlr), STOP_MIN (machine stop per measurement [min], default 1), THRESHOLD (--threshold-sigma,
# default 3), REFIT (--refit-samples, default 3), REFIT_EVERY ([min], default 5), PRIOR (--prior-scale,
# default 1), NOISE_UM (default 0), INPUTS (extra model inputs, e.g. spindle_rpm; default none).
set -euo pipefail
cd "$(dirname "$0")/.."
DATA="${WHIRL_FL_THERMAL:-../shared/data/fl_thermal/data.csv}"
W="${WHIRL_BIN:-build/whirl}"
OUT="${1:-build/drift_monitor_fl_thermal}"
MODEL="${MODEL:-mlr}"
if [ ! -f "$DATA" ]; then
  echo "FL_THERMAL data not found at $DATA (set WHIRL_FL_THERMAL): skipped" >&2
  exit 0
fi
mkdir -p "$OUT"
# Training rows: from the first row to the last row of the first running block (spindle > 0).
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "spindle_rpm") c = i; print; next }
  { if ($c > 0) run = 1; else if (run) exit; print }' "$DATA" > "$OUT/train.csv"
rows=$(($(wc -l < "$OUT/train.csv") - 1))
end_min=$(awk -F, 'END { print $1 / 60 }' "$OUT/train.csv")
echo "== training: rows 0..$((rows - 1)) of $DATA (to $end_min min, first 1250 rpm block); model $MODEL"
echo "== source's seq2seq test MAE (rows 60-80 %, no measurement after training): ch1 3.56, ch3 3.70, ch5 4.28 um"
for ch in ch1_um ch3_um ch5_um; do
  "$W" drift fit --run "$OUT/train.csv" --error "$ch" --max-sensors 4 --model "$MODEL" \
    ${INPUTS:+--inputs "$INPUTS"} --out "$OUT/model_$ch.json" > "$OUT/fit_$ch.txt" 2> /dev/null
  echo "-- $ch: $(grep -m1 -i 'sensors' "$OUT/fit_$ch.txt" || true); $(grep -m1 -i 'time constants\|lag' "$OUT/fit_$ch.txt" || true)"
  for every in 60 120 240; do
    args=(--model "$OUT/model_$ch.json" --run "$DATA" --start-min "$end_min" --check-every-min "$every"
          --threshold-sigma "${THRESHOLD:-3}" --refit-samples "${REFIT:-3}"
          --refit-every-min "${REFIT_EVERY:-5}" --stop-min "${STOP_MIN:-1}"
          --prior-scale "${PRIOR:-1}" --noise-um "${NOISE_UM:-0}")
    "$W" drift monitor "${args[@]}" --json > "$OUT/monitor_${ch}_${every}.json" 2> /dev/null
    "$W" drift monitor "${args[@]}" --score-rows 0.6,0.8 --json \
      > "$OUT/monitor_${ch}_${every}_test.json" 2> /dev/null
    [ "$every" = 120 ] && "$W" drift monitor "${args[@]}" --out-dir "$OUT/report_$ch" \
      > /dev/null 2>&1
    python3 - "$OUT/monitor_${ch}_${every}.json" "$OUT/monitor_${ch}_${every}_test.json" "$every" <<'EOF'
import json, sys
a, t = (json.load(open(p)) for p in sys.argv[1:3])
print(f"   checks every {int(sys.argv[3]) // 60} h, threshold {a['threshold_um']:.2f} um:"
      f" rule, MAE monitored / test window [um], checks, recalibrations, stop [min, %]")
print(f"     {'none':7s} {a['none']['mae_um']:7.2f} / {t['none']['mae_um']:6.2f}")
for s, st in zip(a["strategies"], t["strategies"]):
    print(f"     {s['rule']:7s} {s['score']['mae_um']:7.2f} / {st['score']['mae_um']:6.2f}"
          f" {s['checks']:4d} {s['recalibrations']:4d} {s['stop_min']:6.0f} {100 * s['stop_share']:5.2f} %")
EOF
  done
done
echo "reports (checks every 2 h): $OUT/report_ch*/index.html"
