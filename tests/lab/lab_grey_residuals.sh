#!/usr/bin/env bash
# scripts/grey_residuals.py: on a planted `whirl machine evaluate --json` document (three screws,
# hand-computed medians, correlation and hindsight figures; a scenario without an evaluated screw);
# on a tiny real run (one scenario, one machine, one past and one test day): one block per
# scenario, its screw count the JSON's, the four model rows, the start types adding up, the parts
# non-negative; bad arguments exit non-zero with a message.
# Usage (CTest): lab_grey_residuals.sh <whirl> <scratch dir> <source dir>
set -uo pipefail
W="$1"; D="$2"; S="$3"
rm -rf "$D"; mkdir -p "$D"; cd "$D"
source "$S/tests/lab/lab_common.sh"
GR=("$PY" "$S/scripts/grey_residuals.py")

"$PY" - <<'PY' || fail "could not write the planted document"
import json
def screw(start, totals, b, ok=True):
    # totals: both_grey, both_shop, warmup, workpiece; b: both_grey's slope [um/m] over 1000 mm
    m = lambda t, slope: {"metrics": {"accumulated_total_um": t, "mean_line_slope_um_per_m": slope,
                                      "useful_travel_mm": 1000.0, "v_u_um": 0.5,
                                      "accumulated_1000_um": 1.0}}
    names = ("both_grey", "both_shop", "warmup", "workpiece")
    return {"ok": ok, "start_type": start, "residual_workpiece_total_um": totals[3],
            "strategies": {n: m(t, b if n == "both_grey" else 1.0) for n, t in zip(names, totals)}}
screws = [screw("cold", [1, 4, 2, 9], 1.0), screw("warm", [2, 5, 1, 7], -2.0),
          screw("warm", [3, 6, 8, 8], 3.0), screw("warm", [50, 50, 50, 50], 9.0, ok=False)]
doc = {"schema": "whirl.machine_evaluate", "scenarios": [
    {"scenario": "planted", "seeds": [7], "strongest_sensor_free": "warmup",
     "runs": [{"screws": screws[:2]}, {"screws": screws[2:]}]},
    {"scenario": "empty", "seeds": [7], "strongest_sensor_free": "warmup",
     "runs": [{"screws": [screws[3]]}]}]}
json.dump(doc, open("planted.json", "w"))
PY
"${GR[@]}" planted.json > planted.txt 2> err.txt || fail "planted: $(cat err.txt)"
# The failed screw (ok false) is left out: 3 screws. both_grey: totals 1, 2, 3 (median 2), slope
# parts |b| x 1 m = 1, 2, 3 (median 2), band 0.5, b mean (1 - 2 + 3) / 3 = +0.67, population sd of
# 1, -2, 3 = sqrt(38 / 9) = 2.05, within 1000 mm 1. warmup: totals 2, 1, 8 (median 2), b 1.
# corr(both_grey 1 2 3, warmup 2 1 8) = 6 / sqrt(2 x 86 / 3) = 0.79; 30 % line 0.7 x 2 = 1.40;
# per screw min(both_grey, warmup) = 1, 1, 3 (median 1.00), min(both_grey, both_shop) = 1, 2, 3.
for line in "planted (seeds [7]): 3 screws, strongest sensor-free warmup" \
    "  both_grey     2.00   2.00   0.50   +0.67  2.05   1.00" \
    "  both_shop     5.00   1.00   0.50   +1.00  0.00   1.00" \
    "  warmup        2.00   1.00   0.50   +1.00  0.00   1.00" \
    "  workpiece     8.00   1.00   0.50   +1.00  0.00   1.00" \
    "  start cold        n=  1: both_grey 1.00, both_shop 4.00, warmup 2.00" \
    "  start warm        n=  2: both_grey 2.50, both_shop 5.50, warmup 4.50" \
    "  workpiece plan's own residual (median) 8.00" \
    "  corr(both_grey, warmup) per screw 0.79; slopes both_grey/both_shop nan" \
    "  30 % line 1.40; better of both_grey and warmup per screw (hindsight) 1.00; of both_grey and both_shop 2.00" \
    "empty: no screw evaluated"; do
  grep -qxF -- "$line" planted.txt || fail "planted: no line '$line' in: $(cat planted.txt)"
done

# A tiny real run.
"$W" machine evaluate --scenarios production --machines 1 --past-days 1 --test-days 1 --threads 1 \
  --json > eval.json 2> err.txt || fail "machine evaluate: $(cat err.txt)"
"${GR[@]}" eval.json > eval.txt 2> err.txt || fail "grey_residuals on a run: $(cat err.txt)"
check_py "eval.txt" '
import json, re, sys
doc = json.load(open("eval.json"))
text = open("eval.txt").read().splitlines()
for sc in doc["scenarios"]:
    n = sum(bool(s.get("ok")) for r in sc["runs"] for s in r["screws"])
    sf = sc["strongest_sensor_free"]
    name, seeds = sc["scenario"], sc["seeds"]
    head = f"{name} (seeds {seeds}): {n} screws, strongest sensor-free {sf}"
    assert n > 0 and head in text, (head, text)
    at = text.index(head)
    rows = {l.split()[0]: [float(v) for v in l.split()[1:]] for l in text[at + 2:at + 6]}
    assert list(rows) == ["both_grey", "both_shop", sf, "workpiece"], rows
    assert all(v[0] >= 0 and v[1] >= 0 and v[2] >= 0 and v[4] >= 0 and v[5] >= 0
               for v in rows.values()), rows
    starts = [int(m.group(1)) for l in text if (m := re.match(r"  start \S+ +n= *(\d+):", l))]
    assert sum(starts) == n, (starts, n)
'

# Bad arguments.
expect_usage_error "Usage: scripts/grey_residuals.py EVAL.json" "${GR[@]}"
echo '{"scenarios": 3' > broken.json
expect_usage_error "broken.json: not a \`whirl machine evaluate --json\` file" "${GR[@]}" broken.json
expect_usage_error "nosuch.json: not a" "${GR[@]}" nosuch.json
echo "lab_grey_residuals: passed ($PY)"
