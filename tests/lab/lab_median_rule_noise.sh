#!/usr/bin/env bash
# scripts/median_rule_noise.py --verdicts on planted runs with hand-checkable verdicts: a default 5 %
# behind the best peer on every table is "behind" (ratio 1.050 in every bootstrap draw), one equal
# to it "within" (1.000); coverage 68 / 95 % on every table "inside", 50 / 80 % "outside", +-1 sd
# 0 % and 100 % on alternate tables (mean 50 %, bootstrap interval about 26-74 %) "undecided";
# a table with a failed fit is left out (named on stderr);
# the twin of the best peer is the best peer itself where the default's ratio is the same on every
# table, so the noise floor is 0. --method / --against (docs/workpiece-choice-limits.md) on the same
# runs: a method "cvp" 10 % worse than the best peer on every table of p is "behind" there and
# 10 % better (q) or equal (r) "within"; a method "eq" equal to the best peer is "within"
# everywhere; a peer is judged against the best of the others (loglinear 1 / mlp_cv 1.5 within,
# brnn_whirl 4 / 1 behind); the default against cvp alone (p 1.05 / 1.10, q 1 / 0.9 behind);
# cvp's coverage only on the tables that have one (odd seeds, out1), "n/a" where none has; its
# choices counted. Bad arguments exit non-zero with a message.
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
    cvp = {"p": 1.10, "q": 0.90}.get(prob, 1.0)
    sd = seed % 2 == 1                   # cvp has an sd on odd seeds and out1 only
    m["cvp"] = {"rmse": [cvp * base, 10 * cvp * base], "cv_chosen": ["loglinear", "gp_ard"],
                "cover1": [0.68 if sd else float("nan"), float("nan")],
                "cover2": [0.95 if sd else float("nan"), float("nan")]}
    m["eq"] = {"rmse": [base, 10 * base]}
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
# --method cvp: p (13 tables: the default's failed fit does not concern cvp) behind, q and r within
"${MR[@]}" --verdicts --draws 500 --twins 20 --method cvp a.json b.json > cvp.txt 2> err.txt \
  || fail "--method cvp: $(cat err.txt)"
grep -qx "cvp judged against the best of loglinear, gp_ard, mlp_default, mlp_cv, brnn_whirl" cvp.txt \
  || fail "--method cvp: no header: $(cat cvp.txt)"
grep -qF "| p | 20 | out1 | 13 | loglinear 1.7 | 1.100 | 1.100-1.100 | behind | 68.0 (68.0-68.0) | 95.0 (95.0-95.0) | inside (7 of 13 with an sd) |" \
  cvp.txt || fail "--method cvp, p out1: $(cat cvp.txt)"
grep -qF "| q | 20 | out2 | 12 | loglinear 16.5 | 0.900 | 0.900-0.900 | within | - | - | n/a |" cvp.txt \
  || fail "--method cvp, q out2: $(cat cvp.txt)"
grep -qx "median 20 rows: behind 2 (p out1, p out2); within 4; undecided 0" cvp.txt \
  || fail "--method cvp, median counts: $(cat cvp.txt)"
grep -qx "coverage 20 rows: inside 3; outside 0; undecided 0; n/a 3 (p out2, q out2, r out2)" cvp.txt \
  || fail "--method cvp, coverage counts: $(cat cvp.txt)"
grep -qx "| p | 20 | out1 | 0 | 13 |" cvp.txt && grep -qx "| r | 20 | out2 | 12 | 0 |" cvp.txt \
  || fail "--method cvp, choices (gp_ard, loglinear): $(cat cvp.txt)"
"${MR[@]}" --verdicts --draws 500 --twins 20 --method eq a.json b.json > eq.txt 2> err.txt \
  || fail "--method eq: $(cat err.txt)"
grep -qx "median 20 rows: behind 0; within 6; undecided 0" eq.txt || fail "--method eq: $(cat eq.txt)"
grep -qF "| r | 20 | out1 | 12 | loglinear 1.65 | 1.000 | 1.000-1.000 | within |" eq.txt \
  || fail "--method eq, r out1: $(cat eq.txt)"
# a peer judged against the best of the others
"${MR[@]}" --verdicts --draws 500 --twins 20 --method loglinear a.json b.json > ll.txt 2> err.txt \
  || fail "--method loglinear: $(cat err.txt)"
grep -qF "| q | 20 | out1 | 12 | mlp_cv 2.475 | 0.667 | 0.667-0.667 | within | - | - | n/a |" ll.txt \
  && grep -qx "median 20 rows: behind 0; within 6; undecided 0" ll.txt || fail "--method loglinear: $(cat ll.txt)"
"${MR[@]}" --verdicts --draws 500 --twins 20 --method brnn_whirl a.json b.json > br.txt 2> err.txt \
  || fail "--method brnn_whirl: $(cat err.txt)"
grep -qF "| q | 20 | out1 | 12 | loglinear 1.65 | 4.000 | 4.000-4.000 | behind |" br.txt \
  && grep -qF "median 20 rows: behind 6 (" br.txt || fail "--method brnn_whirl: $(cat br.txt)"
# the default against cvp alone
"${MR[@]}" --verdicts --draws 500 --twins 20 --against cvp a.json b.json > ag.txt 2> err.txt \
  || fail "--against cvp: $(cat err.txt)"
grep -qx "current judged against cvp" ag.txt || fail "--against cvp: no header: $(cat ag.txt)"
grep -qF "| p | 20 | out1 | 12 | cvp 1.815 | 0.955 | 0.955-0.955 | within |" ag.txt \
  && grep -qF "| q | 20 | out1 | 12 | cvp 1.485 | 1.111 | 1.111-1.111 | behind |" ag.txt \
  && grep -qx "median 20 rows: behind 2 (q out1, q out2); within 4; undecided 0" ag.txt \
  || fail "--against cvp: $(cat ag.txt)"
expect_usage_error "is the judged method itself" "${MR[@]}" --verdicts --against current a.json
expect_usage_error "need --verdicts" "${MR[@]}" --method cvp a.json
expect_usage_error "no nosuch" "${MR[@]}" --verdicts --method nosuch a.json
expect_usage_error "no such file" "${MR[@]}" --verdicts nosuch.json
expect_usage_error "no gp_ard" "${MR[@]}" --verdicts bad.json
expect_usage_error "--draws needs at least 20" "${MR[@]}" --verdicts --draws 5 a.json
echo "lab_median_rule_noise: passed ($PY)"
