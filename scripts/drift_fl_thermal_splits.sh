#!/usr/bin/env bash
# The candidate choice of `whirl drift fit` on FL_THERMAL (../shared/data/fl_thermal, MIT) at many
# chronological splits: for each split point p and channel, fit on the first p % of the rows, predict
# the log from its first row (lags, reference and elapsed time from the run's start) and score the
# next 20 % of the rows (rows [floor(p N / 100), floor((p + 20) N / 100))), once per candidate
# family: auto (the default), sensors, time. Prints per case the test MAE [um] of each, the better of
# sensors and time, the default's ratio to it and the candidate it chose; then the sums and the two
# acceptance figures of the default (summed MAE / summed better-of, worst single ratio).
# Only the whirl command line is called; awk computes the MAE from `drift predict --out`.
# Usage: scripts/drift_fl_thermal_splits.sh [out dir (default build/drift_fl_thermal_splits)]
# Environment: WHIRL_FL_THERMAL (data.csv), WHIRL_BIN (default build/whirl),
#   SPLITS (default "40 50 60 70": the acceptance set of issue 38, the confirmation set of the
#   default's choice rule; "35 45 55 65" is its tuning set), TEST_PCT (default 20),
#   CHANNELS (default "ch1_um ch3_um ch5_um"; the tuning set adds ch2_um ch4_um),
#   CANDIDATES (default "auto sensors time"), FIT_ARGS (extra drift fit arguments, e.g. "--model
#   dynamic"), JOBS (parallel fits, default 2).
set -euo pipefail
cd "$(dirname "$0")/.."
DATA="${WHIRL_FL_THERMAL:-../shared/data/fl_thermal/data.csv}"
W="${WHIRL_BIN:-build/whirl}"
OUT="${1:-build/drift_fl_thermal_splits}"
SPLITS="${SPLITS:-40 50 60 70}"
TEST_PCT="${TEST_PCT:-20}"
CHANNELS="${CHANNELS:-ch1_um ch3_um ch5_um}"
CANDIDATES="${CANDIDATES:-auto sensors time}"
JOBS="${JOBS:-2}"
if [ ! -f "$DATA" ]; then
  echo "FL_THERMAL data not found at $DATA (set WHIRL_FL_THERMAL): skipped" >&2
  exit 0
fi
mkdir -p "$OUT"
n=$(($(wc -l < "$DATA") - 1))

# One case: fit on the first p % with --candidates c, predict the prefix, MAE over the test rows.
one_case() {
  local p=$1 ch=$2 c=$3
  local a=$((n * p / 100)) b=$((n * (p + TEST_PCT) / 100))
  local tag="p${p}_${ch}_${c//+/_}"
  # shellcheck disable=SC2086
  "$W" drift fit --run "$OUT/train_$p.csv" --error "$ch" --candidates "$c" ${FIT_ARGS:-} \
    --out "$OUT/model_$tag.json" > "$OUT/fit_$tag.txt" 2> /dev/null
  "$W" drift predict --model "$OUT/model_$tag.json" --run "$OUT/prefix_$p.csv" \
    --out "$OUT/pred_$tag.csv" > /dev/null 2>&1
  local chosen
  chosen=$(sed -n 's/^chosen: \([^:]*\):.*/\1/p' "$OUT/fit_$tag.txt" | head -1)
  awk -F, -v a="$a" -v b="$b" -v tag="$tag" -v chosen="${chosen:-$c}" '
    /^#/ { next } !h { for (i = 1; i <= NF; i++) if ($i == "residual_um") r = i; h = 1; next }
    { k++ } k > a && k <= b { s += ($r < 0 ? -$r : $r); m++ }
    END { printf "%s %.4f %s\n", tag, s / m, chosen }' "$OUT/pred_$tag.csv" > "$OUT/mae_$tag.txt"
}
export -f one_case
export W OUT n TEST_PCT FIT_ARGS

for p in $SPLITS; do
  b=$((n * (p + TEST_PCT) / 100))
  [ "$b" -le "$n" ] || { echo "split $p % + $TEST_PCT % runs past the log" >&2; exit 2; }
  head -n $((1 + n * p / 100)) "$DATA" > "$OUT/train_$p.csv"
  head -n $((1 + b)) "$DATA" > "$OUT/prefix_$p.csv"
done
for p in $SPLITS; do for ch in $CHANNELS; do for c in $CANDIDATES; do echo "$p $ch $c"; done; done; done |
  xargs -P "$JOBS" -n 3 bash -c 'one_case "$@"' _

echo "== FL_THERMAL: fit on the first p % of rows, test MAE [um] on the next $TEST_PCT % (from the run's start)"
printf '%-4s %-7s' p channel
for c in $CANDIDATES; do printf ' %9s' "$c"; done
printf ' %9s %8s  %s\n' better default/better "default chose"
for p in $SPLITS; do
  for ch in $CHANNELS; do
    line=$(printf '%-4s %-7s' "$p" "$ch")
    vals=()
    for c in $CANDIDATES; do
      v=$(awk '{ print $2 }' "$OUT/mae_p${p}_${ch}_${c//+/_}.txt")
      vals+=("$c=$v")
      line="$line $(printf ' %9.2f' "$v")"
    done
    chosen=$(awk '{ print $3 }' "$OUT/mae_p${p}_${ch}_auto.txt" 2> /dev/null || echo -)
    echo "$line ${vals[*]} $chosen"
  done
done | awk -v cands="$CANDIDATES" '
  { n = split(cands, c, " "); for (i = 1; i <= n; i++) { split($(2 + n + i), kv, "="); v[c[i]] = kv[2] }
    better = v["sensors"] < v["time"] ? v["sensors"] : v["time"]
    ratio = better > 0 ? v["auto"] / better : 0
    printf "%s %s", $1, $2; for (i = 1; i <= n; i++) printf " %9.2f", v[c[i]]
    printf " %9.2f %8.3f  %s\n", better, ratio, $NF
    sa += v["auto"]; sb += better; if (ratio > worst) { worst = ratio; wc = $1 " " $2 } }
  END { printf "sum: default %.2f um, better of sensors and time %.2f um: ratio %.3f (acceptance <= 1.05)\n", sa, sb, sa / sb
        printf "worst single case: %s, ratio %.3f (acceptance <= 1.25)\n", wc, worst }'
echo "source's XGBoost at 60 %: ch1 5.61, ch3 6.04, ch5 9.54 um; seq2seq 3.56, 3.70, 4.28 um"
