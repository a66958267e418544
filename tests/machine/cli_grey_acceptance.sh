#!/usr/bin/env bash
# Smoke test of scripts/grey_acceptance.sh (issue 41's acceptance table): --help, bad arguments
# refused with exit 2 and a message naming the argument, and the evaluation's --past-days range
# (1..40: 8 weeks) enforced with a clear error. The table itself takes minutes (not run here).
set -u
W="$1"; D="$2"; S="$3"
rm -rf "$D"; mkdir -p "$D"
source "$S/tests/support/cli_common.sh"
G="$S/scripts/grey_acceptance.sh"
bash "$G" --help > "$D/help.txt" || fail "--help"
grep -q "thread medians" "$D/help.txt" || fail "--help does not say what is measured"
bash "$G" --weeks 9 > "$D/out.txt" 2> "$D/err.txt"; rc=$?
[ $rc -eq 2 ] || fail "--weeks 9: expected exit 2, got $rc"
grep -q "'9'" "$D/err.txt" && grep -q "1..8" "$D/err.txt" || fail "--weeks 9: $(cat "$D/err.txt")"
bash "$G" --frobnicate > "$D/out.txt" 2> "$D/err.txt"; rc=$?
[ $rc -eq 2 ] && grep -q "frobnicate" "$D/err.txt" || fail "unknown argument not named"
bash "$G" --first-seed 0 > "$D/out.txt" 2> "$D/err.txt"; rc=$?
[ $rc -eq 2 ] && grep -q "first-seed" "$D/err.txt" || fail "--first-seed 0 accepted"
bash "$G" --seeds 21 > "$D/out.txt" 2> "$D/err.txt"; rc=$?
[ $rc -eq 2 ] && grep -q "1..20" "$D/err.txt" || fail "--seeds 21 accepted"
# --first-seed reaches the evaluation: a stand-in whirl records its arguments.
mkdir -p "$D/fake"
printf '#!/usr/bin/env bash\necho "$*" >> "%s/args.txt"\n' "$D" > "$D/fake/whirl"
chmod +x "$D/fake/whirl"
WHIRL_BUILD_DIR="$D/fake" bash "$G" --first-seed 101 --seeds 3 --weeks "1 8" --out-dir "$D/o" \
  > "$D/out.txt" 2> "$D/err.txt" || fail "stand-in run: $(cat "$D/err.txt")"
[ "$(grep -c -- "--seed 101 --seeds 3 " "$D/args.txt")" -eq 2 ] || fail "seeds: $(cat "$D/args.txt")"
grep -q -- "--past-days 40 " "$D/args.txt" || fail "8 weeks: $(cat "$D/args.txt")"
grep -q "seeds 101..103" "$D/out.txt" || fail "the seeds are not reported: $(cat "$D/out.txt")"
expect_fail "past-days" "$W" machine evaluate --past-days 41 --machines 1 --test-days 1
echo "cli_grey_acceptance: ok"
