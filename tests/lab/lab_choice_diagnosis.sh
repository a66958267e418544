#!/usr/bin/env bash
# scripts/choice_diagnosis.py on a tiny bench_peers.py run (powerlaw and friedman, 20 rows, seeds
# 1-2; the family library's default and its six candidates alone through build/family_bench, as
# docs/workpiece-history.md's thirteenth attempt runs it, no scikit-learn peer): one row per cell
# whose family was run, the header's columns, the tables counted, the hindsight oracle never
# above a candidate, every output counted once; with planted peers (each the default's RMSE
# doubled) the default's median is -50.0 % of the best peer's; --cells keeps the cells named, on
# their rows; bad arguments exit non-zero with a message.
# Usage (CTest): lab_choice_diagnosis.sh <whirl> <scratch dir> <source dir> <family_bench>
set -uo pipefail
W="$1"; D="$2"; S="$3"; FB="$4"
rm -rf "$D"; mkdir -p "$D"; cd "$D"
source "$S/tests/lab/lab_common.sh"
CD=("$PY" "$S/scripts/choice_diagnosis.py")

"$PY" "$S/scripts/bench_peers.py" --whirl "$W" --problems powerlaw,friedman --first-seed 1 \
  --seeds 2 --sizes 20 --peers "" --no-default --no-threads2 --family-bench "$FB" --family default= \
  --family "linlog=--candidates linear/log --no-cv" --family "linid=--candidates linear/identity --no-cv" \
  --family "gplog=--candidates gp-matern52-linear/log --no-cv" \
  --family "gpm52=--candidates gp-matern52-constant/identity --no-cv" \
  --family "gpse=--candidates gp-se-constant/identity --no-cv" \
  --family "net=--candidates network-h2/identity --no-cv" --json run.json > run.txt 2> err.txt \
  || fail "bench_peers: $(cat err.txt)"
"${CD[@]}" run.json > diag.txt 2> err.txt || fail "choice_diagnosis: $(cat err.txt)"
check_py "diag.txt" '
import math
blocks, cur = [], []
for line in open("diag.txt").read().splitlines() + [""]:
    if line.strip():
        cur.append(line)
    elif cur:
        blocks.append(cur); cur = []
tables = [b for b in blocks if b[0].startswith("| ")]
cells, cover, choice, optimism = tables
cols = lambda l: [c.strip() for c in l.strip().strip("|").split("|")]
for t in tables:
    assert all(len(cols(l)) == len(cols(t[0])) for l in t), t
# 1. the RMSE cells of the two families run, 2 tables each, no peer
assert [cols(l)[0] for l in cells[2:]] == ["powerlaw out2", "friedman out1", "friedman out2"], cells
for l in cells[2:]:
    c = cols(l)
    assert c[1] == "- (0)" and c[2] == "-" and c[-1].endswith("(2)"), c
    ratios = [float(x.split("/")[1]) for x in c[3:9]]
    oracle = float(c[9].split("/")[1].split("(")[0])
    assert all(math.isfinite(g) and g > 0 for g in ratios) and oracle <= min(ratios), (ratios, oracle)
# 3. coverage: friedman out2, the default and six candidates, +-1 sd <= +-2 sd
assert [cols(l)[1] for l in cover[2:]] == ["default", "linlog", "linid", "gplog", "gpm52", "gpse",
                                           "net"], cover
for l in cover[2:]:
    c1, c2 = map(float, cols(l)[2].split("/"))
    assert cols(l)[0] == "friedman out2 (2)" and 0 <= c1 <= c2 <= 100, l
# 4. every output of every table counted once: 4 tables x 2 outputs
assert sum(int(cols(l)[1]) for l in choice[2:]) == 8, choice
# 5. each candidate against its held-out RMSE on all 8 outputs
assert all(cols(l)[2].endswith("(8)") for l in optimism[2:]) and len(optimism) == 8, optimism
# 2. the default choice per cell: each cell once
counts = [l for b in blocks for l in b if " tables): " in l]
assert len(counts) == len(set(counts)) == 3, counts
'
# Planted peers: every acceptance peer has the default's RMSE doubled on every table.
"$PY" - <<'PY' || fail "could not plant the peers"
import copy, json
runs = json.load(open("run.json"))
for r in runs:
    for p in ("loglinear", "gp_ard", "mlp_default", "mlp_cv", "brnn_whirl"):
        r["methods"][p] = {"rmse": [2 * v for v in r["methods"]["default"]["rmse"]]}
json.dump(runs, open("peers.json", "w"))
PY
"${CD[@]}" peers.json > peers.txt 2> err.txt || fail "choice_diagnosis with peers: $(cat err.txt)"
[ "$(grep -c '^| \(powerlaw\|friedman\) out[12] | [a-z_]* [0-9.e+-]* (2) | -50.0 % |' peers.txt)" = 3 ] \
  || fail "planted peers: the default is not -50.0 % of the best peer in 3 cells: $(cat peers.txt)"

# --cells: only the cells named, on their tables of those rows; a cell without tables (powerlaw
# at 100 rows: none were run) is left out, in the RMSE and the coverage sections alike.
"${CD[@]}" --cells friedman/20/out1,powerlaw/100/out2 run.json > cells.txt 2> err.txt \
  || fail "choice_diagnosis --cells: $(cat err.txt)"
check_py "cells.txt" '
lines = open("cells.txt").read().splitlines()
cols = lambda l: [c.strip() for c in l.strip().strip("|").split("|")]
rmse = [l for l in lines if l.startswith("| friedman") and cols(l)[0].endswith("out1")]
assert [cols(l)[0] for l in rmse] == ["friedman 20 rows out1"], lines
ratios = [float(x.split("/")[1]) for x in cols(rmse[0])[3:9]]
assert float(cols(rmse[0])[9].split("/")[1].split("(")[0]) <= min(ratios), rmse
assert cols(rmse[0])[9].endswith("(2)"), rmse
cover = [l for l in lines if l.startswith("| friedman 20 rows out1 (2) |")]
assert [cols(l)[1] for l in cover] == ["default", "linlog", "linid", "gplog", "gpm52", "gpse", "net"], lines
assert [l for l in lines if " tables): " in l] == [l for l in lines if l.startswith("friedman 20 rows out1 (2 tables): ")], lines
assert not any("powerlaw" in l and "rows out" in l for l in lines), lines
'

# Bad arguments.
expect_usage_error "Usage: scripts/choice_diagnosis.py" "${CD[@]}"
expect_usage_error "each cell must be FAMILY/ROWS/out1" "${CD[@]}" --cells friedman/20/out3 run.json
expect_usage_error "Usage: scripts/choice_diagnosis.py" "${CD[@]}" --cells friedman/20/out1
expect_usage_error "not a bench_peers.py --json file" "${CD[@]}" nosuch.json
echo "lab_choice_diagnosis: passed ($PY)"
