#!/usr/bin/env bash
# Every bad input of the sweep is refused with exit 1 and a message naming the
# rule, quickly, and leaves no output behind. Args: <whirl> <scratch dir> <source dir>.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"; cd "$D"
source "$SRC/tests/support/cli_common.sh"
S="$SRC/datasets/screws/reference_80x10x6000.json"
T="$SRC/datasets/whirling_train.csv"
M="$SRC/models/default.json"
# Every command below must answer within seconds (a limit, not hours of work or an 80 GB alloc).
t() { timeout 60 "$@"; }

# A 10 km and a 1000 km blank: simulate, compare, evaluate.
for L in 1e7 1e9; do
  sed "s/\"length_mm\": 6000.0/\"length_mm\": $L/" "$S" > "len_$L.json"
  expect_fail "at most 20000 mm" t "$W" simulate --screw "len_$L.json" --duration-s 10
  expect_fail "at most 20000 mm" t "$W" compare --model "$M" --screw "len_$L.json" \
    --history "$SRC/datasets/whirling_500.csv"
  expect_fail "at most 20000 mm" t "$W" evaluate --base-screw "len_$L.json" --random 1 --no-validation
done
# A cell size that would overflow the cell count, and one coarser than a third of the blank.
expect_fail "3 to 200000 cells" t "$W" simulate --screw "$S" --cell-size-mm 1e-300 --duration-s 10
expect_fail "3 to 200000 cells" t "$W" simulate --screw "$S" --cell-size-mm 5000 --duration-s 10
expect_fail "steps" t "$W" simulate --screw "$S" --time-step-s 1e-6 --duration-s 100
# Unbounded counts.
expect_fail "200" t "$W" train --data "$T" --hidden-sweep 1..1000000
expect_fail "10000" t "$W" evaluate --random 1000000000
expect_fail "10000" t "$W" evaluate --random 100 --seeds 1000
# --seed -1 (and beyond 2^64 - 1) is refused, never wrapped.
expect_fail "whole number" t "$W" simulate --screw "$S" --seed -1 --duration-s 10
expect_fail "whole number" t "$W" dataset --count 1 --seed 18446744073709551616 --out x.csv
# A missing input file is always an error.
expect_fail "missing.json" t "$W" evaluate --base-screw missing.json --random 1 --no-validation

# Model files: a 2e9-neuron layer, epochs 1e30, a number beyond double.
[ -f "$M" ] || fail "models/default.json not shipped"
tr -d '\n' < "$M" | sed -E 's/"layer_sizes": *\[[^]]*\]/"layer_sizes": [5, 2000000000, 2]/' > big_layer.json
grep -q '"layer_sizes": \[5, 2000000000, 2\]' big_layer.json || fail "could not make big_layer.json"
expect_fail "layer_sizes\[1\]" t "$W" predict --model big_layer.json --hardness-hrc 62 --diameter-mm 80 \
  --pitch-mm 10 --raceway-radius-mm 3.7 --cutting-speed-m-min 180
tr -d '\n' < "$M" | sed -E 's/"epochs": *[0-9]+,/"epochs": 1e30,/' > epochs.json
grep -q '"epochs": 1e30' epochs.json || fail "could not make epochs.json"
expect_fail "epochs" t "$W" predict --model epochs.json --hardness-hrc 62 --diameter-mm 80 \
  --pitch-mm 10 --raceway-radius-mm 3.7 --cutting-speed-m-min 180
tr -d '\n' < "$M" | sed -E 's/"epochs": *[0-9]+,/"epochs": 1e999,/' > huge.json
grep -q '"epochs": 1e999' huge.json || fail "could not make huge.json"
expect_fail "huge.json.*double range" t "$W" predict --model huge.json --hardness-hrc 62 \
  --diameter-mm 80 --pitch-mm 10 --raceway-radius-mm 3.7 --cutting-speed-m-min 180
# Process tables with an impossible diameter; predict --diameter-mm 0 likewise.
for bad in -80 0 1e308; do
  awk -F, -v OFS=, -v bad="$bad" '/^#/ {print; next} !h {h=1; print; next} !r {r=1; $2=bad} {print}' \
    "$T" > "table_$bad.csv"
  expect_fail "table_$bad.csv:[0-9]*: diameter_mm = .* (0, 500\] mm" t "$W" train --data "table_$bad.csv" \
    --out m.json --epochs 5
done
[ -e m.json ] && fail "a failed train wrote m.json"
expect_fail "diameter_mm" t "$W" predict --hardness-hrc 62 --diameter-mm 0 --pitch-mm 10 --raceway-radius-mm 3.7 \
  --cutting-speed-m-min 180
# lead-report: positions near 1e308, positions closer than 1 nm (subnormal steps).
printf 'position_mm,deviation_um\n0,0\n1e307,1\n1.7e308,2\n' > lead_big.csv
expect_fail "position" t "$W" lead-report --lead lead_big.csv
printf 'position_mm,deviation_um\n0,0\n1e-320,1e-310\n2e-320,2e-310\n' > lead_sub.csv
expect_fail "1 nm" t "$W" lead-report --lead lead_sub.csv
printf 'position_mm,deviation_um\n0,0\n1,1e-310\n2,2e-310\n3,0\n' > lead_tiny.csv
t "$W" lead-report --lead lead_tiny.csv --json > tiny.json || fail "subnormal deviations refused"
# nlohmann::json writes NaN and infinity as null; only v_2pi may be null (no --lead-mm given).
python3 - tiny.json <<'PY' || fail "non-finite metric: $(cat tiny.json)"
import json, math, sys
def walk(v, path):
    if isinstance(v, dict):
        for k, x in v.items(): walk(x, path + [k])
    elif isinstance(v, list):
        for i, x in enumerate(v): walk(x, path + [str(i)])
    elif v is None:
        assert path[-1] == "v_2pi_um", path
    elif isinstance(v, float):
        assert math.isfinite(v), path
walk(json.load(open(sys.argv[1]), parse_constant=lambda c: float(c)), [])
PY

# plan and curve: absurd features and tolerances are refused at once (no long grid search).
expect_fail "1 nm" t "$W" plan --screw "$S" --start-position-mm 0 --machine-offset-mm 0 --max-elongation-um 30 --settle-time-s 250 --tolerance-um 1e-300
expect_fail "--max-elongation-um: 1e300" t "$W" plan --screw "$S" --start-position-mm 0 --machine-offset-mm 0 --max-elongation-um 1e300 --settle-time-s 250
expect_fail "at least 1 s" t "$W" plan --screw "$S" --start-position-mm 0 --machine-offset-mm 0 --max-elongation-um 30 --settle-time-s 1e-300
expect_fail "--settle-time-s: 1e300" t "$W" curve --max-elongation-um 30 --settle-time-s 1e300
expect_fail "32 characters" t "$W" plan --screw "$S" --start-position-mm 0 --machine-offset-mm 0 --max-elongation-um 30 --settle-time-s 250 \
  --axis "$(printf 'X%.0s' $(seq 1 40))"

# plan: one unwritable output leaves the others unwritten (and previous files intact).
echo previous > keep.json
mkdir adir
expect_fail "adir.*directory" t "$W" plan --screw "$S" --start-position-mm 0 --machine-offset-mm 0 --max-elongation-um 30 --settle-time-s 250 \
  --out keep.json --csv new.csv --nc adir --sync-id-first 100 --sync-id-last 149
[ "$(cat keep.json)" = previous ] || fail "plan replaced keep.json although --nc failed"
[ -e new.csv ] && fail "plan wrote new.csv although --nc failed"
expect_fail "nodir" t "$W" plan --screw "$S" --start-position-mm 0 --machine-offset-mm 0 --max-elongation-um 30 --settle-time-s 250 \
  --out keep.json --nc nodir/XY.mpf --sync-id-first 100 --sync-id-last 149
[ "$(cat keep.json)" = previous ] || fail "plan replaced keep.json although --nc failed"
# The atomic writer respects what sits at the path: a symlink, a FIFO, a directory.
ln -s keep.json link.json
expect_fail "symbolic link" t "$W" plan --screw "$S" --start-position-mm 0 --machine-offset-mm 0 --max-elongation-um 30 --settle-time-s 250 --out link.json
[ -L link.json ] || fail "the symlink was replaced"
mkfifo pipe
expect_fail "FIFO" t "$W" plan --screw "$S" --start-position-mm 0 --machine-offset-mm 0 --max-elongation-um 30 --settle-time-s 250 --out pipe
[ -p pipe ] || fail "the FIFO was replaced"
expect_fail "is a directory" t "$W" plan --screw "$S" --start-position-mm 0 --machine-offset-mm 0 --max-elongation-um 30 --settle-time-s 250 --out adir
grep -q "Success" err.txt && fail "message says Success: $(cat err.txt)"
# Reading a FIFO would block: refused.
expect_fail "FIFO" t "$W" simulate --screw pipe
# Nothing but the files made above, no temporary left.
ls -A | grep -q '\.tmp' && fail "temporary left: $(ls -A)"
# Limits are stated in --help.
for c in simulate train evaluate lead-report; do "$W" $c --help > "help_$c.txt" || fail "$c --help"; done
grep -q "200000" help_simulate.txt || fail "simulate --help lacks the cell limit"
grep -q "(0, 500\] mm" help_train.txt || fail "train --help lacks the physical limits"
grep -q "10000" help_evaluate.txt || fail "evaluate --help lacks the --random limit"
grep -q "1e6 mm" help_lead-report.txt || fail "lead-report --help lacks the limits"
echo "ok"
