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
  --tolerance-s 1000 --measured "$data" --out next.csv > out.txt 2> err.txt || fail "next screws: $(cat err.txt)"
grep -q "stop rule: enough" out.txt || fail "huge tolerance is not 'enough': $(cat out.txt)"
[ "$(grep -vc '^#' next.csv)" -eq 4 ] || fail "next.csv does not hold 3 screws"
"$whirl" design --model m.json --candidates cands.csv --count 3 --tolerance-um 0.001 --json \
  --measured "$data" > next.json 2> err.txt || fail "next --json: $(cat err.txt)"
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
assert d["variance"] == "switch" and "lack_of_fit_ratio" in d, d  # the default
assert all("leave-one-out error ratio" in p["why"] for p in d["picks"])
PY
# A --measured table that is not the model's training table gets a note.
head -9 cands.csv > nine.csv
"$whirl" design --model m.json --candidates cands.csv --count 2 --measured nine.csv > out.txt \
  2> err.txt || fail "next with 8 measured: $(cat err.txt)"
grep -q "note: --measured nine.csv holds 8 screws, the model was trained on 20 rows" out.txt \
  || fail "no note on a --measured table unlike the training table: $(cat out.txt)"
"$whirl" design --model m.json --candidates cands.csv --count 2 --measured "$data" > out.txt \
  2> err.txt || fail "next: $(cat err.txt)"
grep -q "note: --measured" out.txt && fail "a note on the training table itself: $(cat out.txt)"
# The chosen family's own variance needs no measured screws.
"$whirl" design --model m.json --candidates cands.csv --count 2 --variance chosen > out.txt \
  2> err.txt || fail "next --variance chosen: $(cat err.txt)"
grep -q "both outputs weighed equally" out.txt || fail "--variance chosen: $(cat out.txt)"
"$whirl" design --model m.json --candidates cands.csv --count 2 --variance sum --measured "$data" \
  --departure-ratio 4 --length-scale 1.5 > out.txt 2> err.txt || fail "next --variance sum: $(cat err.txt)"
# --variance auto: per output the chosen GP's variance or, where a linear fit is chosen, power-gp.
"$whirl" train --data "$data" --out m_gp.json --family gp --transform log > /dev/null 2> err.txt \
  || fail "train --family gp: $(cat err.txt)"
"$whirl" design --model m_gp.json --candidates cands.csv --count 2 --variance auto \
  --measured "$data" > out.txt 2> err.txt || fail "next --variance auto: $(cat err.txt)"
grep -q "both outputs weighed equally" out.txt || fail "--variance auto on GPs: $(cat out.txt)"
"$whirl" train --data "$data" --out m_lin.json --family linear --transform log > /dev/null \
  2> err.txt || fail "train --family linear: $(cat err.txt)"
"$whirl" design --model m_lin.json --candidates cands.csv --count 2 --variance auto \
  --measured "$data" > out.txt 2> err.txt || fail "next --variance auto: $(cat err.txt)"
grep -q "smooth departure" out.txt || fail "--variance auto on power laws: $(cat out.txt)"
# --variance switch: per output the chosen family's variance while the power law fits the
# --measured screws' targets, power-gp once they depart from it; --switch-ratio decides.
"$whirl" design --model m.json --candidates cands.csv --count 2 --variance switch \
  --measured "$data" --json > switch.json 2> err.txt || fail "next --variance switch: $(cat err.txt)"
python3 - switch.json <<'PY' || fail "--variance switch JSON: $(cat switch.json)"
import json, sys
d = json.load(open(sys.argv[1]))
r = d["lack_of_fit_ratio"]
assert d["variance"] == "switch" and len(d["picks"]) == 2
assert all(v > 0 for v in r.values()), r
PY
for limit in 1e-6 1e6; do
  "$whirl" design --model m.json --candidates cands.csv --count 1 --variance switch \
    --measured "$data" --switch-ratio $limit > "switch_$limit.txt" 2> err.txt \
    || fail "next --variance switch --switch-ratio $limit: $(cat err.txt)"
done
[ "$(grep -o 'depart from the power law' switch_1e-6.txt | wc -l)" -eq 2 ] \
  || fail "--switch-ratio 1e-6: both outputs should depart: $(cat switch_1e-6.txt)"
[ "$(grep -o 'the power law fits' switch_1e6.txt | wc -l)" -eq 2 ] \
  || fail "--switch-ratio 1e6: both outputs should fit: $(cat switch_1e6.txt)"
# --departure-evidence choice: also a departure where the model's choice left the power law
# (linear on raw columns here, m_raw.json); the JSON says which outputs depart.
"$whirl" train --data "$data" --out m_raw.json --family linear --transform identity > /dev/null \
  2> err.txt || fail "train --family linear --transform identity: $(cat err.txt)"
for evidence in lack-of-fit choice; do
  "$whirl" design --model m_raw.json --candidates cands.csv --count 1 --measured "$data" \
    --switch-ratio 1e6 --departure-evidence $evidence --json > "evidence_$evidence.json" \
    2> err.txt || fail "next --departure-evidence $evidence: $(cat err.txt)"
done
python3 - evidence_lack-of-fit.json evidence_choice.json <<'PY' || fail "--departure-evidence JSON"
import json, sys
lack, choice = (json.load(open(f)) for f in sys.argv[1:])
assert lack["departure_evidence"] == "lack-of-fit" and choice["departure_evidence"] == "choice"
assert not any(lack["departure"].values()), lack["departure"]
assert all(choice["departure"].values()), choice["departure"]
assert "choice left the power law" in choice["picks"][0]["why"], choice["picks"][0]["why"]
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
# --inside: the first design's last picks by the power-GP variance, after the optimal ones.
"$whirl" design "${ranges[@]}" --count 8 --inside 2 --json > inside.json 2> err.txt \
  || fail "design --inside: $(cat err.txt)"
python3 - inside.json <<'PY3' || fail "inside.json: $(cat inside.json)"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["inside"] == 2 and len({p["source"] for p in d["picks"]}) == 8
assert [p["why"].startswith("inside the range") for p in d["picks"]] == [False] * 6 + [True] * 2
PY3
# --criterion bayes-d: no inside picks by default, picks beyond the coefficients say why, and the
# prior's figures in the JSON.
"$whirl" design "${ranges[@]}" --count 10 --criterion bayes-d --potential-terms \
  squares+interactions --tau 1 --json > bayes.json 2> err.txt || fail "bayes-d: $(cat err.txt)"
python3 - bayes.json <<'PY4' || fail "bayes.json: $(cat bayes.json)"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["criterion"] == "bayes-d" and d["inside"] == 0 and d["potential_columns"] == 15
assert len({p["source"] for p in d["picks"]}) == 10 and d["bayes_log_det"] > 0
assert [p["why"].startswith("Bayesian D-optimal") for p in d["picks"]] == [False] * 6 + [True] * 4
PY4
"$whirl" design "${ranges[@]}" --count 8 --criterion bayes-d > out.txt 2> err.txt \
  || fail "bayes-d text: $(cat err.txt)"
grep -q "Bayesian D-optimal, potential terms squares, tau 1" out.txt || fail "bayes-d: $(cat out.txt)"
"$whirl" design --model m.json --candidates cands.csv --count 2 --space-filling 1 \
  --measured "$data" > out.txt 2> err.txt || fail "next --space-filling: $(cat err.txt)"
grep -q "why: space filling" out.txt || fail "no space-filling pick: $(cat out.txt)"
# Coverage picks in both modes; --space-filling-when departure follows the switch's verdict.
"$whirl" design --model m.json --candidates cands.csv --count 2 --space-filling 1 \
  --space-filling-rule coverage --measured "$data" --json > cover.json 2> err.txt \
  || fail "next --space-filling-rule coverage: $(cat err.txt)"
"$whirl" design "${ranges[@]}" --count 8 --space-filling 2 --space-filling-rule coverage \
  --json > cover_first.json 2> err.txt || fail "first --space-filling-rule coverage: $(cat err.txt)"
for limit in 1e-6 1e6; do
  "$whirl" design --model m.json --candidates cands.csv --count 2 --space-filling 1 \
    --space-filling-rule coverage --space-filling-when departure --switch-ratio $limit \
    --measured "$data" --json > "when_$limit.json" 2> err.txt \
    || fail "next --space-filling-when departure --switch-ratio $limit: $(cat err.txt)"
done
"$whirl" design --model m.json --candidates cands.csv --count 2 --space-filling 1 \
  --space-filling-when departure --switch-ratio 1e6 --measured "$data" > when_text.txt 2> err.txt \
  || fail "next --space-filling-when departure (text): $(cat err.txt)"
grep -q "no departure from the power law.*the 1 space-filling pick(s) were made by variance" \
  when_text.txt || fail "departure dropping the fill picks is not said: $(cat when_text.txt)"
python3 - cover.json cover_first.json when_1e-6.json when_1e6.json <<'PY3' || fail "coverage: $(cat cover.json when_1e6.json)"
import json, sys
nxt, first, departs, fits = (json.load(open(f)) for f in sys.argv[1:])
assert nxt["space_filling"] == 1 and nxt["space_filling_rule"] == "coverage"
assert nxt["picks"][1]["why"].startswith("coverage") and not nxt["picks"][0]["why"].startswith("coverage")
assert [p["why"].startswith("coverage") for p in first["picks"]] == [False] * 6 + [True] * 2
assert departs["space_filling"] == 1 and departs["picks"][1]["why"].startswith("coverage")
assert fits["space_filling"] == 0 and not any(p["why"].startswith("coverage") for p in fits["picks"])
PY3

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

# A table on which a linear-mean GP's signal sd went to 0 (ln s_f = -30.09, screws of a generator
# family picked by a design); 'whirl train' refused to write its own model (the reader's rule
# for theta is [-30, 30]; the fit now keeps every theta inside it).
cat > flat_signal.csv <<'CSV'
hardness_hrc,diameter_mm,pitch_mm,raceway_radius_mm,cutting_speed_m_min,max_elongation_um,settle_time_s
44.820223841618,21.84380203351935,5.172132662632464,2.052772439709822,104.55123350776283,2.6748269998136633,10.336663826122512
40.930823829510516,21.01376327687321,14.85707049994499,5.5499166188922935,126.27307252588102,12.963641830805269,75.99454398077675
47.46308272435349,26.161212249615314,14.789244988442526,2.06858796590763,282.52666046937895,3.7463451102561636,35.6830133284755
56.10378197807478,27.767904672299014,5.084950098436273,4.508092787897646,292.92456433336787,18.591620807025702,29.896266964870627
40.221474276958354,49.49546051470753,5.920599076994457,4.43018528122208,241.69919330103394,21.000284972924227,27.9741677828575
51.788707889314836,58.826746980760625,12.594185113045413,4.0467436799173235,105.85355343089032,5.41686901685158,38.856670547791744
57.64385979446725,44.99487639488713,10.147922089131384,4.050245345042011,239.06373940830588,10.193030319514289,52.33212674169291
42.19406069890861,52.567499791119054,9.425238442921966,2.1625029373321203,228.92607437476008,4.440807403338631,23.208556378050446
43.96551035546757,44.48250427068454,14.061816705560616,5.869728090286157,258.85567660312654,25.08851460093017,69.29391687122703
57.10352919809678,26.687692304944516,12.688696844273377,5.580845474166322,212.64671185219257,14.629417215106939,95.83152783284017
59.07607877554808,52.07420760994302,8.69454265195266,5.350904458612353,134.76380920848246,10.540419595840419,51.300819189744026
58.63941288759287,41.27477263757803,11.701566181632895,2.2094649039469223,290.93071645962294,3.6010039707730734,29.796945512012396
49.0380393556034,50.49389510717869,5.241160760949918,5.658484329753448,245.82507365102933,27.664475132359332,28.50054720876982
43.07325560589677,27.053939644188688,7.37970397781673,5.885505419013839,276.0567544962387,33.448698568645796,68.76682297012105
41.74681397130884,58.98055974030417,12.50461442355445,5.498877322297539,128.89867695304054,13.203243592553903,54.117379963187354
47.22827894172951,51.11230160511491,6.513617608762444,4.7570495379169575,188.62070010423594,16.682341147344626,31.55810568224105
43.27598024273469,51.71246059138447,10.682177677665669,5.395060024324094,276.563441224245,24.518288157142834,79.89646249432255
43.266596778029566,21.561767402285724,13.009465804279092,4.686190214593528,197.2765845097672,13.155381592397069,76.38351607098632
54.82307258613912,22.36626665603989,14.475391598486503,4.722617046683018,188.25558147806498,9.569374487501046,65.25720351774542
40.544378394328895,49.32363239224266,9.42861182149095,5.461647038294258,242.18065310550733,24.174963559085636,59.413027890293684
50.77834320663391,24.013561307654754,5.056918271163406,5.184365424100732,239.00641257475635,23.605279419379045,35.83869022403813
58.508824375948045,44.79972372696825,14.369900457302233,5.162705088874805,264.57775032058953,14.525971934031121,72.21309185383055
55.63109638656643,22.54818712368507,11.79708549694469,5.631915222031477,123.86392693018213,10.28642889681809,68.75733969191671
58.05177013441271,38.88876050582453,7.463524001089793,4.5744718038810355,101.53792660223131,6.712550063904874,36.89753366609553
53.927023364568136,54.58814848219507,13.548127553537604,5.399249139267029,171.0865508745476,12.428742925121796,56.43508910571521
40.14802170094009,53.92258715736244,7.848201168378276,2.46568898971532,233.56797757935098,6.444386007415326,21.34966645133891
CSV
"$whirl" train --data flat_signal.csv --out flat_signal.json --seed 1 --threads 1 > /dev/null \
  2> err.txt || fail "train on a table whose GP signal sd goes to 0: $(cat err.txt)"

# Bad input: each error names what is wrong.
expect_fail "needs --measured" "$whirl" design --model m.json --candidates cands.csv --count 2 \
  --space-filling 1
expect_fail "--measured needs --model" "$whirl" design "${ranges[@]}" --count 8 --measured "$data"
expect_fail "switch needs --measured" "$whirl" design --model m.json --candidates cands.csv \
  --count 2
expect_fail "power-gp needs --measured" "$whirl" design --model m.json --candidates cands.csv \
  --count 2 --variance power-gp
expect_fail "auto needs --measured" "$whirl" design --model m.json --candidates cands.csv \
  --count 2 --variance auto
cut -d, -f1-5 cands.csv > inputs_only.csv
expect_fail "switch needs the measured screws' targets" "$whirl" design --model m.json \
  --candidates cands.csv --count 2 --variance switch --measured inputs_only.csv
expect_fail "switch-ratio" "$whirl" design --model m.json --candidates cands.csv --count 2 \
  --variance switch --measured "$data" --switch-ratio 0
expect_fail "--variance 'gp': expected 'power-gp'" "$whirl" design --model m.json \
  --candidates cands.csv --count 2 --variance gp --measured "$data"
expect_fail "departure-ratio" "$whirl" design --model m.json --candidates cands.csv --count 2 \
  --measured "$data" --departure-ratio 0
expect_fail "--space-filling-rule 'far': expected 'maximin'" "$whirl" design "${ranges[@]}" \
  --count 8 --space-filling 1 --space-filling-rule far
expect_fail "--space-filling-when needs --model" "$whirl" design "${ranges[@]}" --count 8 \
  --space-filling 1 --space-filling-when departure
expect_fail "--space-filling-when departure needs --variance switch" "$whirl" design \
  --model m.json --candidates cands.csv --count 2 --space-filling 1 --variance power-gp \
  --space-filling-when departure --measured "$data"
expect_fail "--variance needs --model" "$whirl" design "${ranges[@]}" --count 8 --variance sum
expect_fail "--departure-evidence needs --model" "$whirl" design "${ranges[@]}" --count 8 \
  --departure-evidence choice
expect_fail "--departure-evidence 'fit': expected 'lack-of-fit'" "$whirl" design --model m.json \
  --candidates cands.csv --count 2 --measured "$data" --departure-evidence fit
expect_fail "--departure-evidence choice needs --variance switch" "$whirl" design --model m.json \
  --candidates cands.csv --count 2 --measured "$data" --variance power-gp --departure-evidence choice
expect_fail "--potential-terms and --tau need --criterion bayes-d" "$whirl" design "${ranges[@]}" \
  --count 8 --tau 2
expect_fail "--criterion bayes-d is a first design" "$whirl" design --model m.json \
  --candidates cands.csv --count 2 --measured "$data" --criterion bayes-d
expect_fail "--potential-terms 'cubes': expected" "$whirl" design "${ranges[@]}" --count 8 \
  --criterion bayes-d --potential-terms cubes
expect_fail "--inside is a first design" "$whirl" design --model m.json --candidates cands.csv \
  --count 2 --measured "$data" --inside 1
expect_fail "count 8: the power law.*plus --inside 3" "$whirl" design "${ranges[@]}" --count 8 \
  --inside 3
head -6 cands.csv > five.csv
expect_fail "at least 6 measured screws" "$whirl" design --model m.json --candidates cands.csv \
  --count 2 --measured five.csv
expect_fail "count 8: the power law.*\[9, 243\]" "$whirl" design "${ranges[@]}" --count 8 \
  --space-filling 3
# Fewer candidates than the design needs: says so (it said "the count must lie in [8, 3]").
head -4 cands.csv > three.csv
expect_fail "the 3 candidates are too few: .* needs 8 different candidates" "$whirl" design \
  --candidates three.csv --count 8
grep -q "\[8, 3\]" err.txt && fail "an empty range in the message: $(cat err.txt)"
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
  --candidates cands.csv --count 2 --measured "$data"
expect_fail "is a network" "$whirl" design --model "$src/models/default.json" \
  --candidates cands.csv --count 2 --measured "$data"
expect_fail "need --model" "$whirl" design "${ranges[@]}" --count 8 --tolerance-um 1
expect_fail "tolerance-um" "$whirl" design --model m.json --candidates cands.csv --count 2 \
  --tolerance-um -1
expect_fail "must lie in \[1, 20\]" "$whirl" design --model m.json --candidates cands.csv --count 21
[ ! -e bad.csv ] || fail "a failed run left an output"
echo "design_cli: ok"
