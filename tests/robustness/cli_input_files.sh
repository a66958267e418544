#!/usr/bin/env bash
# Loaded files go through the same range and schema checks as the command-line flags, and the
# message names the file and the field (line and column for CSV): inputs that used to run with
# exit 0 and print nan or inf, sensors that never move, and text encodings (BOM, invalid UTF-8,
# hexadecimal numbers). Args: <whirl> <scratch dir> <source dir>.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"; cd "$D"
source "$SRC/tests/support/cli_common.sh"
# KEEP_GOING=1: report every failing check instead of stopping at the first (to see what an older
# build gets wrong).
if [ -n "${KEEP_GOING:-}" ]; then fail() { echo "FAIL: $*"; }; fi
S="$SRC/datasets/screws/reference_80x10x6000.json"
PROFILE="$SRC/datasets/machines/example_840d.json"
# json_set <in> <out> <python expression on j>: a copy of a JSON file with one field changed.
json_set() { python3 -c "import json,sys; j=json.load(open(sys.argv[1])); $3; json.dump(j, open(sys.argv[2], 'w'))" "$1" "$2" || fail "json_set $*"; }

# --- Surface files: every number in range (a centre or bound of 1e308 printed nan) -------------
"$W" surface synth --nx 6 --ny 5 --out pts.csv > /dev/null || fail "synth"
"$W" surface fit --points pts.csv --out cubic.json > /dev/null || fail "fit cubic"
"$W" surface fit --points pts.csv --method bspline --out bspline.json > /dev/null || fail "fit bspline"
json_set cubic.json centre.json "j['cubic']['x_center_mm'] = 1e308"
json_set cubic.json bound.json "j['bounds']['x_max_mm'] = 1e308"
json_set cubic.json coeff.json "j['cubic']['b_um'][3] = 1e300"
json_set cubic.json version.json "j['schema_version'] = 1.5"
json_set bspline.json weight.json "j['bspline']['weights_um'][1][2] = -1e300"
expect_fail "centre.json.*cubic.x_center_mm = 1e+308.*\[-100000, 100000\] mm" "$W" surface line --surface centre.json
expect_fail "bound.json.*bounds.x_max_mm = 1e+308" "$W" surface line --surface bound.json
expect_fail "centre.json.*cubic.x_center_mm" "$W" surface predict --surface centre.json --x-mm 1 --y-mm 1
expect_fail "coeff.json.*cubic.b_um\[3\] = 1e+300" "$W" surface predict --surface coeff.json --x-mm 1 --y-mm 1
expect_fail "version.json.*schema_version" "$W" surface predict --surface version.json --x-mm 1 --y-mm 1
expect_fail "weight.json.*bspline.weights_um\[1\]\[2\]" "$W" surface predict --surface weight.json --x-mm 1 --y-mm 1
# --axis is an 840D axis name, as in 'plan'.
for axis in 1 _ "X Y" ""; do
  expect_fail "--axis: '$axis' breaks the rule: an 840D axis name" "$W" surface line --surface cubic.json --axis "$axis"
done
"$W" surface line --surface cubic.json --axis Z1 > /dev/null || fail "axis Z1 refused"
# Flags that stand for numbers are finite numbers.
expect_fail "at-mm.*finite" "$W" surface line --surface cubic.json --at-mm nan
expect_fail "\-\-x.*finite" "$W" surface predict --surface cubic.json --x-mm nan --y-mm 1
# synth writes only what fit reads (at most 10000 points).
expect_fail "nx \* ny = 40000.*10000" "$W" surface synth --nx 200 --ny 200 --out big.csv
[ -e big.csv ] && fail "synth wrote a points file that fit refuses"

# --- The retired legacy machine file: refused, naming what replaced it; nothing written ------
echo '{}' > empty.json
expect_fail "\-\-machine: applied to the legacy machine world, which was retired" \
  "$W" machine sensors --machine empty.json --out-dir m_out
expect_fail "\-\-machine: applied to the legacy machine world" "$W" machine evaluate --machine empty.json
[ -e m_out ] && fail "machine wrote files after a retired flag"

# --- Drift model files: residual_std_um of +-1e308 gave std inf and a threshold of inf ---------
awk 'BEGIN { print "time_min,a_C,b_C,c_C,err_um,spindle_rpm";
  for (k = 0; k < 120; k++) { A = 8 * (1 - exp(-k / 13)); B = k / 40;
    printf "%d,%.4f,%.4f,%.4f,%.4f,%d\n", k, 20 + A + 0.01 * sin(7 * k), 20 + B + 0.01 * cos(5 * k),
      20 + 2 * sin(k / 15), 2 * A - 1.5 * B + 0.05 * sin(3 * k), (k % 40 < 30 ? 1000 : 0) } }' > run.csv
"$W" drift fit --run run.csv --error err_um --sensors a_C,b_C --out model.json > /dev/null 2>&1 \
  || fail "drift fit"
for v in 1e308 -1e308; do
  json_set model.json "std_$v.json" "j['residual_std_um'] = $v"
  expect_fail "std_$v.json.*residual_std_um = ${v/e/e+}.*\[0, 1e+06\] um" "$W" drift predict --model "std_$v.json" --run run.csv
  expect_fail "std_$v.json.*residual_std_um" "$W" drift monitor --model "std_$v.json" --run run.csv
done
json_set model.json version_str.json "j['schema_version'] = '1'"
expect_fail "version_str.json.*schema_version" "$W" drift predict --model version_str.json --run run.csv
# split --threshold nan cut nothing and exited 0.
expect_fail "threshold.*finite" "$W" drift split --log run.csv --threshold nan --out-dir split_out
[ -e split_out ] && fail "split wrote runs with a nan threshold"

# --- Screw files and machine offsets: the field the user wrote, with its range ----------------
json_set "$S" margin.json "j.setdefault('process', {})['tool_circle_margin_mm'] = 1e308"
expect_fail "margin.json.*process.tool_circle_margin_mm = 1e+308.*(0, 100\] mm" "$W" simulate --screw margin.json --duration-s 10
json_set "$S" offset.json "j.setdefault('process', {})['thread_start_offset_mm'] = 1e308"
expect_fail "offset.json.*process.thread_start_offset_mm = 1e+308" "$W" simulate --screw offset.json --duration-s 10
PLAN=(plan --screw "$S" --max-elongation-um 30 --settle-time-s 250 --nc P.SPF)
expect_fail "machine-offset-mm.*1e308" "$W" "${PLAN[@]}" --start-position-mm 0 --machine-offset-mm 1e308
expect_fail "start-position-mm.*1e308" "$W" "${PLAN[@]}" --start-position-mm 1e308 --machine-offset-mm 0
json_set "$PROFILE" profile.json "j['machine_offset_mm'] = 1e308"
expect_fail "profile.json.*machine_offset_mm = 1e+308.*\[-100000, 100000\] mm" "$W" "${PLAN[@]}" --machine profile.json
[ -e P.SPF ] && fail "plan wrote a program"

# --- Stuck and dead sensors: named, left out with a warning; all dead is an error -------------
awk -F, -v OFS=, 'NR == 1 { print $0, "dead_C", "a_copy_C"; next } { print $0, "21.5", $2 }' run.csv > sensors.csv
"$W" drift select --run sensors.csv --error err_um --classes margin > sel.txt 2> sel.err || fail "select: $(cat sel.err)"
grep -q "warning: dead_C is dead: its reading never moves in sensors.csv" sel.err || fail "no dead-sensor warning: $(cat sel.err)"
grep -q "warning: a_copy_C moves exactly as a_C" sel.err || fail "no duplicate warning: $(cat sel.err)"
grep "chosen sensors" sel.txt | grep -Eq "dead_C|a_copy_C" && fail "a dead or copied sensor was chosen: $(cat sel.txt)"
"$W" drift fit --run sensors.csv --error err_um --classes margin --out fit.json > /dev/null 2> fit.err \
  || fail "fit with a dead sensor: $(cat fit.err)"
grep -q "dead_C is dead" fit.err || fail "fit: no warning"
"$W" drift fit --run sensors.csv --error err_um --sensors a_C,dead_C,a_copy_C --out given.json \
  > /dev/null 2> given.err || fail "fit on given sensors: $(cat given.err)"
python3 -c "import json,sys; s = json.load(open('given.json'))['sensors']; assert s == ['a_C'], s" \
  || fail "given dead/copied sensors not left out"
awk 'BEGIN { printf "time_min"; for (i = 1; i <= 16; i++) printf ",t%d_C", i; print ",err_um";
  for (k = 0; k < 30; k++) { printf "%d", k; for (i = 1; i <= 16; i++) printf ",20"; printf ",%g\n", k * 0.1 } }' > constant.csv
expect_fail "constant.csv: no usable temperature sensor" "$W" drift select --run constant.csv --error err_um
expect_fail "constant.csv: no usable temperature sensor" "$W" drift fit --run constant.csv --error err_um --out c.json

# --- Text encodings ----------------------------------------------------------------------------
# A byte-order mark (what spreadsheets write) hid the time column; before '#' it made the comment
# the header.
{ printf '\xef\xbb\xbf'; cat run.csv; } > bom.csv
"$W" drift select --run bom.csv --error err_um > /dev/null 2> bom.err || fail "BOM run: $(cat bom.err)"
grep -q "sample index" bom.err && fail "a BOM hid the time column: $(cat bom.err)"
{ printf '\xef\xbb\xbf# made by a spreadsheet\n'; cat pts.csv; } > bom_pts.csv
"$W" surface fit --points bom_pts.csv > /dev/null || fail "BOM before a comment line"
# Invalid UTF-8 in a column name: file, line and column, never a raw JSON exception.
sed '1s/c_C/c\xff_C/' run.csv > bad_name.csv
expect_fail "bad_name.csv:1: column 4, character 19: byte 0xFF is not UTF-8" "$W" drift select --run bad_name.csv --error err_um --json
sed '3s/^1,/1,\xc3/' run.csv > bad_cell.csv
expect_fail "bad_cell.csv:3: column 2" "$W" drift fit --run bad_cell.csv --error err_um --out never.json
grep -q "json.exception" err.txt && fail "raw JSON exception: $(cat err.txt)"
# Hexadecimal and other non-decimal numbers in any CSV reader.
sed '3s/^1,/0x1p0,/' run.csv > hex_run.csv
expect_fail "hex_run.csv:3: column 1 ('time_min'): '0x1p0' is not a decimal number" "$W" drift select --run hex_run.csv --error err_um
printf 'x_mm,y_mm\n0x1p3,0\n' > hex_xy.csv
expect_fail "hex_xy.csv:2: column 1 ('x_mm')" "$W" surface predict --surface cubic.json --input hex_xy.csv
printf 'position_mm,deviation_um\n0,0\n0x10,1\n32,2\n' > hex_lead.csv
expect_fail "hex_lead.csv:3" "$W" lead-report --lead hex_lead.csv
# surface points: BOM files keep their time axis (--time-min 90 is 90 min, not sample 90), a
# --time-min nan is refused, and a failed run leaves no --predictions file behind.
python3 - <<'PY'
import math
xs, ys = [0, 200, 400, 600], [0, 100, 200, 300]
def run(tau1, tau2, gain, name):
    text = "\ufefftime_min,t1_C,t2_C" + "".join(f",p_x{x}_y{y}_um" for y in ys for x in xs) + "\n"
    for k in range(81):
        t = 5.0 * k
        d1, d2 = gain * 8 * (1 - math.exp(-t / tau1)), 3 * (1 - math.exp(-t / tau2))
        text += f"{t},{20 + d1},{21 + d2}" + "".join(
            f",{(1 + x / 400) * d1 + (0.5 + y / 300) * d2}" for y in ys for x in xs) + "\n"
    open(name, "wb").write(text.encode())
run(30, 120, 1.0, "train.csv"); run(50, 90, 0.7, "target.csv")
PY
POINTS=(surface points --run target.csv --train train.csv --sensors t1_C,t2_C)
if "$W" "${POINTS[@]}" --time-min 90 --json > points.json 2> points.err; then
  grep -q '"whirl surface points --run target.csv at time 90 min"' points.json \
    || fail "BOM: the time column was lost: $(grep 'at time' points.json)"
  expect_fail "time-min.*finite" "$W" "${POINTS[@]}" --time-min nan
  mkdir -p out_dir
  expect_fail "out_dir" "$W" "${POINTS[@]}" --time-min 90 --predictions pred.csv --out out_dir
  [ -e pred.csv ] && fail "surface points left its --predictions file behind"
else
  grep -q "not in this build" points.err || fail "points: $(cat points.err)"
fi
echo "ok"
