#!/usr/bin/env bash
# An installed whirl runs from anywhere: args <build dir> <scratch dir> <source dir>.
# Installs the build to a temporary prefix (cmake --install), moves far from the source tree and
# runs <prefix>/bin/whirl demo: the shipped model, screw, history and ISO table must come from
# <prefix>/share/whirl (the source tree is still on disk, so the output must name the prefix's
# files). Then $WHIRL_HOME overrides both.
set -u
B="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"
source "$SRC/tests/support/cli_common.sh"
P="$D/prefix with space"
cmake --install "$B" --prefix "$P" > "$D/install.log" 2>&1 || fail "cmake --install: $(tail -5 "$D/install.log")"
W="$P/bin/whirl"
[ -x "$W" ] || fail "no $W"
for f in models/default.json datasets/whirling_500.csv datasets/screws/reference_80x10x6000.json \
         datasets/standards/iso3408_3_lead_tolerances.csv; do
  [ -s "$P/share/whirl/$f" ] || fail "not installed: share/whirl/$f"
done
"$W" --help > "$D/help.txt" || fail "whirl --help"
grep -q "WHIRL_HOME" "$D/help.txt" || fail "whirl --help does not document WHIRL_HOME"
"$W" demo --help > "$D/demo_help.txt" || fail "whirl demo --help"
grep -q "WHIRL_HOME" "$D/demo_help.txt" || fail "whirl demo --help does not document WHIRL_HOME"

mkdir -p "$D/elsewhere"; cd "$D/elsewhere"
env -u WHIRL_HOME "$W" demo --no-plots --out-dir out > demo.txt 2> demo.err || fail "installed demo: $(cat demo.err)"
grep -q "summary:" demo.txt || fail "no summary"
grep -q "$P/share/whirl/models/default.json" demo.txt || fail "model not taken from the prefix: $(head -2 demo.txt)"
test -s out/reference_80x10x6000_plan.json || fail "no plan file"
test -s out/report/index.html || fail "no report"

# $WHIRL_HOME overrides: a home without the model is an error naming that home (never a silent
# fallback to another copy).
mkdir -p "$D/home/datasets"
WHIRL_HOME="$D/home" "$W" demo --no-plots --out-dir out2 > /dev/null 2> home.err \
  && fail "demo with an empty WHIRL_HOME succeeded"
grep -q "$D/home/" home.err || fail "error does not name WHIRL_HOME: $(cat home.err)"
echo "ok"
