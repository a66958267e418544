#!/usr/bin/env bash
# Smoke test of 'whirl crosscheck': usage <whirl> <scratch> <source dir> <torch_make_model>
set -euo pipefail
WHIRL="$1"; SCRATCH="$2"; MAKE_MODEL="$4"
rm -rf "$SCRATCH"; mkdir -p "$SCRATCH"; cd "$SCRATCH"
"$MAKE_MODEL" model.json table.csv

"$WHIRL" crosscheck --help | grep "1e-12" > /dev/null

# Human table: every figure ok, exit 0.
"$WHIRL" crosscheck --model model.json --data table.csv > table.txt
cat table.txt
for f in forward forward_original_units jacobian objective gradient training_objective training_prediction; do
  grep -Eq "^$f +[^ ]+ +[^ ]+ +ok " table.txt || { echo "figure $f missing or failed"; exit 1; }
done

# JSON: valid, passed, seven figures.
"$WHIRL" crosscheck --model model.json --data table.csv --json > report.json
python3 - <<'PY'
import json
r = json.load(open("report.json"))
assert r["passed"] is True, r
assert len(r["figures"]) == 7
assert all(f["passed"] and f["value"] <= f["tolerance"] for f in r["figures"])
PY

# A tolerance that cannot be met: exit code 2 (the check ran and failed).
set +e
"$WHIRL" crosscheck --model model.json --data table.csv --prediction-tolerance 1e-300 > /dev/null 2> fail.txt
rc=$?
set -e
[ "$rc" -eq 2 ] || { echo "expected exit 2, got $rc"; exit 1; }
grep -q "failed" fail.txt

# Bad input: a table without targets -> exit 1 with an error naming the file.
grep -v '^#' table.csv | cut -d, -f1-5 > inputs_only.csv
set +e
"$WHIRL" crosscheck --model model.json --data inputs_only.csv 2> err.txt
rc=$?
set -e
[ "$rc" -eq 1 ] || { echo "expected exit 1, got $rc"; exit 1; }
grep -q "inputs_only.csv" err.txt
echo "cli_crosscheck ok"
