#!/usr/bin/env bash
# Smoke test of 'whirl plan': args <whirl> <scratch dir> <source dir>.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"
source "$SRC/tests/support/cli_common.sh"
S="$SRC/datasets/screws/reference_80x10x6000.json"

"$W" plan --help | grep -q "SD43910" || fail "plan --help"

# From given features: all three outputs, consistent with each other.
"$W" plan --screw "$S" --max-elongation 30 --settle-time 250 --out "$D/plan.json" \
  --csv "$D/plan.csv" --nc "$D/plan.mpf" > "$D/plan.txt" || fail "plan"
for f in plan.json plan.csv plan.mpf; do [ -s "$D/$f" ] || fail "$f not written"; done
grep -q '"schema": "whirl.plan"' "$D/plan.json" || fail "plan JSON schema"
grep -q '"uniform_point_count"' "$D/plan.json" || fail "plan JSON uniform count"
grep -q "MD32750 \$MA_TEMP_COMP_TYPE = 3" "$D/plan.mpf" || fail "NC header"
segments=$(grep -v '^#' "$D/plan.csv" | tail -n +2 | wc -l)
actions=$(grep -c '^ID=' "$D/plan.mpf")
[ "$actions" -eq $((segments - 1)) ] || fail "$segments segments but $actions synchronized actions"
grep -q ">=" "$D/plan.mpf" || fail "direction +1 must compare with >="
"$W" plan --screw "$S" --max-elongation 30 --settle-time 250 --direction -1 --sign add \
  --nc "$D/minus.mpf" > /dev/null || fail "plan direction -1"
grep -q "<=" "$D/minus.mpf" || fail "direction -1 must compare with <="
# A tighter tolerance needs more points.
"$W" plan --screw "$S" --max-elongation 30 --settle-time 250 --tolerance-um 0.1 --csv "$D/tight.csv" \
  > /dev/null || fail "plan tight"
tight=$(grep -v '^#' "$D/tight.csv" | tail -n +2 | wc -l)
[ "$tight" -gt "$segments" ] || fail "tolerance 0.1 gave $tight segments, 0.5 gave $segments"

# Bad input: negative tolerance, a slope cap below the plan's slopes (nothing overwritten).
cp "$D/plan.json" "$D/plan.before"
"$W" plan --screw "$S" --max-elongation 30 --settle-time 250 --tolerance-um -1 > /dev/null 2>&1 \
  && fail "negative tolerance accepted"
expect_fail "MD32760" "$W" plan --screw "$S" --max-elongation 30 --settle-time 250 --md32760 1e-6 \
  --out "$D/plan.json"
cmp -s "$D/plan.json" "$D/plan.before" || fail "failed plan overwrote the previous file"
expect_fail "either" "$W" plan --screw "$S"

# With a model: train a small one on the shipped table, then plan inside and outside its domain.
if [ -f "$SRC/datasets/whirling_train.csv" ]; then
  "$W" train --data "$SRC/datasets/whirling_train.csv" --out "$D/m.json" --epochs 200 \
    > /dev/null 2>&1 || fail "train"
  "$W" plan --model "$D/m.json" --screw "$S" --json > "$D/model_plan.json" || fail "plan --model"
  grep -q '"max_elongation_std_um"' "$D/model_plan.json" || fail "plan JSON lacks the std"
  sed 's/"diameter_mm": 80.0/"diameter_mm": 130.0/' "$S" > "$D/big.json"
  expect_fail "allow-extrapolation" "$W" plan --model "$D/m.json" --screw "$D/big.json"
  "$W" plan --model "$D/m.json" --screw "$D/big.json" --allow-extrapolation > /dev/null 2> "$D/warn.txt" \
    || fail "plan --allow-extrapolation: $(cat "$D/warn.txt")"
  grep -q "warning" "$D/warn.txt" || fail "no extrapolation warning"
  "$W" curve --model "$D/m.json" --screw "$S" --out "$D/model_curve.csv" > /dev/null || fail "curve --model"
  expect_fail "allow-extrapolation" "$W" curve --model "$D/m.json" --screw "$D/big.json"
fi
echo "ok"
