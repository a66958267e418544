# Helpers for the command-line smoke tests; source it after setting D (the scratch directory).
fail() { echo "FAIL: $*"; exit 1; }
expect_fail() {  # expect_fail <pattern> <command...>: exit code 1 and 'error:' + pattern on stderr
  local pattern="$1"; shift
  "$@" > "$D/out.txt" 2> "$D/err.txt"; local rc=$?
  [ $rc -eq 1 ] || fail "expected exit 1, got $rc: $*"
  grep -q "error" "$D/err.txt" || fail "no error message: $*"
  grep -qi -- "$pattern" "$D/err.txt" || fail "message lacks '$pattern': $(cat "$D/err.txt")"
}
expect_jumps_to_end() {  # expect_jumps_to_end <file>: an NC program whose every SETAL is followed
  # by "GOTOF WHIRL_END", the label just before its M17 (it changes nothing after a failed check)
  awk '/^SETAL\(/ { n++; if ((getline next_line) <= 0 || next_line != "GOTOF WHIRL_END") bad = 1 }
       END { exit (bad || n == 0) }' "$1" || fail "$1: a SETAL not followed by GOTOF WHIRL_END"
  [ "$(tail -n 2 "$1" | tr '\n' ' ')" = "WHIRL_END: M17 " ] || fail "$1: no WHIRL_END: before M17"
}
without_torch() {  # without_torch <command words...>: true for a command that runs whirl-torch in a
  # build without it (-DWHIRL_WITH_TORCH=OFF, e.g. scripts/sanitize.sh): its --help is whirl-torch's
  case "$1" in crosscheck | export) [ ! -x "$(dirname "$W")/whirl-torch" ] ;; *) return 1 ;; esac
}
