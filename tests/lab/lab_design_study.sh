#!/usr/bin/env bash
# scripts/design_study.py, and the scripts that read its --json run: design_diagnosis.py and
# design_oracle.py (both import it and bench_peers.py).
#  - the seed rule: adjacent seed ranges give disjoint seeds, replacements of seeds whose candidate
#    list holds a negative target included (additive's seed 2 is one), and every seed's list has
#    none;
#  - a tiny study (additive, seeds 1-2: seed 2 replaced) through build/whirl: the JSON's fields,
#    one case per problem and seed, every RMSE positive and finite, the design's picks distinct rows
#    of the list, the medians between the cases' values; --from-json prints the same tables;
#  - design_diagnosis.py on that run: per case its four tables, whose RMSE are the study's own at
#    12 and 20 screws (the same rows, the same training);
#  - design_oracle.py (one case, a small search): the oracle's 12 never worse than the study's
#    design 12 and random 12 it starts from, which are the study's figures again;
#  - bad arguments exit non-zero with a message.
# Usage (CTest): lab_design_study.sh <whirl> <scratch dir> <source dir>
set -uo pipefail
W="$1"; D="$2"; S="$3"
rm -rf "$D"; mkdir -p "$D"; cd "$D"
source "$S/tests/lab/lab_common.sh"
export PYTHONPATH="$PYTHONPATH:$S/scripts"

# The seed rule, against the generators themselves.
check_py "the seed rule" '
import bench_peers as bp, design_study as ds
replaced = 0
for prob, lo, n in (("additive", 1, 10), ("additive", 3001, 10), ("additive", 1, 3),
                    ("powerlaw", 1, 10)):
    first = ds.usable_seeds(prob, ds.seeds_of(f"{lo}-{lo + n - 1}"))
    second = ds.usable_seeds(prob, ds.seeds_of(f"{lo + n}-{lo + 2 * n - 1}"))
    assert not set(first) & set(second), (prob, lo, n, sorted(set(first) & set(second)))
    for seeds, start in ((first, lo), (second, lo + n)):
        assert len(set(seeds)) == n, (prob, seeds)
        for s, own in zip(seeds, range(start, start + n)):
            fine = (bp.generated(prob, ds.POOL_ROWS, own)[1] >= 0).all()
            assert s == own if fine else s != own, (prob, own, s)
            assert (bp.generated(prob, ds.POOL_ROWS, s)[1] >= 0).all(), (prob, s)
            replaced += s != own
assert replaced > 0, "no range of the test holds a seed to replace: the test cannot fail"
'

# The legacy rule (--seed-rule next-after-range), kept so that docs/design.md's published commands
# reproduce their figures: the range's usable seeds in order, then the first usable seeds after the
# range; additive 1-10 (seed 2 unusable) ends with 11, which the range 11-20 uses as well.
check_py "the legacy seed rule" '
import bench_peers as bp, design_study as ds
ok = lambda s: (bp.generated("additive", ds.POOL_ROWS, s)[1] >= 0).all()
assert not ok(2) and ok(11), "additive seed 2 usable or 11 not: the hand-made case moved"
legacy = ds.usable_seeds("additive", list(range(1, 11)), "next-after-range")
assert legacy == [1] + list(range(3, 12)), legacy
assert 11 in ds.usable_seeds("additive", list(range(11, 21)), "next-after-range")
assert ds.usable_seeds("powerlaw", list(range(1, 11)), "next-after-range") == \
    ds.usable_seeds("powerlaw", list(range(1, 11))), "the rules differ where nothing is replaced"
'

# A tiny study: one generator problem, seeds 1-2 (additive 2 is replaced), all four strategies.
"$PY" "$S/scripts/design_study.py" --whirl "$W" --problems additive --seeds 1-2 --jobs 1 \
  --sim-cache "$D/sim" --json study.json > study.txt 2> err.txt || fail "design_study: $(cat err.txt)"
grep -q "additive seed 2 replaced by" err.txt || fail "the replacement is not reported: $(cat err.txt)"
check_py "study.json" '
import json, math, numpy as np, design_study as ds
d = json.load(open("study.json"))
for key in ("criterion", "batch", "seeds", "cases", "medians", "design_picks", "command"):
    assert key in d, key
seeds = ds.usable_seeds("additive", [1, 2])
assert [(p, s) for p, s, _ in d["cases"]] == [("additive", s) for s in seeds], d["cases"]
for p, s, res in d["cases"]:
    assert set(res) == set(ds.STRATEGIES), res.keys()
    for strategy, by_n in res.items():
        assert sorted(map(int, by_n)) == ds.SIZES, (strategy, by_n.keys())
        assert all(len(v) == 2 and all(math.isfinite(x) and x > 0 for x in v)
                   for v in by_n.values()), (strategy, by_n)
    picks = d["design_picks"][f"{p}/{s}"]
    assert len(picks) == max(ds.SIZES) == len(set(picks)), picks
    assert all(0 <= i < ds.POOL_ROWS for i in picks), picks
med = d["medians"]["additive"]
for strategy in ds.STRATEGIES:
    for n in ds.SIZES:
        values = np.array([res[strategy][str(n)] for _, _, res in d["cases"]])
        assert np.allclose(med[strategy][str(n)], np.median(values, axis=0)), (strategy, n)
'
for out in max_elongation_um settle_time_s; do
  grep -qF "additive, $out: median test RMSE over seeds (N = 8, 12, 16, 20, 30)" study.txt \
    || fail "no table of $out: $(cat study.txt)"
done
awk '/^\| strategy \|/ { t++; cols = NF } /^\| (random|lhs|natural|design) \|/ { rows++; if (NF != cols) bad = 1 }
     END { exit !(t == 2 && rows == 8 && !bad) }' study.txt \
  || fail "not two tables of 4 strategies with the header's columns: $(cat study.txt)"
"$PY" "$S/scripts/design_study.py" --from-json study.json > again.txt 2> err.txt \
  || fail "--from-json: $(cat err.txt)"
diff <(grep '^|' study.txt) <(grep '^|' again.txt) > /dev/null \
  || fail "--from-json prints other tables than the run: $(diff <(grep '^|' study.txt) <(grep '^|' again.txt))"

# design_diagnosis.py: the study's tables again, trained as the study does.
"$PY" "$S/scripts/design_diagnosis.py" --whirl "$W" --sim-cache "$D/sim" study.json diag.json \
  > diag.txt 2> err.txt || fail "design_diagnosis: $(cat err.txt)"
check_py "diag.json" '
import json, math
study = {(p, s): r for p, s, r in json.load(open("study.json"))["cases"]}
diag = json.load(open("diag.json"))
assert sorted((p, s) for p, s, _ in diag) == sorted(study), diag
same = {"design12": ("design", "12"), "design20": ("design", "20"), "random12": ("random", "12"),
        "random20": ("random", "20")}
for p, s, tables in diag:
    assert set(tables) == set(same), tables.keys()
    for t, (strategy, n) in same.items():
        r = tables[t]
        for key in ("rmse", "rmse_inside", "rmse_edge", "rmse_power_law", "rmse_noise_free"):
            assert len(r[key]) == 2 and all(math.isfinite(v) and v > 0 for v in r[key]), (t, key, r)
        assert all(math.isclose(a, b, rel_tol=1e-9) for a, b in zip(r["rmse"], study[p, s][strategy][n])), \
            (p, s, t, r["rmse"], study[p, s][strategy][n])
        g = r["geometry"]
        assert 0 <= g["inside"] <= int(t[-2:]) and 0 <= g["share_edge"] <= 1 and g["min_distance"] > 0, g
'
grep -qF "additive, max_elongation_um: geometric mean test RMSE over 2 seeds" diag.txt \
  || fail "design_diagnosis summary: $(cat diag.txt)"

# design_oracle.py: one case (additive, max elongation, seed 1), a small search on the list's
# own targets (its score: the study's test RMSE of the output).
"$PY" "$S/scripts/design_oracle.py" --whirl "$W" --sim-cache "$D/sim" --seeds 1 --cases additive:0 \
  --greedy 1 --exchange 1 --draws 0 --jobs 1 --json oracle.json > oracle.txt 2> err.txt \
  || fail "design_oracle: $(cat err.txt)"
check_py "oracle.json" '
import json, math
study = {(p, s): r for p, s, r in json.load(open("study.json"))["cases"]}
cases = json.load(open("oracle.json"))["cases"]
assert [(p, k, s) for p, k, s, _ in cases] == [("additive", 0, 1)], cases
out = cases[0][3]
r = out["rmse"]
assert set(r) == {"design12", "random12", "random20", "oracle12"}, r
assert all(math.isfinite(v) and v > 0 for v in r.values()), r
assert r["oracle12"] <= min(r["design12"], r["random12"]), r
for t, (strategy, n) in {"design12": ("design", "12"), "random12": ("random", "12"),
                         "random20": ("random", "20")}.items():
    assert math.isclose(r[t], study["additive", 1][strategy][n][0], rel_tol=1e-9), (t, r[t])
assert len(out["rows"]["oracle12"]) == 12 == len(set(out["rows"]["oracle12"])), out["rows"]
'
"$PY" "$S/scripts/design_oracle.py" --from-json oracle.json > oracle_again.txt 2> err.txt \
  || fail "design_oracle --from-json: $(cat err.txt)"
grep -qF "additive, max_elongation_um (1 seeds): oracle12 / random20" oracle_again.txt \
  || fail "design_oracle --from-json: $(cat oracle_again.txt)"

# Bad arguments.
expect_usage_error "--seeds 'x'" "$PY" "$S/scripts/design_study.py" --whirl "$W" --seeds x
expect_usage_error "--seeds '0-3'" "$PY" "$S/scripts/design_study.py" --whirl "$W" --seeds 0-3
expect_usage_error "--seeds '5-4'" "$PY" "$S/scripts/design_oracle.py" --whirl "$W" --seeds 5-4
expect_usage_error "invalid choice" "$PY" "$S/scripts/design_study.py" --whirl "$W" --criterion q
expect_usage_error "diag.json: not a design_study.py --json run" \
  "$PY" "$S/scripts/design_diagnosis.py" --whirl "$W" diag.json again.json
expect_usage_error "nosuch.json: not a --json run" "$PY" "$S/scripts/design_oracle.py" --from-json nosuch.json
echo "lab_design_study: passed ($PY)"
