# Helpers of the lab-script tests (tests/lab/tests.cmake); source it after setting W (build/whirl),
# D (the scratch directory) and S (the source tree). Sets PY: the first of $WHIRL_PYTHON,
# `python3` on PATH and /usr/bin/python3 that imports numpy (the scripts need it: Debian's
# python3-numpy, which scripts/setup.sh installs). None does: the test fails and says so, it never
# skips. scikit-learn is hidden (tests/lab/no_sklearn), as on CI, where setup.sh leaves it out.
source "$S/tests/support/cli_common.sh"
PY=""
for candidate in ${WHIRL_PYTHON:-} python3 /usr/bin/python3; do
  if "$candidate" -c "import numpy" > /dev/null 2>&1; then PY="$candidate"; break; fi
  [ -n "${WHIRL_PYTHON:-}" ] && [ "$candidate" = "$WHIRL_PYTHON" ] \
    && fail "WHIRL_PYTHON=$WHIRL_PYTHON cannot import numpy"
done
[ -n "$PY" ] || fail "no python with numpy (tried ${WHIRL_PYTHON:+$WHIRL_PYTHON, }python3 on PATH" \
  "($(command -v python3 || echo none)) and /usr/bin/python3): install python3-numpy" \
  "(scripts/setup.sh) or set WHIRL_PYTHON"
export PYTHONPATH="$S/tests/lab/no_sklearn"
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
# expect_usage_error <pattern> <command...>: a non-zero exit with the pattern on stderr, and no
# Python traceback (a clear message, not a crash)
expect_usage_error() {
  local pattern="$1"; shift
  "$@" > "$D/out.txt" 2> "$D/err.txt"; local rc=$?
  [ $rc -ne 0 ] || fail "expected a non-zero exit: $*"
  grep -qi -- "$pattern" "$D/err.txt" || fail "message lacks '$pattern': $(cat "$D/err.txt")"
  ! grep -q "Traceback" "$D/err.txt" || fail "a traceback instead of a message: $(cat "$D/err.txt")"
}
# check_py <what> <python code> [args...]: runs the code (sys.argv[1:] = args) in the scratch
# directory; a failed assertion fails the test with <what>
check_py() {
  local what="$1" code="$2"; shift 2
  "$PY" -c "$code" "$@" > "$D/check.txt" 2>&1 || fail "$what: $(cat "$D/check.txt")"
}
