#!/usr/bin/env bash
# scripts/median_rule_noise.py --verdicts on planted runs with hand-checkable verdicts: a default 5 %
# behind the best peer on every table is "behind" (ratio 1.050 in every bootstrap draw), one equal
# to it "within" (1.000); coverage 68 / 95 % on every table "inside", 50 / 80 % "outside", +-1 sd
# 0 % and 100 % on alternate tables (mean 50 %, bootstrap interval about 26-74 %) "undecided";
# a table with a failed fit is left out (named on stderr);
# the twin of the best peer is the best peer itself where the default's ratio is the same on every
# table, so the noise floor is 0. Bad arguments exit non-zero with a message.
# Usage (CTest): lab_median_rule_noise.sh <whirl> <scratch dir> <source dir>
set -uo pipefail
W="$1"; D="$2"; S="$3"
rm -rf "$D"; mkdir -p "$D"; cd "$D"
source "$S/tests/lab/lab_common.sh"
MR=("$PY" "$S/scripts/median_rule_noise.py")

"$PY" - <<'PY' || fail "could not write the planted runs"
import json
PEERS = {"loglinear": 1.0, "gp_ard": 2.0, "mlp_default": 3.0, "mlp_cv": 1.5, "brnn_whirl": 4.0}
def rec(prob, seed, factor, c1, c2):
    base = 1.0 + 0.1 * seed              # loglinear, the best peer on every table
    m = {p: {"rmse": [f * base, 10 * f * base]} for p, f in PEERS.items()}
    m["current"] = {"rmse": [factor * base, 10 * factor * base], "cover1": [c1, c1],
                    "cover2": [c2, c2]}
    return {"problem": prob, "rows": 20, "seed": seed, "methods": m}
runs = [rec("p", s, 1.05, 0.68, 0.95) for s in range(1, 13)]
runs += [rec("q", s, 1.0, 0.50, 0.80) for s in range(1, 13)]
runs += [rec("r", s, 1.0, float(s % 2), 0.95) for s in range(1, 13)]
failed = rec("p", 13, 1.05, 0.68, 0.95); failed["methods"]["current"]["rmse"] = [float("nan")] * 2
json.dump(runs[:20], open("a.json", "w")); json.dump(runs[20:] + [failed], open("b.json", "w"))
bad = runs[:1]; del bad[0]["methods"]["gp_ard"]
json.dump(bad, open("bad.json", "w"))
PY
"${MR[@]}" --verdicts --draws 500 --twins 20 a.json b.json > v.txt 2> err.txt \
  || fail "--verdicts on the planted runs: $(cat err.txt)"
grep -qF "left out p, 20 rows, seed 13: no finite RMSE of current" err.txt \
  || fail "a failed table is not named: $(cat err.txt)"
for k in 1 2; do
  grep -qF "| p | 20 | out$k | 12 | loglinear " v.txt && \
    grep -F "| p | 20 | out$k |" v.txt | grep -qF "| 1.050 | 1.050-1.050 | behind | 68.0 (68.0-68.0) | 95.0 (95.0-95.0) | inside |" \
    || fail "p out$k (5 % behind on every table): $(cat v.txt)"
  grep -F "| q | 20 | out$k |" v.txt | grep -qF "| 1.000 | 1.000-1.000 | within | 50.0 (50.0-50.0) | 80.0 (80.0-80.0) | outside |" \
    || fail "q out$k (equal to the best peer): $(cat v.txt)"
  grep -F "| r | 20 | out$k |" v.txt | grep -qF "| within | 50.0 (" && \
    grep -F "| r | 20 | out$k |" v.txt | grep -qF "| undecided |" || fail "r out$k: $(cat v.txt)"
done
grep -qx "median 20 rows: behind 2 (p out1, p out2); within 4; undecided 0" v.txt \
  || fail "median counts: $(cat v.txt)"
grep -qx "coverage 20 rows: inside 2; outside 2 (q out1, q out2); undecided 2 (r out1, r out2)" v.txt \
  || fail "coverage counts: $(cat v.txt)"
grep -qF "point rule on all N tables: 2 of 6 medians more than 1 % behind: p 20 out1 +5.0 %; p 20 out2 +5.0 %" \
  v.txt || fail "point rule: $(cat v.txt)"
grep -qF "(i) point rule 0.0 of 6 cells expected behind; (ii) verdict 'behind' 0.00 expected" v.txt \
  || fail "noise floor: $(cat v.txt)"
# an r interval at +-1 sd that reaches both below 60 % and above 60 % (undecided, not outside)
check_py "r's +-1 sd interval" '
import re
line = [l for l in open("v.txt") if l.startswith("| r | 20 | out1 |")][0]
lo, hi = map(float, re.search(r"\| 50\.0 \(([0-9.]+)-([0-9.]+)\) \|", line).groups())
assert 20 < lo < 60 < hi < 80, (lo, hi)
'
expect_usage_error "no such file" "${MR[@]}" --verdicts nosuch.json
expect_usage_error "no gp_ard" "${MR[@]}" --verdicts bad.json
expect_usage_error "--draws needs at least 20" "${MR[@]}" --verdicts --draws 5 a.json
echo "lab_median_rule_noise: passed ($PY)"
