#!/usr/bin/env bash
# Smoke test of `whirl surface synth|fit|predict|compare|line` on synthetic fields with known
# properties, and its input errors (exit 1, message naming file/line/rule, nothing written).
set -uo pipefail
whirl="$1"; D="$2"; src="$3"
rm -rf "$D"; mkdir -p "$D"; cd "$D"
source "$src/tests/support/cli_common.sh"

"$whirl" surface --help | grep -c "B-spline" > /dev/null || fail "surface --help"
"$whirl" surface fit --help | grep -c "x_mm,y_mm,error_um" > /dev/null || fail "fit --help"
"$whirl" surface line --help | grep -c "SD43910" > /dev/null || fail "line --help"

# A field that is exactly cubic (no noise): the cubic reproduces every point and predicts it
# anywhere; the noise-free smooth field is 10 um at (0, 0) and 38 um at (800, 500).
"$whirl" surface synth --field smooth --noise-um 0 --out smooth.csv > /dev/null || fail "synth"
grep -q "^# .*seed 1" smooth.csv || fail "synth provenance"
"$whirl" surface fit --points smooth.csv --method cubic --out cubic.json --json > fit.json \
  || fail "fit cubic"
"$whirl" surface predict --surface cubic.json --x-mm 800 --y-mm 500 --json > p.json || fail "predict"
"$whirl" surface fit --points smooth.csv --method bspline --out bspline.json > /dev/null \
  || fail "fit bspline"
printf 'x_mm,y_mm\n0,0\n400,250\n800,500\n' > xy.csv
"$whirl" surface predict --surface bspline.json --input xy.csv --out pred.csv > /dev/null \
  || fail "predict --input"
python3 - <<'PY' || fail "numbers"
import csv, json
f = json.load(open("fit.json"))
assert f["schema"] == "whirl.surface" and f["method"] == "cubic", f.keys()
assert f["summary"]["max_abs_residual_um"] < 1e-9, f["summary"]
assert len(f["cubic"]["a_mm"]) == 10
p = json.load(open("p.json"))["predictions"][0]
assert abs(p["error_um"] - 38) < 1e-9 and p["inside_measured_rectangle"], p
rows = list(csv.DictReader(r for r in open("pred.csv") if not r.startswith("#")))
want = {(0, 0): 10.0, (800, 500): 38.0}
for r in rows:
    key = (float(r["x_mm"]), float(r["y_mm"]))
    if key in want:
        assert abs(float(r["error_um"]) - want[key]) < 1e-9, r
PY

# The bump field: the B-spline's leave-one-out error is lower and it is recommended.
"$whirl" surface synth --field bump --out bump.csv > /dev/null || fail "synth bump"
"$whirl" surface compare --points bump.csv --json > cmp.json || fail "compare"
python3 -c "
import json; c = json.load(open('cmp.json'))
assert c['recommended'] == 'bspline', c['reason']
assert c['bspline']['loo_common']['rms_um'] < c['cubic']['loo_common']['rms_um']
" || fail "bump comparison"
# compare's thresholds: refused by the flag's name with the rule --help shows (the help said
# "finite" and the message named the field, "overshoot_fraction -1 must be > 0").
expect_fail "\-\-edge-ratio: 1 breaks the rule: .*> 1" "$whirl" surface compare --points bump.csv --edge-ratio 1
expect_fail "\-\-overshoot-fraction: -1 breaks the rule: .*> 0" "$whirl" surface compare --points bump.csv \
  --overshoot-fraction -1
expect_fail "\-\-min-excess-um: -5 breaks the rule: .*>= 0" "$whirl" surface compare --points bump.csv \
  --min-excess-um -5
# Positions: the axis range of 'plan' (+-100000 mm), by the flag's name.
"$whirl" surface fit --points bump.csv --out bump_fit.json > /dev/null || fail "fit bump"
for flag in --ref-position-mm --machine-offset-mm; do
  expect_fail "\\$flag: 1e300 breaks the rule: .*\[-100000, 100000\] mm" "$whirl" surface line \
    --surface bump_fit.json "$flag" 1e300
done
expect_fail "\-\-x-mm: 1e300 breaks the rule" "$whirl" surface predict --surface bump_fit.json \
  --x-mm 1e300 --y-mm 0
"$whirl" surface compare --help | grep -A1 -- "--edge-ratio" | grep -q "FLOAT:> 1" \
  || fail "compare --help: no range of --edge-ratio: $("$whirl" surface compare --help | grep -A1 -- --edge-ratio)"

# 840D line of an exactly linear field: nothing left uncorrected, slope = -0.02 um/mm / 1000.
printf 'x_mm,y_mm,error_um\n' > plane.csv
for y in 0 100 200 300; do for x in 0 100 200 300 400; do
  echo "$x,$y,$(python3 -c "print(5 + 0.02 * $x)")" >> plane.csv; done; done
"$whirl" surface fit --points plane.csv --method bspline --degree 3 --out plane.json > /dev/null \
  || fail "fit plane"
"$whirl" surface line --surface plane.json --axis X1 --json > line.json || fail "line"
python3 -c "
import json; l = json.load(open('line.json'))
assert abs(l['sd43910'] + 0.02 / 1000) < 1e-12, l
assert abs(l['sd43900_mm'] + 5 / 1000) < 1e-12, l
assert l['uncorrected_max_abs_um'] < 1e-9 and not l['slope_capped'], l
" || fail "line numbers"
"$whirl" surface line --surface plane.json | grep -q 'SD43920 \$SA_TEMP_COMP_REF_POSITION\[X\]' \
  || fail "line text"

# Report with a map.
"$whirl" surface fit --points bump.csv --method bspline --out b.json --out-dir rep > /dev/null \
  2> rep.err || fail "report"
[ -s rep/index.html ] && [ -s rep/map.gp ] || fail "report files"
if command -v gnuplot > /dev/null; then [ -s rep/map.png ] || fail "no map.png"; fi

# Hostile file names (quote, backslash, newline, markup) stay text in the page, the CSVs and gnuplot.
evil=$'ev\'il\\ "x"\n<script>alert(1).csv'
cp bump.csv "$evil"
"$whirl" surface fit --points "$evil" --method cubic --out "$evil.json" --out-dir rep2 > /dev/null \
  2> rep2.err || fail "report with a hostile name: $(cat rep2.err)"
! grep -q "<script>" rep2/index.html || fail "markup reached the page"
grep -q "&lt;script&gt;" rep2/index.html || fail "name not shown escaped"
"$whirl" surface predict --surface "$evil.json" --input xy.csv --out evil_pred.csv > /dev/null \
  || fail "predict with a hostile name"
python3 - <<'PY' || fail "hostile name broke a CSV"
for name in ("rep2/points.csv", "evil_pred.csv"):
    rows = [l for l in open(name) if not l.startswith("#")]
    assert rows[0].strip() == "x_mm,y_mm,error_um", (name, rows[0])
    assert all(len(r.split(",")) == 3 for r in rows), name
PY
if command -v gnuplot > /dev/null; then [ -s rep2/map.png ] || fail "no map with a hostile name"; fi

# Bad input: exit 1, the message names the rule; nothing written.
head -12 smooth.csv > few.csv  # a regular file: whirl reads no FIFOs
expect_fail "distinct positions" "$whirl" surface fit --points few.csv \
  --method cubic --out none.json
[ ! -e none.json ] || fail "wrote a surface on failure"
head -20 bump.csv | grep -v '^#' > partial.csv
expect_fail "irregular grid" "$whirl" surface fit --points partial.csv --method bspline \
  --out none.json
printf 'x_mm,y_mm,error_um\n0,0,1\n1,0,1\n0,1,1\n1,1,1\n' > tiny.csv
expect_fail "needs at least degree + 1" "$whirl" surface fit --points tiny.csv --method bspline
printf 'x_mm,y_mm,error_um\n0,0,1\n1,x,1\n' > bad.csv
expect_fail "bad.csv:3" "$whirl" surface fit --points bad.csv
printf 'x_mm,error_um\n0,1\n' > nocol.csv
expect_fail "missing column 'y_mm'" "$whirl" surface fit --points nocol.csv
expect_fail "does not extrapolate" "$whirl" surface predict --surface b.json --x-mm 900 --y-mm 10
expect_fail "either --x-mm X --y-mm Y or --input" "$whirl" surface predict --surface b.json
expect_fail "must be in (0, 0.10]" "$whirl" surface line --surface b.json --md32760 0.5
expect_fail "outside the measured range" "$whirl" surface line --surface b.json --at-mm 9999
printf '{"schema": "whirl.plan"}' > notsurface.json
expect_fail "not a whirl surface file" "$whirl" surface predict --surface notsurface.json --x-mm 1 --y-mm 1

# Per-point models (point 1): the drift module's MLR at each point.
"$whirl" surface points --help | grep -c "_x<X>_y<Y>_um" > /dev/null || fail "points --help"
python3 - <<'PY' || fail "per-point runs not generated"
import math
xs, ys = [0, 200, 400, 600], [0, 100, 200, 300]
def run(tau1, tau2, gain, name):  # error = (1 + x/400) dT1 + (0.5 + y/300) dT2
    with open(name, "w") as f:
        f.write("# generated by cli_surface.sh\ntime_min,t1_C,t2_C" +
                "".join(f",p_x{x}_y{y}_um" for y in ys for x in xs) + "\n")
        for k in range(81):
            t = 5.0 * k
            d1, d2 = gain * 8 * (1 - math.exp(-t / tau1)), 3 * (1 - math.exp(-t / tau2))
            f.write(f"{t},{20 + d1},{21 + d2}" +
                    "".join(f",{(1 + x / 400) * d1 + (0.5 + y / 300) * d2}" for y in ys for x in xs)
                    + "\n")
run(30, 120, 1.0, "train.csv"); run(50, 90, 0.7, "target.csv")
PY
"$whirl" surface points --run target.csv --train train.csv --sensors t1_C,t2_C --time-min 100 \
  --out pts.json > pts.txt 2> pts.err || fail "points: $(cat pts.err)"
"$whirl" surface predict --surface pts.json --x-mm 333 --y-mm 77 --json > pp.json || fail "points predict"
python3 -c "
import json, math
d1, d2 = 0.7 * 8 * (1 - math.exp(-100 / 50)), 3 * (1 - math.exp(-100 / 90))
want = (1 + 333 / 400) * d1 + (0.5 + 77 / 300) * d2
got = json.load(open('pp.json'))['predictions'][0]['error_um']
assert abs(got - want) < 1e-5, (got, want)
" || fail "per-point surface"
echo OK
