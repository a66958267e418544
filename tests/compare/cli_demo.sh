#!/usr/bin/env bash
# Smoke test of `whirl demo` in a scratch directory: plan files, report, summary with reductions.
set -euo pipefail
whirl="$1"; scratch="$2"
rm -rf "$scratch"; mkdir -p "$scratch"; cd "$scratch"
t0=$(date +%s.%N)
"$whirl" demo --out-dir out > demo.txt
wall=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { print b - a }')
# "done in X s" is the whole run: it stopped the clock before step 7 (about 2 of 6 s).
done_s=$(grep -oE "done in [0-9.]+ s" demo.txt | grep -oE "[0-9.]+")
awk -v d="$done_s" -v w="$wall" 'BEGIN { exit !(d >= 0.8 * w - 0.5 && d <= w + 0.1) }' \
  || { echo "done in $done_s s, but the run took $wall s"; exit 1; }
grep -q "summary:" demo.txt
grep -Eq "% (less|more) than traditional" demo.txt
# A reduction is never negative in words ("model -5 % less"): a larger error says "more than".
if grep -Eq -- "-[0-9.]+ % (less|more)" demo.txt; then echo "negative percentage in words"; exit 1; fi
# The numbered steps print in order (not "3. 4. 3. 4.").
steps=$(grep -oE "^[0-9]+\. " demo.txt | tr -d '. ' | tr '\n' ' ')
sorted=$(grep -oE "^[0-9]+\. " demo.txt | tr -d '. ' | sort -n | tr '\n' ' ')
[ "$steps" = "$sorted" ] || { echo "steps out of order: $steps"; exit 1; }
# The report says what the new-type screw is, not the code's identifier.
if grep -q "compare::" out/report/index.html; then echo "code identifier in the report"; exit 1; fi
for f in reference_80x10x6000_plan.json reference_80x10x6000_plan.csv WHIRL_REFERENCE.SPF \
         new-type_63x12x6000_plan.json report/index.html report/report.json; do
  test -s "out/$f" || { echo "missing out/$f"; exit 1; }
done
grep -q "SA_TEMP_COMP" out/WHIRL_REFERENCE.SPF
head -1 out/WHIRL_REFERENCE.SPF | grep -q "^; WHIRL_REFERENCE: " || { echo "header does not name the program"; exit 1; }
grep -q "call WHIRL_REFERENCE_RESET after" out/WHIRL_REFERENCE.SPF || { echo "reset program not named"; exit 1; }
test -s out/machine_report/index.html || { echo "missing machine report"; exit 1; }
grep -q "both halves on a drifting machine" demo.txt
# A drift program whose short-record mix weighs the grey box 1 is the grey box's own (one
# component): its header must not call it mixed (it said "mixed with warmup (w = 1.00)").
for spf in out/machine_report/WHIRL_DRIFT_*.SPF; do
  if grep -q "^; mixed line of" "$spf"; then
    grep -q "(w = 1\.00)" "$spf" && { echo "$spf: a mixed line with w = 1.00"; exit 1; }
  else
    grep -q "mixed with" "$spf" && { echo "$spf: one component called mixed"; exit 1; }
  fi
done
# Again into the same directory: the demo replaces its own output (core/output_dir.h).
"$whirl" demo --out-dir out --no-plots > demo2.txt
grep -q "summary:" demo2.txt
test -s out/report/index.html && test -s out/machine_report/index.html
if ls out/report/*.png > /dev/null 2>&1; then echo "old figures beside a page without plots"; exit 1; fi

echo OK
