#!/usr/bin/env bash
# Smoke test of scripts/drift_fl_thermal_splits.sh (the 12-case table of issue 38) on a synthetic
# log shaped like FL_THERMAL (time_s, spindle_rpm, two channels, three sensors): the table, the
# sums and the two acceptance figures are printed, and in every case the default's MAE is that of
# the sensors or of the time model it chose (the choice picks one of them).
# Usage: cli_fl_splits.sh <whirl binary> <scratch dir> <source dir>
set -uo pipefail
W="$1" D="$2" SRC="$3"
source "$SRC/tests/support/cli_common.sh"
rm -rf "$D" && mkdir -p "$D"
# 1200 rows every 60 s: a warm-up that the first channel follows in time, speed steps that the
# second follows through sensor t2.
awk 'BEGIN { print "time_s,spindle_rpm,ch1_um,ch2_um,t1_C,t2_C,t3_C"; a = 0; b = 0;
  for (k = 0; k < 1200; k++) { rpm = (int(k / 150) % 2 ? 3000 : 1000); u = rpm / 3000;
    a += (1 - exp(-1 / 80)) * (1 - a); b += (1 - exp(-1 / 30)) * (u - b);
    printf "%d,%d,%.4f,%.4f,%.4f,%.4f,%.4f\n", 60 * k, rpm, 12 * a + 0.2 * sin(k), 6 * b + 0.1 * cos(k),
      20 + 3 * b + 0.02 * sin(3 * k), 21 + 5 * b, 20.5 + 0.001 * k + 0.05 * sin(k / 7) } }' > "$D/log.csv"
WHIRL_BIN="$W" WHIRL_FL_THERMAL="$D/log.csv" SPLITS="50 60" CHANNELS="ch1_um ch2_um" \
  bash "$SRC/scripts/drift_fl_thermal_splits.sh" "$D/out" > "$D/table.txt" 2>&1 \
  || fail "splits script: $(cat "$D/table.txt")"
grep -q "^sum: default" "$D/table.txt" || fail "no sums: $(cat "$D/table.txt")"
grep -q "^worst single case" "$D/table.txt" || fail "no worst case"
rows=$(awk '$1 ~ /^[0-9]+$/ && NF == 8' "$D/table.txt" | wc -l)
[ "$rows" -eq 4 ] || fail "expected 4 cases, got $rows: $(cat "$D/table.txt")"
awk '$1 ~ /^[0-9]+$/ && NF == 8 { if ($3 != $4 && $3 != $5) bad = bad " " $1 "/" $2 }
     END { if (bad != "") { print "the default matches neither candidate:" bad; exit 1 } }' \
  "$D/table.txt" || fail "$(cat "$D/table.txt")"
echo "ok"
