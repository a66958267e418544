#!/usr/bin/env bash
# Smoke test of 'whirl design': a first design from ranges and from a candidate CSV (text, CSV,
# JSON; the picks are candidates and lie inside the ranges), the next screws from a trained model
# with the stop rule, and the errors for bad input (empty list, reversed range, a model whose
# columns do not match the candidates, a network model, a missing column).
# Usage (CTest): design_cli.sh <whirl> <scratch dir> <source dir>
set -uo pipefail
whirl="$1"; D="$2"; src="$3"
rm -rf "$D"; mkdir -p "$D"; cd "$D"
source "$src/tests/support/cli_common.sh"
data="$src/datasets/whirling_train.csv"
ranges=(--hardness-hrc-range 60..65 --diameter-mm-range 50..100 --pitch-mm-range 6..16
        --raceway-radius-mm-range 3..10 --cutting-speed-m-min-range 150..210)

# First design over the ranges: 10 screws, each within every range, with a reason.
"$whirl" design "${ranges[@]}" --count 10 --out first.csv > out.txt 2> err.txt \
  || fail "design from ranges: $(cat err.txt)"
grep -q "why:" out.txt || fail "no reason per screw: $(cat out.txt)"
[ "$(grep -vc '^#' first.csv)" -eq 11 ] || fail "first.csv does not hold 10 screws: $(cat first.csv)"
awk -F, '!/^#/ && NR > 1 && $1 != "rank" {
  if ($3 < 60 || $3 > 65 || $4 < 50 || $4 > 100 || $5 < 6 || $5 > 16 || $6 < 3 || $6 > 10 ||
      $7 < 150 || $7 > 210) bad = 1 } END { exit bad }' first.csv || fail "a screw outside the ranges"
"$whirl" design "${ranges[@]}" --count 10 --criterion i --json > first.json 2> err.txt \
  || fail "design --json: $(cat err.txt)"
python3 -c "import json,sys; d=json.load(open('first.json')); assert d['mode']=='first' and len(d['picks'])==10 and d['mean_sd_factor']>0" \
  || fail "first.json: $(cat first.json)"

# First design from a candidate list: the picks are rows of the list, named by their lines.
grep -v '^#' "$data" > cands.csv
"$whirl" design --candidates cands.csv --count 8 --json > cand.json 2> err.txt \
  || fail "design from candidates: $(cat err.txt)"
python3 - cands.csv cand.json <<'PY' || fail "a pick is not the candidate of its line"
import json, sys
lines = open(sys.argv[1]).read().splitlines()
head = lines[0].split(",")
d = json.load(open(sys.argv[2]))
seen = set()
for p in d["picks"]:
    n = int(p["source"].split()[1]); assert n not in seen; seen.add(n)
    row = dict(zip(head, map(float, lines[n - 1].split(","))))
    assert all(abs(row[k] - v) < 1e-9 for k, v in p["inputs"].items()), (p, row)
PY

# Next screws from a trained model: sd after <= sd now; the stop rule in three cases.
"$whirl" train --data "$data" --out m.json > /dev/null 2> err.txt || fail "train: $(cat err.txt)"
"$whirl" design --model m.json --candidates cands.csv --count 3 --tolerance-um 1000 \
  --tolerance-s 1000 --out next.csv > out.txt 2> err.txt || fail "next screws: $(cat err.txt)"
grep -q "stop rule: enough" out.txt || fail "huge tolerance is not 'enough': $(cat out.txt)"
[ "$(grep -vc '^#' next.csv)" -eq 4 ] || fail "next.csv does not hold 3 screws"
"$whirl" design --model m.json --candidates cands.csv --count 3 --tolerance-um 0.001 --json \
  > next.json 2> err.txt || fail "next --json: $(cat err.txt)"
python3 - next.json <<'PY' || fail "next.json: $(cat next.json)"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["mode"] == "next" and len(d["picks"]) == 3
for p in d["picks"]:
    assert p["max_elongation_sd_after_um"] <= p["max_elongation_sd_now_um"] + 1e-12
    assert p["settle_time_sd_after_s"] <= p["settle_time_sd_now_s"] + 1e-12
for k in ("max_elongation_um", "settle_time_s"):
    assert d["rms_sd_after"][k] <= d["rms_sd_now"][k] + 1e-12
assert d["stop"]["decision"] == "floor", d["stop"]
PY

# Space filling: the first design's last picks and a next batch's last pick say so; the next
# mode keeps them away from the --measured screws (the training table here).
"$whirl" design "${ranges[@]}" --count 8 --space-filling 2 --json > fill.json 2> err.txt \
  || fail "design --space-filling: $(cat err.txt)"
python3 - fill.json <<'PY2' || fail "fill.json: $(cat fill.json)"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["space_filling"] == 2 and d["min_distance"] > 0
assert [p["why"].startswith("space filling") for p in d["picks"]] == [False] * 6 + [True] * 2
PY2
"$whirl" design --model m.json --candidates cands.csv --count 2 --space-filling 1 \
  --measured "$data" > out.txt 2> err.txt || fail "next --space-filling: $(cat err.txt)"
grep -q "why: space filling" out.txt || fail "no space-filling pick: $(cat out.txt)"

# A table on which one candidate's held-out error diverges (score about 5e16: 8 screws of the
# "interacting" generator of scripts/bench_peers.py picked by a space-filling first design);
# 'whirl train' once refused to write its own model (the reader capped the error at 1e12).
cat > diverging.csv <<'CSV'
hardness_hrc,diameter_mm,pitch_mm,raceway_radius_mm,cutting_speed_m_min,max_elongation_um,settle_time_s
50.762477742280424,20.27267384430763,5.299392587692616,5.317813643073528,249.0046025194891,23.950378153773762,12.019006595636997
59.13457875206609,55.189232146018846,5.214686253513435,2.164271446872278,202.1488808251812,23.93438445183566,96.53466927644885
42.388248445995444,53.4333287071961,5.227074433669532,5.267341509700547,116.97442586967277,23.88215216318723,33.202572027351735
47.01507872773325,27.720727701534926,6.425275601729446,2.076261253180501,110.55471097449616,20.0071543838235,72.1238315345706
58.8614760712245,46.50141013936262,13.00520532993242,5.052311958984523,130.3281629080634,29.623856593589178,51.91513764821854
40.516918553369926,48.532146158975735,14.433769797439734,4.076705566326774,289.39621460534283,26.606376403732835,34.379201659697706
44.48381934991297,21.463099627060885,11.475570867320155,2.237988049604183,275.57357860637967,21.044517838873926,20.53174790942123
42.72766961115034,55.692046868241405,11.353671940415104,2.5196295573274234,106.44017749318631,20.495208861380203,37.03694626199615
CSV
"$whirl" train --data diverging.csv --out diverging.json --seed 1 --threads 1 > /dev/null \
  2> err.txt || fail "train on a table with a diverging candidate: $(cat err.txt)"

# Bad input: each error names what is wrong.
expect_fail "needs --measured" "$whirl" design --model m.json --candidates cands.csv --count 2 \
  --space-filling 1
expect_fail "--measured needs --model" "$whirl" design "${ranges[@]}" --count 8 --measured "$data"
expect_fail "count 8: the power law.*\[9, 243\]" "$whirl" design "${ranges[@]}" --count 8 \
  --space-filling 3
head -1 cands.csv > empty.csv
expect_fail "empty.csv: table has no data rows" "$whirl" design --candidates empty.csv --count 6
expect_fail "--pitch-mm-range 16..6: reversed range" "$whirl" design --hardness-hrc-range 60..65 \
  --diameter-mm-range 50..100 --pitch-mm-range 16..6 --raceway-radius-mm-range 3..10 \
  --cutting-speed-m-min-range 150..210 --count 8
expect_fail "missing: --cutting-speed-m-min-range" "$whirl" design --hardness-hrc-range 60..65 \
  --diameter-mm-range 50..100 --pitch-mm-range 6..16 --raceway-radius-mm-range 3..10 --count 8
expect_fail "count 3: the power law" "$whirl" design "${ranges[@]}" --count 3
cut -d, -f1-4 cands.csv > nospeed.csv
expect_fail "cutting_speed_m_min" "$whirl" design --candidates nospeed.csv --count 6
# A model trained with a constant hardness does not match candidates that vary it.
awk -F, 'BEGIN { OFS = "," } NR == 1 { print; next } { $1 = 62; print }' cands.csv > const.csv
"$whirl" train --data const.csv --out const.json > /dev/null 2> err.txt || fail "train const: $(cat err.txt)"
expect_fail "leaves out hardness_hrc (constant 62 in its training table .const.csv.), but line 2 has hardness_hrc" "$whirl" design --model const.json \
  --candidates cands.csv --count 2
expect_fail "is a network" "$whirl" design --model "$src/models/default.json" \
  --candidates cands.csv --count 2
expect_fail "need --model" "$whirl" design "${ranges[@]}" --count 8 --tolerance-um 1
expect_fail "tolerance-um" "$whirl" design --model m.json --candidates cands.csv --count 2 \
  --tolerance-um -1
expect_fail "must lie in \[1, 20\]" "$whirl" design --model m.json --candidates cands.csv --count 21
[ ! -e bad.csv ] || fail "a failed run left an output"
echo "design_cli: ok"
