#!/usr/bin/env bash
# Installs everything whirl needs to build, test, benchmark and plot, from Debian packages.
# Idempotent and non-interactive; runs as root (or through sudo when not root).
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev nlohmann-json3-dev libcli11-dev
  googletest libgtest-dev libgmock-dev libbenchmark-dev
  libtorch-dev
  gnuplot-nox fonts-liberation   # report plots (pngcairo needs a font; a Recommends of gnuplot-nox)
  libboost-dev                   # Boost.Math (header-only): F-distribution quantile of the drift selection
  python3                        # the command-line tests read JSON outputs with it
  python3-numpy                  # the lab's scripts (scripts/*.py) and their tests (tests/lab)
  # tests/compare/cli_report_render.sh renders every report in it (skipped without). Measured on
  # Debian 12: 10 packages, about 280 MB installed, 35 s to download and install; the test takes
  # about 15 s (most of it the demo that writes the reports).
  chromium-headless-shell
)
# Only for scripts/bench_peers.sh (the peer benchmark), never for the default build or tests.
if [ "${WHIRL_SETUP_BENCH_PEERS:-0}" = 1 ]; then packages+=(python3-sklearn); fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages already installed" >&2
  exit 0
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "setup: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
