# Helpers for the command-line smoke tests; source it after setting D (the scratch directory).
fail() { echo "FAIL: $*"; exit 1; }
expect_fail() {  # expect_fail <pattern> <command...>: exit code 1 and 'error:' + pattern on stderr
  local pattern="$1"; shift
  "$@" > "$D/out.txt" 2> "$D/err.txt"; local rc=$?
  [ $rc -eq 1 ] || fail "expected exit 1, got $rc: $*"
  grep -q "error" "$D/err.txt" || fail "no error message: $*"
  grep -qi -- "$pattern" "$D/err.txt" || fail "message lacks '$pattern': $(cat "$D/err.txt")"
}
