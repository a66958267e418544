#!/usr/bin/env bash
# The FL_THERMAL target's settings are chosen before the test window: scripts/fl_thermal_moonshot.sh
# run on the log and on a copy whose rows from the test window on are perturbed (+40 um on the
# three scored channels, +3 K on every temperature) prints the same validation table and the same
# chosen setting, while its test figures move. Needs the shared data (../shared beside the source,
# or WHIRL_FL_THERMAL): skipped (exit 77) without it unless WHIRL_REQUIRE_SHARED_DATA=1.
# Usage: cli_fl_moonshot.sh <whirl binary> <scratch dir> <source dir> [quick|full]
# quick (the default test run): 3 of the 8 settings, one of them with refit measurements; full
# (label slow): the script's whole grid.
set -uo pipefail
W="$1" D="$2" SRC="$3" GRID="${4:-quick}"
[ "$GRID" = quick ] && export MOONSHOT_SETTINGS="auto/default/0 sensors/default/0 sensors/prior100/3"
source "$SRC/tests/support/cli_common.sh"
DATA="${WHIRL_FL_THERMAL:-$SRC/../shared/data/fl_thermal/data.csv}"
if [ ! -f "$DATA" ]; then
  [ "${WHIRL_REQUIRE_SHARED_DATA:-}" = 1 ] && fail "FL_THERMAL data absent: $DATA"
  echo "NOTE: FL_THERMAL data absent ($DATA): skipped"
  exit 77
fi
rm -rf "$D" && mkdir -p "$D"
n=$(($(wc -l < "$DATA") - 1))
awk -F, -v from=$((n * 6 / 10)) 'NR == 1 { print; next }
  { if (NR - 2 >= from) { for (i = 1; i <= NF; i++)
      if (i == 3 || i == 5 || i == 7) $i += 40; else if (i > 7) $i += 3 }
    print }' OFS=, "$DATA" > "$D/perturbed.csv"
cmp -s "$DATA" "$D/perturbed.csv" && fail "the perturbation changed nothing"
WHIRL_BIN="$W" bash "$SRC/scripts/fl_thermal_moonshot.sh" "$DATA" "$D/a" > "$D/a.txt" 2>&1 ||
  fail "moonshot script on the log: $(cat "$D/a.txt")"
WHIRL_BIN="$W" bash "$SRC/scripts/fl_thermal_moonshot.sh" "$D/perturbed.csv" "$D/b" > "$D/b.txt" 2>&1 ||
  fail "moonshot script on the perturbed log: $(cat "$D/b.txt")"
grep -q '^chosen: ' "$D/a.txt" || fail "no chosen setting: $(cat "$D/a.txt")"
rows=$([ "$GRID" = quick ] && echo 3 || echo 8)
[ "$(grep -c '^   .*mean' "$D/a.txt")" = "$rows" ] || fail "the validation table has not $rows rows"
diff <(sed -n '1,/^chosen: /p' "$D/a.txt") <(sed -n '1,/^chosen: /p' "$D/b.txt") > "$D/diff.txt" ||
  fail "the choice depends on the test window: $(cat "$D/diff.txt")"
cmp -s <(grep '^test ' "$D/a.txt") <(grep '^test ' "$D/b.txt") &&
  fail "the test figures did not move: the perturbation missed the test window"
echo "OK: $(grep '^chosen: ' "$D/a.txt")"
