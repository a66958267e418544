#!/usr/bin/env bash
# Every numeric flag of every subcommand refuses nan, inf, 1e999 and -inf (exit 1, the flag named
# on stderr) and shows its range and its default (or that it has none) in --help (the one validator of numeric flags, cli/common.h
# NumberIn, or a list of allowed values): args <whirl> <scratch dir> <source dir>. The flags are
# found by walking --help (an option whose type is FLOAT, INT or UINT), so a new flag or
# subcommand is covered without touching this test. KEEP_GOING=1 lists every failure instead of
# stopping at the first.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"
source "$SRC/tests/support/cli_common.sh"

# The subcommand names listed under "Subcommands:" in a --help text on stdin.
subcommands() {
  awk '/^Subcommands:/ {on = 1; next} on && /^  [a-z][a-z0-9-]* / {print $1}'
}
# The numeric flags in a --help text on stdin: "--name FLOAT...", "--name INT...", "--name UINT...".
numeric_flags() {
  grep -oE -- '^ +(-[a-zA-Z],)?--[a-z0-9-]+ +(FLOAT|INT|UINT)([: ]|$)' | grep -oE -- '--[a-z0-9-]+'
}

failures=0
check_flag() {  # check_flag <flag> <command words...>
  local flag="$1"; shift
  for value in nan inf 1e999 -inf; do
    "$W" "$@" "$flag" "$value" > "$D/out.txt" 2> "$D/err.txt"; local rc=$?
    if [ $rc -ne 1 ] || ! grep -q -- "$flag" "$D/err.txt"; then
      echo "FAIL: whirl $* $flag $value: exit $rc, stderr: $(head -c 300 "$D/err.txt")"
      failures=$((failures + 1))
      [ "${KEEP_GOING:-0}" = 1 ] || exit 1
    fi
  done
}

# Numeric option lines of a --help text on stdin without a range or a list after the type.
without_range() {
  grep -E -- '^ +(-[a-zA-Z],)?--[a-z0-9-]+ +(FLOAT|INT|UINT)([: ]|$)' |
    grep -vE -- '(FLOAT|INT|UINT):([[({]|>=? |finite)'
}

# Numeric options of a --help text on stdin (the option line joined with its continuation lines)
# that show no default: neither CLI11's "=value" after the range, nor the word "default" (or "no
# default"), nor REQUIRED / "required", nor "instead of" or "Excludes:" another flag. A user reads
# what the command does without the flag from its help.
without_default() {
  awk '/^ +(-[a-zA-Z],)?--[a-z0-9-]+ / { if (o != "") print o; o = $0; next }
       /^                    +[^ ]/ && o != "" { o = o " " $0; next } { if (o != "") print o; o = "" }
       END { if (o != "") print o }' |
    grep -E -- '^ +(-[a-zA-Z],)?--[a-z0-9-]+ +(FLOAT|INT|UINT)([: ]|$)' |
    grep -vE -- '[^ ]=[^ ]|[Dd]efault|REQUIRED|required|instead of|Excludes:' | sed -E 's/ +/ /g'
}

report_lines() {  # report_lines WHAT: one failure per non-empty line on stdin
  local line
  while IFS= read -r line; do
    [ -n "$line" ] || continue
    echo "FAIL: $1: $line"
    failures=$((failures + 1))
    [ "${KEEP_GOING:-0}" = 1 ] || exit 1
  done
}

walk() {  # walk <command words...>: checks the command's flags, then its subcommands'
  local flag sub help
  if without_torch "$@"; then echo "skipped: whirl $* (no whirl-torch in this build)"; return; fi
  help=$("$W" "$@" --help) || fail "whirl $* --help failed"
  report_lines "whirl $*: no range in --help" <<< "$(without_range <<< "$help")"
  report_lines "whirl $*: no default in --help" <<< "$(without_default <<< "$help")"
  for flag in $(numeric_flags <<< "$help"); do
    check_flag "$flag" "$@"
    checked=$((checked + 1))
  done
  for sub in $(subcommands <<< "$help"); do walk "$@" "$sub"; done
}

checked=0
for sub in $("$W" --help | subcommands); do walk "$sub"; done
[ "$failures" -eq 0 ] || fail "$failures flag values accepted or refused without naming the flag"
# The walk itself must find the flags: plan alone has more than ten numeric ones.
[ "$checked" -gt 50 ] || fail "only $checked numeric flags found: has the --help format changed?"
[ -n "$("$W" plan --help | numeric_flags | grep -x -- --tolerance-um)" ] || fail "plan --tolerance-um not found"
echo "checked $checked numeric flags"
