#!/usr/bin/env bash
# Smoke test of `whirl demo` in a scratch directory: plan files, report, summary with reductions.
set -euo pipefail
whirl="$1"; scratch="$2"
rm -rf "$scratch"; mkdir -p "$scratch"; cd "$scratch"
"$whirl" demo --out-dir out > demo.txt
grep -q "summary:" demo.txt
grep -q "% less" demo.txt
for f in reference_80x10x6000_plan.json reference_80x10x6000_plan.csv WHIRL_REFERENCE.SPF \
         new-type_63x12x6000_plan.json report/index.html report/report.json; do
  test -s "out/$f" || { echo "missing out/$f"; exit 1; }
done
grep -q "SA_TEMP_COMP" out/WHIRL_REFERENCE.SPF
head -1 out/WHIRL_REFERENCE.SPF | grep -q "^; WHIRL_REFERENCE: " || { echo "header does not name the program"; exit 1; }
grep -q "call WHIRL_REFERENCE_RESET after" out/WHIRL_REFERENCE.SPF || { echo "reset program not named"; exit 1; }
test -s out/machine_report/index.html || { echo "missing machine report"; exit 1; }
grep -q "both halves on a drifting machine" demo.txt
# Again into the same directory: the demo replaces its own output (core/output_dir.h).
"$whirl" demo --out-dir out --no-plots > demo2.txt
grep -q "summary:" demo2.txt
test -s out/report/index.html && test -s out/machine_report/index.html
if ls out/report/*.png > /dev/null 2>&1; then echo "old figures beside a page without plots"; exit 1; fi

echo OK
