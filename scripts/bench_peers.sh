#!/usr/bin/env bash
# Peer benchmark of whirl's workpiece models: Friedman #1 plus a second smooth output (20 and 100
# training rows, 1000 test rows), the simulator's shipped tables (train 20, test 500), generated
# simulator tables (simgen: 20 and 100 rows per seed, test 500) and generator families (power
# laws with and without bends, additive, Friedman #2/#3, interacting terms; --split tuning or
# --split confirmation selects the suite's two parts), whirl train (and, with
# --family-bench build/tests/family_bench --family NAME=ARGS, the family library) against
# scikit-learn's MLPRegressor (default and grid-searched), LinearRegression, RidgeCV, the power law
# (LinearRegression on log inputs and log outputs) and Gaussian processes (ARD and isotropic RBF
# kernels); prints
# median test RMSE per output, wins, interval coverage and fit time. The functions, noise and
# peers are documented in scripts/bench_peers.py.
# Installs Debian's python3-sklearn on first use (only here: the default setup and tests never need it).
# Usage: scripts/bench_peers.sh [SEEDS (default 20)] [extra bench_peers.py arguments, e.g.
#        --split tuning --sizes 8,20,100 --peer-cache peers.json --json bench.json]
#   WHIRL=<path to whirl> overrides the binary (default: ${WHIRL_BUILD_DIR:-build}/whirl).
set -euo pipefail
cd "$(dirname "$0")/.."
WHIRL="${WHIRL:-${WHIRL_BUILD_DIR:-build}/whirl}"
SEEDS="${1:-20}"
shift || true
if [ ! -x "$WHIRL" ]; then
  echo "bench_peers: '$WHIRL' not found; build first (scripts/build.sh) or set WHIRL" >&2
  exit 1
fi
PYTHON="${PYTHON:-/usr/bin/python3}"  # Debian's interpreter: python3-sklearn installs there
if ! "$PYTHON" -c "import sklearn, numpy" 2>/dev/null; then
  WHIRL_SETUP_BENCH_PEERS=1 scripts/setup.sh
fi
exec "$PYTHON" scripts/bench_peers.py --whirl "$WHIRL" --seeds "$SEEDS" "$@"
