#!/usr/bin/env bash
# scripts/bench_peers.py: the paired decision (--from-json --paired, --rule fifth|sixth) on planted
# runs with hand-computed figures; a tiny run through build/whirl and build/family_bench (2 problems
# x 1 size x 2 seeds, no scikit-learn peer): its JSON's records, fields and counts, and two
# identical whirl settings paired give every d = 0 and "no change"; a planted table with a
# non-positive target is replaced by seed + k x 1,000,000 and counted; bad arguments exit non-zero
# with a message; cv_peers' choice on planted cross-validation errors.
# Usage (CTest): lab_bench_peers.sh <whirl> <scratch dir> <source dir> <family_bench>
set -uo pipefail
W="$1"; D="$2"; S="$3"; FB="$4"
rm -rf "$D"; mkdir -p "$D"; cd "$D"
source "$S/tests/lab/lab_common.sh"
BP=("$PY" "$S/scripts/bench_peers.py" --whirl "$W")

# Planted runs. rec <problem> <seed> <rmse a> <rmse b> [<cover1 a>]: methods a and b on one
# table, coverage inside the bands (+-1 sd 68 %, +-2 sd 95 %) unless <cover1 a> is given.
"$PY" - <<'PY' || fail "could not write the planted runs"
import json
def rec(prob, seed, ra, rb, cover1_a=0.68):
    m = lambda r, c1: {"rmse": r, "cover1": [c1, c1], "cover2": [0.95, 0.95], "sd_rms": [1.0, 1.0]}
    return {"problem": prob, "rows": 20, "seed": seed,
            "methods": {"a": m(ra, cover1_a), "b": m(rb, 0.68)}}
# d = ln(b / a) per (table, output): ln 0.5, ln 0.25, ln 0.5, 0, i.e. -L, -2L, -L, 0 (L = ln 2):
# mean -L = -0.6931 (geometric mean ratio 0.5), sd L sqrt(2/3), t = -L / (sd / 2) = -sqrt(6)
# = -2.45; median of d -L (ratio 0.5000); 3 cases lower, 0 higher, one d = 0.
better = [rec("p", 1, [1.0, 1.0], [0.5, 0.25]), rec("p", 2, [1.0, 1.0], [0.5, 1.0])]
json.dump(better, open("better.json", "w"))
# plus problem q where b is 5 % worse on every case: q's median ratio 1.05 > 1.03, its geometric
# mean 1.05 > 1.02 (both rules keep a)
json.dump(better + [rec("q", 1, [2.0, 4.0], [2.1, 4.2]), rec("q", 2, [1.0, 3.0], [1.05, 3.15])],
          open("worse_q.json", "w"))
# b has a's RMSE everywhere and only its sd changed: a's +-1 sd coverage 50 % (outside the band)
# on both outputs of p, b's 68 %: the sixth rule's "sd only" path adopts b (2 cells -> 0), the
# fifth rule keeps a (mean d = 0 is not < 0)
json.dump([rec("p", 1, [1.0, 2.0], [1.0, 2.0], 0.5), rec("p", 2, [3.0, 4.0], [3.0, 4.0], 0.5)],
          open("sd_only.json", "w"))
PY
for rule in fifth sixth; do
  "${BP[@]}" --from-json better.json --paired a b --rule $rule > better_$rule.txt 2> err.txt \
    || fail "--paired on better.json ($rule): $(cat err.txt)"
  grep -qF "4 cases (problem, rows, seed, output) of 2 tables; 1 cases with identical RMSE (d = 0)" \
    better_$rule.txt || fail "better.json ($rule): counts: $(cat better_$rule.txt)"
  grep -qF "mean d -0.6931 (geometric mean ratio 0.5000), paired t -2.45" better_$rule.txt \
    || fail "better.json ($rule): not the hand-computed mean d and t: $(cat better_$rule.txt)"
  grep -qF "| p | 4 | 1 | 0.5000 | -0.6931 | -2.45 | 3 / 0 |" better_$rule.txt \
    || fail "better.json ($rule): not the hand-computed row of p: $(cat better_$rule.txt)"
  grep -qx "decision: ADOPT b" better_$rule.txt || fail "better.json ($rule): $(cat better_$rule.txt)"
  "${BP[@]}" --from-json worse_q.json --paired a b --rule $rule > worse_$rule.txt 2> err.txt \
    || fail "--paired on worse_q.json ($rule): $(cat err.txt)"
  grep -qx "decision: keep a" worse_$rule.txt || fail "worse_q.json ($rule): $(cat worse_$rule.txt)"
done
grep -qF "| q | 4 | 0 | 1.0500 | +0.0488 |" worse_fifth.txt || fail "q's row: $(cat worse_fifth.txt)"
grep -qF "FAILS: largest problem median ratio 1.0500 <= 1.03" worse_fifth.txt \
  || fail "fifth rule, q: $(cat worse_fifth.txt)"
grep -qF "FAILS: largest problem geometric mean ratio 1.0500 <= 1.02" worse_sixth.txt \
  || fail "sixth rule, q: $(cat worse_sixth.txt)"
"${BP[@]}" --from-json sd_only.json --paired a b --rule sixth > sd6.txt 2> err.txt || fail "$(cat err.txt)"
grep -qF "holds: sd only: every case d = 0" sd6.txt && grep -qF "holds: coverage cells 0 < 2" sd6.txt \
  && grep -qx "decision: ADOPT b" sd6.txt || fail "sixth rule, sd only: $(cat sd6.txt)"
"${BP[@]}" --from-json sd_only.json --paired a b --rule fifth > sd5.txt 2> err.txt || fail "$(cat err.txt)"
grep -qx "decision: keep a" sd5.txt || fail "fifth rule, sd only: $(cat sd5.txt)"

# A tiny run: 2 problems x 20 rows x seeds 1-2; whirl's default, the same settings again ("twin")
# and the family library's default choice through family_bench ("fam"); no peer.
"${BP[@]}" --problems powerlaw,friedman --sizes 20 --seeds 2 --first-seed 1 --peers "" \
  --variant twin= --family-bench "$FB" --family fam= --json run.json > run.txt 2> err.txt \
  || fail "the tiny run: $(cat err.txt)"
check_py "run.json" '
import json, math, sys
runs = json.load(open("run.json"))
keys = sorted((r["problem"], r["rows"], r["seed"]) for r in runs)
assert keys == [(p, 20, s) for p in ("friedman", "powerlaw") for s in (1, 2)], keys
for r in runs:
    assert set(r["methods"]) == {"whirl", "twin", "fam"}, r["methods"].keys()
    for name, m in r["methods"].items():
        assert "failed" not in m, (name, m)
        for key in ("rmse", "sd_rms", "resid_rms", "cover1", "cover2", "cover1_truth", "cover2_truth"):
            assert len(m[key]) == 2 and all(math.isfinite(v) for v in m[key]), (name, key, m[key])
        assert all(v > 0 for v in m["rmse"] + m["sd_rms"]), (name, m)
        assert all(0 <= v <= 1 for k in ("cover1", "cover2") for v in m[k]), (name, m)
        assert all(c1 <= c2 for c1, c2 in zip(m["cover1"], m["cover2"])), (name, m)
        assert isinstance(m["chosen"], str) and m["chosen"] and m["time_ms"] >= 0, (name, m)
    assert "time2_ms" in r["methods"]["whirl"]  # the --threads 2 rerun predicted identically
'
for p in powerlaw friedman; do
  grep -qF "$p, 20 training rows, 2 seeds (1-2;" run.txt || fail "no report of $p: $(cat run.txt)"
done
"${BP[@]}" --from-json run.json --paired whirl twin > twin.txt 2> err.txt || fail "$(cat err.txt)"
grep -qF "8 cases (problem, rows, seed, output) of 4 tables; 8 cases with identical RMSE (d = 0)" \
  twin.txt && grep -qF "mean d +0.0000" twin.txt \
  && grep -qx "decision: no change (twin has whirl's RMSE, sd and coverage on every table; keep whirl)" \
  twin.txt || fail "two identical settings paired: $(cat twin.txt)"

# A planted table with a non-positive target (which whirl train, brnn_whirl and loglinear refuse):
# powerlaw 20 rows seed 2 gets a negative settle time, its first replacement 1000002 a zero
# elongation, so seed 2 is run as 2000002 (s + 2 x 1,000,000), said on stderr, counted in the
# report and kept as "replaces" in the JSON; seed 1 is run as drawn. replacement_seed by hand:
# the first of 1, 1000001, 2000001 divisible by 3 is 2000001.
"$PY" - "$S/scripts" "$W" > planted.txt 2> planted_err.txt <<'PY' || fail "planted run: $(cat planted_err.txt)"
import sys
sys.path.insert(0, sys.argv[1])
import bench_peers as bp
assert bp.replacement_seed(lambda s: s % 3 == 0, 1) == 2000001
drawn = bp.problem_data
def planted(prob, n, seed, *rest):
    xtr, ytr, xte, fte, yte = drawn(prob, n, seed, *rest)
    ytr = ytr.copy()
    if seed == 2:
        ytr[5, 1] = -1.0
    if seed == 1000002:
        ytr[0, 0] = 0.0
    return xtr, ytr, xte, fte, yte
bp.problem_data = planted
sys.argv = ["bench_peers.py", "--whirl", sys.argv[2], "--problems", "powerlaw", "--sizes", "20",
            "--seeds", "2", "--first-seed", "1", "--peers", "", "--no-threads2", "--json",
            "planted.json"]
bp.main()
PY
check_py "planted.json" '
import json
runs = json.load(open("planted.json"))
assert [(r["seed"], r.get("replaces")) for r in runs] == [(1, None), (2000002, 2)], runs
assert all("failed" not in m for r in runs for m in r["methods"].values()), runs
'
grep -qF "bench_peers: powerlaw 20 rows seed 2 replaced by 2000002 (a training target <= 0)" \
  planted_err.txt || fail "no replacement message: $(cat planted_err.txt)"
grep -qF "powerlaw, 20 training rows, 2 seeds (1-2;" planted.txt \
  && grep -qF "1 of 2 seeds replaced (a training target <= 0): 2 by 2000002" planted.txt \
  || fail "the report does not count the replacement: $(cat planted.txt)"

# Bad arguments: a non-zero exit and a message.
# cv_peers' choice (docs/workpiece-choice-limits.md) on planted CV errors: per output the candidate
# with the lowest CV MSE, its own record (RMSE, coverage; NaN where it has no sd), ties in the
# order loglinear, gp_ard, mlp_default, brnn_whirl; a failed candidate (inf) is never chosen
check_py "cv_peers' choice" '
import math, sys
sys.path.insert(0, sys.argv[1])
from bench_peers import cv_peers
sd = lambda c: {"cover1": [c, c], "cover2": [0.9, 0.9], "sd_rms": [1.0, 1.0], "resid_rms": [1.0, 1.0],
                "cover1_truth": [c, c], "cover2_truth": [c, c]}
fitted = {"loglinear": {"rmse": [1.0, 10.0], "time_ms": 1.0},
          "gp_ard": {"rmse": [2.0, 20.0], "time_ms": 2.0, **sd(0.6)},
          "mlp_default": {"rmse": [3.0, 30.0], "time_ms": 3.0},
          "brnn_whirl": {"rmse": [4.0, 40.0], "time_ms": 4.0, **sd(0.7)}}
cv = {"loglinear": [0.5, 9.0], "gp_ard": [0.7, 3.0], "mlp_default": [0.9, 3.0], "brnn_whirl": [math.inf, 5.0]}
r = cv_peers(fitted, cv, 5.0)
assert r["cv_chosen"] == ["loglinear", "gp_ard"], r
assert r["rmse"] == [1.0, 20.0] and r["time_ms"] == 15.0, r
assert math.isnan(r["cover1"][0]) and r["cover1"][1] == 0.6 and r["cover2"][1] == 0.9, r
cv["loglinear"] = [math.inf, math.inf]
assert cv_peers(fitted, cv, 5.0)["cv_chosen"] == ["gp_ard", "gp_ard"]
' "$S/scripts"
expect_usage_error "needs --from-json" "${BP[@]}" --paired a b
expect_usage_error "invalid choice" "${BP[@]}" --from-json better.json --paired a b --rule seventh
expect_usage_error "method 'nosuch' missing in p, 20 rows, seed 1" \
  "${BP[@]}" --from-json better.json --paired a nosuch
expect_usage_error "need scikit-learn" "${BP[@]}" --problems powerlaw --seeds 1 --peers gp_ard
expect_usage_error "--family needs --family-bench" "${BP[@]}" --problems powerlaw --family x=
expect_usage_error "no acceptance peer" "${BP[@]}" --from-json run.json
echo "lab_bench_peers: passed ($PY)"
