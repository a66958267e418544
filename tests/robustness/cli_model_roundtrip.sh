#!/usr/bin/env bash
# Every model a command writes, handed to every command that takes a model file: accepted, or
# refused by name (exit 1 or 2, an 'error:' line that states the rule, never a library's own
# message), never a signal. Producers: drift fit (mlr, dynamic, network, time-only, sensors+time,
# the slope channel), train (auto, linear, gp, network, the paper's trainbr), surface fit (cubic,
# bspline) and surface points, ballbar drift (its drift CSV, read as a run file). Consumers:
# drift predict, drift nc (--model, --slope-model), drift monitor (--run, --day), predict,
# curve, plan (alone and --with-drift-action), compare, evaluate, crosscheck, export, surface
# predict, surface line, and the run-file readers for the ball-bar CSV. Where a pair must be
# accepted (a model of the kind the command takes) the test says so; the matrix is printed.
# Args: <whirl> <scratch dir> <source dir>.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"; cd "$D"
source "$SRC/tests/support/cli_common.sh"
if [ -n "${KEEP_GOING:-}" ]; then fail() { echo "FAIL: $*"; }; fi
S="$SRC/datasets/screws/reference_80x10x6000.json"
TABLE="$SRC/datasets/whirling_train.csv"
P840="$SRC/datasets/machines/example_840d.json"
PSLOPE="$SRC/datasets/machines/whirling_840d.json"

# --- Producers ---------------------------------------------------------------------------------
"$W" machine sensors --out-dir runs --idle 2 --cutting 2 > /dev/null || fail "machine sensors"
# The field machine logs one displacement (offset_um); a slope model (drift nc --slope-model)
# needs a lead-slope channel: zscrew_per_1000_um, made from the offset and the first sensor, so
# that the mlr fit has something to follow (what is checked here is the file round trip).
python3 - runs/cutting_1.csv runs/cutting_2.csv runs/idle_1.csv <<'EOF' || fail "slope channel"
import sys
for path in sys.argv[1:]:
    lines = open(path).read().splitlines()
    head = next(i for i, l in enumerate(lines) if l and not l.startswith("#"))
    cols = lines[head].split(",")
    off = cols.index("offset_um")
    temp = next(i for i, c in enumerate(cols) if c.endswith("_C"))
    out = lines[:head] + [lines[head] + ",zscrew_per_1000_um"]
    for l in lines[head + 1:]:
        c = l.split(",")
        out.append(l + f",{0.3 * float(c[off]) + 0.5 * float(c[temp]):.4f}")
    open(path, "w").write("\n".join(out) + "\n")
EOF
R=runs/cutting_1.csv
fit() {  # fit <name> <error column> <drift fit options...>
  local name="$1" error="$2"; shift 2
  "$W" drift fit --cutting runs/cutting_1.csv runs/cutting_2.csv --idle runs/idle_1.csv \
    --error "$error" "$@" --out "$name.json" > /dev/null 2> fit.err || fail "drift fit $name: $(cat fit.err)"
}
fit drift_mlr offset_um --model mlr --candidates sensors
fit drift_dynamic offset_um --model dynamic --candidates sensors
fit drift_network offset_um --model network --candidates sensors --hidden 2
fit drift_time offset_um --candidates time
fit drift_sensors_time offset_um --candidates sensors+time
fit drift_default offset_um
fit drift_slope zscrew_per_1000_um --model mlr --candidates sensors
for family in auto linear gp network; do
  "$W" train --data "$TABLE" --family "$family" --out "work_$family.json" > /dev/null 2>&1 ||
    fail "train --family $family"
done
"$W" train --data "$TABLE" --trainbr-matlab --out work_trainbr.json > /dev/null 2>&1 || fail "trainbr"
"$W" surface synth --nx 6 --ny 5 --out pts.csv > /dev/null || fail "surface synth"
"$W" surface fit --points pts.csv --out surf_cubic.json > /dev/null || fail "surface fit cubic"
"$W" surface fit --points pts.csv --method bspline --degree 2 --out surf_bspline.json > /dev/null ||
  fail "surface fit bspline"
python3 - "$R" > /dev/null <<'EOF' || fail "position-tagged run"
import sys
rows = [r for r in open(sys.argv[1]).read().splitlines() if r and not r.startswith("#")]
head = rows[0].split(",")
tags = {"offset_um": "p1_x0_y0_um", "zscrew_per_1000_um": "p2_x400_y0_um"}
extra = ["p3_x0_y300_um", "p4_x400_y300_um", "p5_x200_y150_um", "p6_x0_y150_um",
         "p7_x400_y150_um", "p8_x200_y0_um", "p9_x200_y300_um"]  # a complete 3 x 3 grid
out = [",".join([tags.get(h, h) for h in head] + extra)]
for k, r in enumerate(rows[1:]):
    cells = r.split(",")
    base = float(cells[head.index("offset_um")])
    out.append(",".join(cells + [f"{base * (1 + 0.1 * (i + 1)):.4f}" for i in range(len(extra))]))
open("points_run.csv", "w").write("\n".join(out) + "\n")
EOF
"$W" surface points --run points_run.csv --time-min 60 --method bspline --degree 1 \
  --out surf_points.json > /dev/null 2>&1 || fail "surface points"
"$W" ballbar simulate --out-dir bb > /dev/null || fail "ballbar simulate"
"$W" ballbar drift --readings bb/readings.csv --pivots bb/pivots.json --out ballbar_drift.csv \
  > /dev/null || fail "ballbar drift"
MODELS=(drift_mlr drift_dynamic drift_network drift_time drift_sensors_time drift_default
        drift_slope work_auto work_linear work_gp work_network work_trainbr surf_cubic
        surf_bspline surf_points)

# --- Consumers ---------------------------------------------------------------------------------
# consumer <id> <kind it takes> <command with MODEL for the file>
CONSUMERS=(
  "drift_predict|drift|drift predict --model MODEL --run $R"
  "drift_nc|drift_linear|drift nc --model MODEL --machine $PSLOPE --nc DRIFT.SPF --reset-nc DRIFT_RESET.SPF --csv plc.csv"
  "drift_nc_slope|drift_linear|drift nc --model drift_mlr.json --slope-model MODEL --machine $PSLOPE --nc DRIFT.SPF --reset-nc DRIFT_RESET.SPF"
  "drift_monitor_run|drift_linear|drift monitor --model MODEL --run $R"
  "drift_monitor_day|drift_linear|drift monitor --model MODEL --day runs/cutting_1.csv --day runs/cutting_2.csv"
  "predict|work|predict --model MODEL --input $TABLE"
  "curve|work|curve --model MODEL --screw $S"
  "plan|work|plan --model MODEL --screw $S --machine $P840 --nc PLAN.SPF --reset-nc PLAN_RESET.SPF --csv plan.csv"
  "plan_drift|work|plan --model MODEL --screw $S --machine $P840 --with-drift-action --nc PLAN.SPF --reset-nc PLAN_RESET.SPF"
  "compare|work|compare --model MODEL --screw $S --history $SRC/datasets/whirling_500.csv"
  "evaluate|work|evaluate --model MODEL --random 1 --no-validation"
  "crosscheck|work_network|crosscheck --model MODEL --data $TABLE"
  "export|work_network|export --model MODEL --torchscript model.pt"
  "surface_predict|surf|surface predict --surface MODEL --x-mm 100 --y-mm 50"
  "surface_line|surf|surface line --surface MODEL --along x"
)
# Must a model of this name be accepted by a consumer taking `kind`? (The rest must be accepted or
# refused by name.) Known refusals by name: a drift network or an elapsed-time model on the
# control (drift nc, monitor: linear models only); a family model for crosscheck and export; the
# LibTorch commands when whirl was built without LibTorch.
must_accept() {
  local model="$1" kind="$2"
  case "$kind" in
    drift) [[ $model == drift_* ]] ;;
    drift_linear) [[ $model == drift_mlr || $model == drift_dynamic || $model == drift_slope ]] ;;
    work) [[ $model == work_* ]] ;;
    work_network) false ;;  # crosscheck/export: network only, and only with LibTorch
    surf) [[ $model == surf_* ]] ;;
  esac
}
printf '%-20s' model > matrix.txt
for c in "${CONSUMERS[@]}"; do printf ' %-8.8s' "${c%%|*}" >> matrix.txt; done
echo >> matrix.txt
for m in "${MODELS[@]}"; do
  printf '%-20s' "$m" >> matrix.txt
  for c in "${CONSUMERS[@]}"; do
    id="${c%%|*}"; rest="${c#*|}"; kind="${rest%%|*}"; cmd="${rest#*|}"
    # shellcheck disable=SC2086
    "$W" ${cmd//MODEL/$m.json} > out.txt 2> err.txt; rc=$?
    [ $rc -lt 128 ] || fail "$m -> $id: killed by signal $((rc - 128)) ($(tail -n 2 err.txt))"
    [ $rc -le 2 ] || fail "$m -> $id: exit code $rc"
    if [ $rc -eq 0 ]; then
      printf ' %-8s' ok >> matrix.txt
      continue
    fi
    printf ' %-8s' "refused" >> matrix.txt
    must_accept "$m" "$kind" && fail "$m -> $id refused: $(grep error err.txt | head -n 1)"
    grep -q '^error: ' err.txt || fail "$m -> $id: exit $rc without an error line: $(tail -n 2 err.txt)"
    grep -q 'json.exception' err.txt && fail "$m -> $id: a library message: $(cat err.txt)"
    # By name: the message names the model file, or (a model the command cannot use) says why.
    grep -Eq "$m\.json|model|surface|LibTorch" err.txt || fail "$m -> $id: refused without naming it: $(cat err.txt)"
  done
  echo >> matrix.txt
done
# The ball-bar drift CSV is a run file with error columns only: the run readers name the rule.
for cmd in "drift predict --model drift_mlr.json --run ballbar_drift.csv" \
           "drift fit --run ballbar_drift.csv --error drift_x_um --out x.json" \
           "drift select --run ballbar_drift.csv --error drift_x_um" \
           "drift monitor --model drift_mlr.json --run ballbar_drift.csv"; do
  # shellcheck disable=SC2086
  "$W" $cmd > out.txt 2> err.txt; rc=$?
  [ $rc -ge 1 ] && [ $rc -le 2 ] || fail "ballbar_drift.csv -> $cmd: exit $rc"
  grep -q "ballbar_drift.csv.*temperature column" err.txt || fail "ballbar CSV: $(cat err.txt)"
done
cat matrix.txt
echo "cli_model_roundtrip: ok"
