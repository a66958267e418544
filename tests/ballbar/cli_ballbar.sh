#!/usr/bin/env bash
# Smoke test of 'whirl ballbar drift|circle|simulate': args <whirl> <scratch dir> <source dir>.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"
source "$SRC/tests/support/cli_common.sh"
num() { tr -d ' \n' < "$1" | grep -o "\"$2\":[-0-9.e+]*" | head -1 | cut -d: -f2; }

for c in drift circle simulate; do
  "$W" ballbar $c --help > "$D/help_$c.txt" || fail "ballbar $c --help"
done
grep -q "length_mm" "$D/help_drift.txt" || fail "drift --help does not explain the columns"
grep -q "1/K" "$D/help_drift.txt" || fail "drift --help has no units for alpha"
grep -q "SD43900" "$D/help_drift.txt" || fail "drift --help does not mention SD43900"
grep -q "um/m" "$D/help_circle.txt" || fail "circle --help has no units"

# The shipped demo data set is what the documented command writes (byte for byte).
(cd "$D" && "$W" ballbar simulate --seed 1 --out-dir datasets/ballbar > /dev/null) || fail "simulate"
for f in readings.csv pivots.json truth_drift.csv circle_xy_scale.csv circle_xy_cyclic.csv \
         circle_xz_parallelism.csv README.md .whirl-output.json; do
  cmp -s "$D/datasets/ballbar/$f" "$SRC/datasets/ballbar/$f" || fail "datasets/ballbar/$f differs from its command"
done
# The documented command also runs over the shipped folder itself (whirl's output: replaced).
mkdir -p "$D/regen/datasets" && cp -r "$SRC/datasets/ballbar" "$D/regen/datasets/"
(cd "$D/regen" && "$W" ballbar simulate --seed 1 --out-dir datasets/ballbar > /dev/null) \
  || fail "simulate over the shipped datasets/ballbar"
diff -r "$D/regen/datasets/ballbar" "$SRC/datasets/ballbar" > /dev/null || fail "regenerated folder differs"
S="$D/datasets/ballbar"

# Drift: run file, JSON, SD43900 = -drift/1000 with the default sign.
"$W" ballbar drift --readings "$S/readings.csv" --pivots "$S/pivots.json" --out "$D/drift.csv" \
  > "$D/drift.txt" 2> "$D/drift.err" || fail "drift: $(cat "$D/drift.err")"
sed -n '/^time_min/p' "$D/drift.csv" | grep -qx "time_min,drift_x_um,drift_y_um,drift_z_um" \
  || fail "drift CSV header"
[ "$(grep -vc '^#' "$D/drift.csv")" -eq 18 ] || fail "drift CSV: expected 17 blocks + header"
grep -q "SD43900" "$D/drift.txt" || fail "drift text output lacks SD43900"
"$W" ballbar drift --readings "$S/readings.csv" --pivots "$S/pivots.json" --json > "$D/drift.json" \
  || fail "drift --json"
# Last block: measured Z drift against the truth within 3 sd.
zt=$(tail -1 "$S/truth_drift.csv" | cut -d, -f4)
zm=$(tail -1 "$D/drift.csv" | cut -d, -f4)
zs=$(tr -d ' \n' < "$D/drift.json" | grep -o '"drift_sd_um":\[[^]]*\]' | tail -1 | tr -d ']' | cut -d, -f3)
awk -v a="$zm" -v b="$zt" -v s="$zs" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= 3 * s && s > 0) }' \
  || fail "Z drift $zm vs truth $zt (sd $zs)"
k=$(tr -d ' \n' < "$D/drift.json" | grep -o '"Z":[-0-9.e+]*' | cut -d: -f2)
awk -v k="$k" -v z="$zm" 'BEGIN { d = k + z / 1000; if (d < 0) d = -d; exit !(d < 1e-12) }' \
  || fail "SD43900 Z $k is not -drift/1000 ($zm um)"
"$W" ballbar drift --readings "$S/readings.csv" --pivots "$S/pivots.json" --sign add --json \
  > "$D/drift_add.json" || fail "--sign add"
tr -d ' \n' < "$D/drift_add.json" | grep -q '"sign":"add"' || fail "--sign add: no sign in the JSON"

# Circle: each planted error back within 2 %.
"$W" ballbar circle --trace "$S/circle_xy_scale.csv" --plane XY --radius-mm 100 --json > "$D/c1.json" \
  || fail "circle scale"
v=$(num "$D/c1.json" scale_mismatch_um_per_m)
awk -v v="$v" 'BEGIN { exit !(v > 29.4 && v < 30.6) }' || fail "scale mismatch $v, planted 30"
"$W" ballbar circle --trace "$S/circle_xz_parallelism.csv" --plane XZ --radius-mm 100 --json \
  > "$D/c2.json" || fail "circle XZ"
v=$(num "$D/c2.json" parallelism_urad)
awk -v v="$v" 'BEGIN { exit !(v > 39.2 && v < 40.8) }' || fail "parallelism $v, planted 40"
"$W" ballbar circle --trace "$S/circle_xy_cyclic.csv" --cyclic-period-1-mm 10 > "$D/c3.txt" \
  || fail "circle cyclic"
grep -q "cyclic amplitude X" "$D/c3.txt" || fail "circle text lacks the cyclic amplitude"
grep -q "fit residual RMS" "$D/c3.txt" || fail "circle text lacks the residual"

# Errors: exit 1, a message naming the file and the rule, nothing written.
printf 'time_min,pivot,length_mm\n0,1,150\n0,2,150\n' > "$D/short.csv"
expect_fail "no reading of pivot 3" "$W" ballbar drift --readings "$D/short.csv" --pivots "$S/pivots.json" \
  --bar-sd-um 0.1 --out "$D/none.csv"
[ -e "$D/none.csv" ] && fail "an output was written on failure"
printf 'time_min,pivot,length_mm\n0,7,150\n' > "$D/p7.csv"
expect_fail "p7.csv:2: column 'pivot'" "$W" ballbar drift --readings "$D/p7.csv" --pivots "$S/pivots.json"
printf '{"schema": "whirl.ballbar.pivots", "schema_version": 1, "pivots_mm": [[0,0,0],[100,0,0],[200,0.5,0]]}' \
  > "$D/line.json"
expect_fail "collinear" "$W" ballbar drift --readings "$S/readings.csv" --pivots "$D/line.json"
printf 'angle_deg,deviation_um\n' > "$D/quarter.csv"
for a in $(seq 0 5 90); do echo "$a,0" >> "$D/quarter.csv"; done
expect_fail "spans 90" "$W" ballbar circle --trace "$D/quarter.csv"
expect_fail "plane" "$W" ballbar circle --trace "$S/circle_xy_scale.csv" --plane XW
# A hostile file name reaches only messages (no HTML or gnuplot here): it must not break them.
cp "$D/p7.csv" "$D/a'b\"<script>.csv"
expect_fail "script" "$W" ballbar drift --readings "$D/a'b\"<script>.csv" --pivots "$S/pivots.json"
echo "ok"
