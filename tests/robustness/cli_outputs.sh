#!/usr/bin/env bash
# Where whirl writes: multi-file outputs are all-or-nothing and a killed run leaves only hidden
# whirl temporaries that the next run removes; every directory output follows one rule (never a
# symbolic link; new, empty or written by whirl before; anything foreign refuses it); no output
# may resolve to an input or to another output. Args: <whirl> <scratch dir> <source dir>.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"; cd "$D"
source "$SRC/tests/support/cli_common.sh"
M840="$SRC/datasets/machines/example_840d.json"
t() { timeout 120 "$@"; }
dead_pid() { sh -c 'echo $$'; }  # a process that has ended
debris() { find "$1" -name '*.partial' -o -name '.*.whirl-tmp-*' -o -name '.*.whirl-bak-*' \
  -o -name '.whirl-stage-*' | head -1; }

# A log with three machine starts (spindle_rpm rises from 0 at 0, 100, 200 min), two sensors and
# an error driven by both; a model fitted on it.
awk 'BEGIN { print "time_min,t1_C,t2_C,ch1_um,spindle_rpm";
  for (k = 0; k < 300; k++) { on = (k % 100) < 60 ? 3000 : 0; t1 = 20 + 8 * (1 - exp(-(k % 100) / 30));
    t2 = 21 + 0.01 * k; printf "%d,%.4f,%.4f,%.4f,%d\n", k, t1, t2, 2 * (t1 - 20) - (t2 - 21) + 0.05 * sin(k), on } }' \
  > log.csv
mkdir v2; awk -F, 'NR > 1 { $3 += 0.5 } 1' OFS=, log.csv > v2/log.csv  # other contents
"$W" drift fit --run log.csv --error ch1_um --sensors t1_C,t2_C --out model.json > /dev/null \
  || fail "drift fit"

# --- Multi-file outputs: all or nothing, targets checked up front ----------------------------
t "$W" drift split --log log.csv --out-dir split > /dev/null || fail "split"
[ -f split/log_3.csv ] || fail "split: expected three runs: $(ls split)"
cp split/log_1.csv keep_1.csv
# A directory planted at one target: refused by name before anything is renamed into place.
rm split/log_2.csv; mkdir split/log_2.csv
expect_fail "log_2.csv" t "$W" drift split --log v2/log.csv --out-dir split
grep -q "a directory" err.txt || fail "split: the message does not say what log_2.csv is: $(cat err.txt)"
grep -q "filesystem error" err.txt && fail "split: raw filesystem error: $(cat err.txt)"
cmp -s split/log_1.csv keep_1.csv || fail "split: log_1.csv replaced although log_2.csv failed"
[ -z "$(debris split)" ] || fail "split left $(debris split)"
rmdir split/log_2.csv
# A symbolic link planted at a target: refused, the link and what it points to left alone.
echo "precious" > victim.txt
rm split/log_1.csv; ln -s ../victim.txt split/log_1.csv
expect_fail "symbolic link" t "$W" drift split --log v2/log.csv --out-dir split
[ -L split/log_1.csv ] && [ "$(cat victim.txt)" = precious ] || fail "split replaced a planted link"
rm split/log_1.csv
# What kill -9 leaves (hidden whirl temporaries of a process that is gone) is removed by the next
# run; the runs the new split no longer writes (log_3) go too.
p=$(dead_pid)
echo half > "split/.log_1.csv.whirl-tmp-$p-1"; mkdir "split/.whirl-stage-$p-2"
head -201 log.csv > two.csv
t "$W" drift split --log two.csv --out-dir split > /dev/null || fail "split after a killed run"
[ -z "$(debris split)" ] || fail "split kept a killed run's $(debris split)"
[ "$(ls split)" = "$(printf 'two_1.csv\ntwo_2.csv')" ] || fail "split kept old runs: $(ls split)"

# machine sensors: the same writer.
t "$W" machine sensors --out-dir msens --idle 1 --cutting 1 > /dev/null || fail "machine sensors"
cp msens/idle_1.csv keep_idle.csv
rm msens/cutting_1.csv; mkdir msens/cutting_1.csv
expect_fail "cutting_1.csv" t "$W" machine sensors --out-dir msens --idle 1 --cutting 1 --machine-seed 2
grep -q "filesystem error" err.txt && fail "sensors: raw filesystem error: $(cat err.txt)"
cmp -s msens/idle_1.csv keep_idle.csv || fail "sensors: idle_1.csv replaced although cutting_1 failed"
rmdir msens/cutting_1.csv; ln -s ../victim.txt msens/cutting_1.csv
expect_fail "symbolic link" t "$W" machine sensors --out-dir msens --idle 1 --cutting 1
[ -L msens/cutting_1.csv ] && [ "$(cat victim.txt)" = precious ] || fail "sensors replaced a link"
rm msens/cutting_1.csv
t "$W" machine sensors --out-dir msens --idle 1 --cutting 1 --machine-seed 2 > /dev/null \
  || fail "machine sensors again"

# drift monitor: the report and --timeline/--events together; a directory at --events stops all.
mkdir evdir
expect_fail "evdir" t "$W" drift monitor --model model.json --run log.csv --out-dir mrep \
  --timeline tl.csv --events evdir
[ -e mrep ] || [ -e tl.csv ] && fail "monitor wrote a report or timeline although --events failed"

# kill -9 in the middle of a report (gnuplot blocks): nothing visible, the next run cleans up.
mkdir fakebin
cat > fakebin/gnuplot <<EOF
#!/bin/sh
case "\$1" in --version|-e) exit 0;; esac
echo \$\$ > "$D/gnuplot.pid"
exec sleep 60
EOF
chmod +x fakebin/gnuplot
"$W" surface synth --out pts.csv > /dev/null || fail "surface synth"
PATH="$D/fakebin:$PATH" "$W" surface fit --points pts.csv --out-dir srep > /dev/null 2>&1 &
wpid=$!
for _ in $(seq 100); do [ -s gnuplot.pid ] && break; sleep 0.1; done
[ -s gnuplot.pid ] || fail "the fake gnuplot never ran"
kill -9 "$wpid"; kill -9 "$(cat gnuplot.pid)"; wait "$wpid" 2> /dev/null
[ -d srep ] || fail "no report directory while gnuplot ran"
[ -z "$(ls srep)" ] || fail "kill -9 left visible report files: $(ls srep)"
[ -n "$(debris srep)" ] || fail "expected the killed run's staging folder in srep"
t "$W" surface fit --points pts.csv --out-dir srep --no-plots > /dev/null || fail "report after kill"
[ -f srep/index.html ] && [ -z "$(debris srep)" ] || fail "rerun did not clean up: $(ls -A srep)"

# --- One rule for every directory output -----------------------------------------------------
mkdir real foreign; ln -s real linkdir; echo mine > foreign/notes.txt
dir_rule() {  # dir_rule <flag> <command...>: a symlinked and a foreign directory are refused
  local flag="$1"; shift
  expect_fail "symbolic link" t "$@" "$flag" linkdir
  grep -q -- "$flag" err.txt || fail "$*: message does not name $flag: $(cat err.txt)"
  [ -z "$(ls -A real)" ] || fail "$*: wrote through the symlinked $flag: $(ls -A real)"
  expect_fail "notes.txt" t "$@" "$flag" foreign
  grep -q "foreign" err.txt || fail "$*: message does not name the directory: $(cat err.txt)"
  [ "$(ls -A foreign)" = notes.txt ] || fail "$*: wrote into a foreign $flag: $(ls -A foreign)"
}
dir_rule --out-dir "$W" drift split --log log.csv
dir_rule --out-dir "$W" machine sensors --idle 1 --cutting 0
dir_rule --out-dir "$W" drift report --train-run log.csv --error ch1_um --sensors t1_C,t2_C
dir_rule --out-dir "$W" drift holdout --log log.csv --channels ch1_um --no-network
dir_rule --out-dir "$W" drift monitor --model model.json --run log.csv
dir_rule --out-dir "$W" ballbar simulate
dir_rule --out-dir "$W" surface fit --points pts.csv --no-plots
dir_rule --curves-dir "$W" dataset --count 1 --out table.csv
dir_rule --out-dir "$W" compare --model "$SRC/models/default.json" \
  --screw "$SRC/datasets/screws/reference_80x10x6000.json" --history "$SRC/datasets/whirling_500.csv"
dir_rule --out-dir "$W" machine evaluate --machines 1 --test-days 1 --past-days 1
dir_rule --out-dir "$W" demo --no-plots
[ -e table.csv ] && fail "dataset wrote its table although --curves-dir was refused"
# Run twice into the same directory: whirl's own output is replaced.
for k in 1 2; do
  t "$W" ballbar simulate --out-dir bb > /dev/null || fail "ballbar simulate run $k"
  t "$W" drift report --train-run log.csv --error ch1_um --sensors t1_C,t2_C --out-dir drep \
    > /dev/null 2>&1 || fail "drift report run $k"
  t "$W" drift monitor --model model.json --run log.csv --out-dir mon > /dev/null 2>&1 \
    || fail "drift monitor run $k"
done
# A file that is not whirl's, added to whirl's output, refuses it and is never removed.
echo mine > bb/notes.txt
expect_fail "notes.txt" t "$W" ballbar simulate --out-dir bb
[ -f bb/notes.txt ] || fail "ballbar simulate removed a foreign file"

# --- No output over an input -----------------------------------------------------------------
cp log.csv run.csv; cp run.csv run_copy.csv; ln -s run.csv alias.csv
cp "$SRC/datasets/screws/reference_80x10x6000.json" screw.json; cp screw.json screw_copy.json
cp model.json model_copy.json
same() {  # same <input copy> <input> <command...>: refused naming the output flag, input unchanged
  local copy="$1" input="$2"; shift 2
  expect_fail "is the input" t "$@"
  cmp -s "$copy" "$input" || fail "$*: overwrote its input $input"
}
same run_copy.csv run.csv "$W" drift predict --model model.json --run run.csv --out ./run.csv
grep -q -- "--out" err.txt && grep -q -- "--run" err.txt || fail "predict: flags not named: $(cat err.txt)"
same run_copy.csv run.csv "$W" drift predict --model model.json --run run.csv --out alias.csv
same model_copy.json model.json "$W" drift nc --model model.json --machine "$M840" --csv ./model.json
grep -q -- "--csv" err.txt && grep -q -- "--model" err.txt || fail "drift nc: flags: $(cat err.txt)"
same screw_copy.json screw.json "$W" plan --screw screw.json --max-elongation-um 30 \
  --settle-time-s 250 --machine "$M840" --out ./screw.json
same run_copy.csv run.csv "$W" drift fit --run run.csv --error ch1_um --out "$D/run.csv"
same run_copy.csv run.csv "$W" drift monitor --model model.json --run run.csv --timeline alias.csv
same model_copy.json model.json "$W" drift predict --model model.json --run run.csv --out model.json
expect_fail "same file" t "$W" plan --screw screw.json --max-elongation-um 30 --settle-time-s 250 \
  --machine "$M840" --nc A.SPF --reset-nc ./A.SPF
[ -e A.SPF ] && fail "plan wrote A.SPF although --nc and --reset-nc are one file"
# An output directory that holds an input: whirl would replace or remove it.
cp split/two_1.csv split_copy.csv
expect_fail "holds the input" t "$W" drift split --log split/two_1.csv --out-dir split
cmp -s split/two_1.csv split_copy.csv || fail "split replaced its own input"
echo "ok"
