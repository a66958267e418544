#!/usr/bin/env bash
# The grey box (both_grey, drift/grey_box.h) against the strongest sensor-free rule of each field
# scenario, per length of the shop's history, in the project's simulator only (issue 41's
# acceptance): thread medians over the seeds, 4 machines, 3 test days each.
# Usage: scripts/grey_acceptance.sh [--weeks "1 2 4 8"] [--seeds 5] [--first-seed 1]
#                                   [--threads 2] [--scenarios production,duty-changes,...]
#                                   [--out-dir DIR] [--slope-through-lags-only]
# Seeds S..S+N-1 with S = --first-seed (default 1) and N = --seeds (1..20): a confirmation run
# takes seeds no tuning run has used (e.g. --first-seed 101).
# A week is 5 production days of history (--past-days 5 x weeks; at most 8 weeks = 40 days). Writes DIR/weeks_<w>.md (the evaluation's
# Markdown) and prints one table: per weeks and scenario the strongest sensor-free row and its
# thread median, both_shop, both_grey, the gain of both_grey (1 - grey / sensor-free), the seeds
# in which it left less, and the criterion of issue 41 (30 % and every seed for
# unconditioned-hall and interrupted-starts after 1 week; for production and duty-changes never
# worse after 1 week and 30 % after 8). --slope-through-lags-only: both_grey with its slope sensors
# through their lags only (whirl machine evaluate's flag; an opt-in candidate, off by default).
set -euo pipefail
cd "$(dirname "$0")/.."
weeks="1"
seeds=5
first_seed=1
threads=2
scenarios="production,duty-changes,interrupted-starts,unconditioned-hall"
out_dir=""
candidate=()
while [ $# -gt 0 ]; do
  case "$1" in
    --weeks) weeks="$2"; shift 2 ;;
    --seeds) seeds="$2"; shift 2 ;;
    --first-seed) first_seed="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    --scenarios) scenarios="$2"; shift 2 ;;
    --out-dir) out_dir="$2"; shift 2 ;;
    --slope-through-lags-only) candidate=(--slope-through-lags-only); shift ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    *) echo "grey_acceptance.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[[ "$first_seed" =~ ^[1-9][0-9]{0,8}$ ]] ||
  { echo "grey_acceptance.sh: --first-seed holds '$first_seed': must be an integer 1..999999999" >&2
    exit 2; }
[[ "$seeds" =~ ^[1-9][0-9]?$ ]] && [ "$seeds" -le 20 ] ||
  { echo "grey_acceptance.sh: --seeds holds '$seeds': must be an integer 1..20" >&2; exit 2; }
for w in $weeks; do
  case "$w" in
    [1-8]) ;;
    *) echo "grey_acceptance.sh: --weeks holds '$w': each must be 1..8 (5 x weeks <= 40 days)" >&2
       exit 2 ;;
  esac
done
whirl="${WHIRL_BUILD_DIR:-build}/whirl"
[ -x "$whirl" ] || { echo "grey_acceptance.sh: $whirl not built (scripts/build.sh)" >&2; exit 2; }
[ -n "$out_dir" ] || out_dir="$(mktemp -d)"
mkdir -p "$out_dir"
for w in $weeks; do
  "$whirl" machine evaluate --scenarios "$scenarios" --seed "$first_seed" --seeds "$seeds" --machines 4 \
    --test-days 3 --past-days $((5 * w)) --threads "$threads" --markdown \
    ${candidate[@]+"${candidate[@]}"} \
    > "$out_dir/weeks_$w.md" 2> "$out_dir/weeks_$w.log"
done
python3 - "$out_dir" $weeks <<'PY'
import re, sys
out_dir, weeks = sys.argv[1], sys.argv[2:]
print("| weeks | scenario | strongest sensor-free (thread median um) | both_shop um | both_grey um "
      "| gain of both_grey | seeds better | criterion | holds |")
print("|---|---|---|---|---|---|---|---|---|")
for w in weeks:
    text = open(f"{out_dir}/weeks_{w}.md").read()
    rows = {}
    for m in re.finditer(r"^\| ([a-z-]+) \| ([a-z_]+) \| [^|]+ \| [^|]+ \| ([0-9.]+) \[", text, re.M):
        rows[(m.group(1), m.group(2))] = float(m.group(3))
    for m in re.finditer(r"^- ([a-z-]+): the strongest sensor-free strategy is ([a-z_]+) "
                         r"\(thread median ([0-9.]+) um", text, re.M):
        sc, best, med = m.group(1), m.group(2), float(m.group(3))
        v = re.search(rf"^- {sc}: both_grey \(sensors\) (?:beats|does NOT beat) the strongest "
                      r"sensor-free strategy [a-z_]+ over the thread (?:by )?\(?([-+0-9.]+) %"
                      r"(?:;)? ?\(?better in (\d+) of (\d+) seeds\)", text, re.M)
        gain, won, n = float(v.group(1)), int(v.group(2)), int(v.group(3))
        if sc in ("unconditioned-hall", "interrupted-starts"):
            crit = ">= 30 %, every seed (1 week)" if w == "1" else "-"
            ok = (gain >= 30 and won == n) if w == "1" else None
        elif sc in ("production", "duty-changes"):
            if w == "1":
                crit, ok = "not worse, every seed (1 week)", gain >= 0 and won == n
            elif w == "8":
                crit, ok = ">= 30 % (8 weeks)", gain >= 30
            else:
                crit, ok = "-", None
        else:
            crit, ok = "-", None
        holds = "-" if ok is None else ("yes" if ok else "NO")
        print(f"| {w} | {sc} | {best} {med:.1f} | {rows.get((sc, 'both_shop'), float('nan')):.1f} "
              f"| {rows.get((sc, 'both_grey'), float('nan')):.1f} | {gain:+.1f} % | {won} of {n} "
              f"| {crit} | {holds} |")
PY
echo "(simulator only; seeds $first_seed..$((first_seed + seeds - 1))${candidate[@]+; both_grey with ${candidate[*]}}; the evaluations' tables: $out_dir)"
