#!/usr/bin/env bash
# What whirl prints never carries a terminal control from user input (src/cli/terminal.h):
# args <whirl> <scratch dir> <source dir>. A run file whose sensor header and a data field hold
# ESC sequences (set colour, set window title, clear screen) and the C1 CSI byte pair.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"
source "$SRC/tests/support/cli_common.sh"

ESC=$'\033'
HOSTILE="a${ESC}]0;pwned${ESC}\\${ESC}[2J$(printf '\302\233')31m_C"
{
  echo "time_min,${HOSTILE},b_C,err_um"
  awk 'BEGIN { for (k = 0; k < 60; k++) {
    A = 8 * (1 - exp(-k / 30)); B = k / 40;
    printf "%d,%.4f,%.4f,%.4f\n", k, 20 + A, 21 + B, 2 * A - 1.5 * B + 0.1 * sin(7 * k) } }'
} > "$D/run.csv"
has_control() {  # has_control <file>: ESC, BEL or the UTF-8 C1 CSI anywhere in the file
  LC_ALL=C grep -q "$(printf '[\033\007]')" "$1" && return 0
  LC_ALL=C grep -q "$(printf '\302\233')" "$1"
}

# 1. stdout and stderr to files: the fit prints the sensor names; no control byte arrives, and
#    the name is shown with visible escapes.
"$W" drift fit --run "$D/run.csv" --error err_um --sensors "$HOSTILE,b_C" --out "$D/m.json" \
  > "$D/out.txt" 2> "$D/err.txt" || fail "fit: $(cat "$D/err.txt")"
has_control "$D/out.txt" && fail "stdout carries a terminal control"
has_control "$D/err.txt" && fail "stderr carries a terminal control"
grep -qF 'a\x1B]0;pwned\x1B\\x1B[2J\u009B31m_C' "$D/out.txt" || fail "name not shown escaped: $(cat "$D/out.txt")"
# The model file is data: it keeps the header exactly (JSON escapes it).
grep -qF '\u001b]0;pwned' "$D/m.json" || fail "model file lost the column name"

# 2. An error quoting a hostile data field.
sed "3s/^1,[^,]*,/1,2${ESC}[31mX,/" "$D/run.csv" > "$D/bad.csv"
expect_fail 'is not a number' "$W" drift fit --run "$D/bad.csv" --error err_um --out "$D/m2.json"
has_control "$D/err.txt" && fail "error message carries a terminal control"
grep -qF '2\x1B[31mX' "$D/err.txt" || fail "field not shown escaped: $(cat "$D/err.txt")"
[ -e "$D/m2.json" ] && fail "a failed fit left a model file"

# 3. On a real terminal (a pty from util-linux 'script'), stdout and stderr together.
if command -v script > /dev/null 2>&1; then
  script -qec "'$W' drift fit --run '$D/run.csv' --error err_um --sensors '$HOSTILE,b_C' \
    --out '$D/m3.json'; '$W' drift fit --run '$D/bad.csv' --error err_um --out '$D/m4.json'" \
    /dev/null > "$D/tty.txt" 2>&1 < /dev/null
  [ -s "$D/tty.txt" ] || fail "no output on the pty"
  has_control "$D/tty.txt" && fail "the terminal received a control: $(od -c "$D/tty.txt" | head)"
  grep -qF '\x1B[31mX' "$D/tty.txt" || fail "pty: error not shown escaped"
fi
echo "cli_terminal: ok"
