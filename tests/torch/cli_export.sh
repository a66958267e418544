#!/usr/bin/env bash
# Smoke test of 'whirl export': usage <whirl> <scratch> <source dir> <torch_make_model>
set -euo pipefail
WHIRL="$1"; SCRATCH="$2"; MAKE_MODEL="$4"
rm -rf "$SCRATCH"; mkdir -p "$SCRATCH"; cd "$SCRATCH"
"$MAKE_MODEL" model.json table.csv

"$WHIRL" export --help | grep "original units" > /dev/null

"$WHIRL" export --model model.json --torchscript out.pt | tee export.txt
[ -s out.pt ] || { echo "out.pt missing"; exit 1; }
grep -q "max relative difference" export.txt
# TorchScript files are zip archives holding the code of forward().
python3 - <<'PY'
import zipfile
z = zipfile.ZipFile("out.pt")
code = "".join(z.read(n).decode("utf-8", "replace") for n in z.namelist() if n.endswith(".py"))
assert "def forward" in code and "tanh" in code, code
PY
# Only the output file and the inputs remain (no temporary files).
[ "$(ls -A | sort | tr '\n' ' ')" = "export.txt model.json out.pt table.csv " ] || { ls -A; exit 1; }

"$WHIRL" export --model model.json --torchscript out2.pt --json > export.json
python3 -c "import json; r = json.load(open('export.json')); assert r['written'] and r['max_relative_difference'] <= 1e-12, r"

# A directory that does not exist: exit 1, nothing written.
set +e
"$WHIRL" export --model model.json --torchscript missing/out.pt 2> err.txt
rc=$?
set -e
[ "$rc" -eq 1 ] || { echo "expected exit 1, got $rc"; exit 1; }
grep -q "missing" err.txt
[ ! -e missing ]
echo "cli_export ok"
