#!/usr/bin/env bash
# The grey box (both_grey, drift/grey_box.h) against the strongest sensor-free rule of each field
# scenario, per length of the shop's history, in the project's simulator only (issue 41's
# acceptance): thread medians over the seeds, 4 machines, 3 test days each.
# Usage: scripts/grey_acceptance.sh [--weeks "1 2 4 8"] [--seeds 5] [--first-seed 1]
#                                   [--threads 2] [--scenarios production,duty-changes,...]
#                                   [--out-dir DIR] [--slope-through-lags-only]
#                                   [--offset-candidates] [--grey-candidates]
#                                   [--grey-five-sensors] [--grey-without-short-mix]
# Seeds S..S+N-1 with S = --first-seed (default 1) and N = --seeds (1..20): a confirmation run
# takes seeds no tuning run has used (e.g. --first-seed 101).
# A week is 5 production days of history (--past-days 5 x weeks; at most 8 weeks = 40 days). Writes DIR/weeks_<w>.md (the evaluation's
# Markdown) and prints one table: per weeks and scenario the strongest sensor-free row and its
# thread median, both_shop, both_grey, the gain of both_grey (1 - grey / sensor-free), the seeds
# in which it left less, and the criterion of issue 41 (30 % and every seed for
# unconditioned-hall and interrupted-starts after 1 week; for production and duty-changes never
# worse after 1 week and 30 % after 8). --slope-through-lags-only: both_grey with its slope sensors
# through their lags only (whirl machine evaluate's flag; an opt-in candidate, off by default).
# --offset-candidates: the evaluation's opt-in rows too (grey_warmup_k0, grey_mean_k0: both_grey's
# slope with warmup's offset or the mean of both offsets), judged like both_grey, one table row
# each beside both_grey's, with the per-seed range of the gain.
# --grey-candidates: the opt-in grey rows (grey_all_sensors: every sensor on both channels;
# grey_sensors_by_days: grey_all_sensors' model from 20 lead days in the record, both_grey's
# before; grey_short_prior: both_grey with the prior strength fixed at 1 below 20 lead days;
# grey_short_offset_as_read / grey_short_offset_one_lag: both_grey with the offset sensors as read
# / through the shortest chosen lag below 20 lead days;
# grey_guarded: both_grey or the sensor-free base rule, chosen on the shop's own last two lead
# days; grey_short_mix / grey_short_mix_fixed: below 20 lead days the line w both_grey + (1 - w)
# the base rule, w from those two lead days clamped to [0.5, 1] / fixed at 0.75), judged and
# tabled the same way.
# --grey-five-sensors: both_grey with its five physical sensors on every record (the model before
# the eleventh round, which takes every sensor from 20 lead days on), so older figures reproduce.
# --grey-without-short-mix: both_grey as the grey box's line alone below 20 lead days (the default
# before the fourteenth round's adoption of grey_short_mix), so older figures reproduce.
set -euo pipefail
cd "$(dirname "$0")/.."
weeks="1"
seeds=5
first_seed=1
threads=2
scenarios="production,duty-changes,interrupted-starts,unconditioned-hall"
out_dir=""
candidate=()
rows="both_grey"
while [ $# -gt 0 ]; do
  case "$1" in
    --weeks) weeks="$2"; shift 2 ;;
    --seeds) seeds="$2"; shift 2 ;;
    --first-seed) first_seed="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    --scenarios) scenarios="$2"; shift 2 ;;
    --out-dir) out_dir="$2"; shift 2 ;;
    --slope-through-lags-only) candidate+=(--slope-through-lags-only); shift ;;
    --grey-five-sensors) candidate+=(--grey-five-sensors); shift ;;
    --grey-without-short-mix) candidate+=(--grey-without-short-mix); shift ;;
    --offset-candidates) candidate+=(--offset-candidates); rows="both_grey,grey_warmup_k0,grey_mean_k0"
                         shift ;;
    --grey-candidates) candidate+=(--grey-candidates); rows="both_grey,grey_all_sensors,grey_sensors_by_days,grey_short_prior,grey_short_offset_as_read,grey_short_offset_one_lag,grey_guarded,grey_short_mix,grey_short_mix_fixed"
                       shift ;;
    -h|--help) sed -n '2,30p' "$0"; exit 0 ;;
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
python3 - "$out_dir" "$rows" $weeks <<'PY'
import re, sys
out_dir, judged, weeks = sys.argv[1], sys.argv[2].split(","), sys.argv[3:]
several = len(judged) > 1
if several:
    print("| weeks | scenario | row | strongest sensor-free (thread median um) | both_shop um | row um "
          "| gain of the row (per seed) | seeds better | criterion | holds |")
    print("|---|---|---|---|---|---|---|---|---|---|")
else:
    print("| weeks | scenario | strongest sensor-free (thread median um) | both_shop um | both_grey um "
          "| gain of both_grey | seeds better | criterion | holds |")
    print("|---|---|---|---|---|---|---|---|---|")
def criterion(sc, w, gain, won, n):
    if sc in ("unconditioned-hall", "interrupted-starts"):
        return (">= 30 %, every seed (1 week)", gain >= 30 and won == n) if w == "1" else ("-", None)
    if sc in ("production", "duty-changes"):
        if w == "1":
            return "not worse, every seed (1 week)", gain >= 0 and won == n
        if w == "8":
            return ">= 30 % (8 weeks)", gain >= 30
    return "-", None
for w in weeks:
    text = open(f"{out_dir}/weeks_{w}.md").read()
    rows = {}
    for m in re.finditer(r"^\| ([a-z-]+) \| ([a-z0-9_]+) \| [^|]+ \| [^|]+ \| ([0-9.]+) \[", text, re.M):
        rows[(m.group(1), m.group(2))] = float(m.group(3))
    for m in re.finditer(r"^- ([a-z-]+): the strongest sensor-free strategy is ([a-z_]+) "
                         r"\(thread median ([0-9.]+) um", text, re.M):
        sc, best, med = m.group(1), m.group(2), float(m.group(3))
        for row in judged:
            v = re.search(rf"^- {sc}: {row} \(sensors\) (?:beats|does NOT beat) the strongest "
                          r"sensor-free strategy [a-z_]+ over the thread (?:by )?\(?([-+0-9.]+) %"
                          r"(?:;)? ?\(?better in (\d+) of (\d+) seeds\)", text, re.M)
            gain, won, n = float(v.group(1)), int(v.group(2)), int(v.group(3))
            crit, ok = criterion(sc, w, gain, won, n)
            holds = "-" if ok is None else ("yes" if ok else "NO")
            shop = rows.get((sc, 'both_shop'), float('nan'))
            value = rows.get((sc, row), float('nan'))
            if not several:
                print(f"| {w} | {sc} | {best} {med:.1f} | {shop:.1f} | {value:.1f} | {gain:+.1f} % "
                      f"| {won} of {n} | {crit} | {holds} |")
                continue
            # the gain lines name no scenario: the first after this scenario's headline is its own
            p = re.compile(rf"^- {row} vs [a-z_]+ over the thread: [-+0-9.]+ % \(per seed "
                           r"([-+0-9.]+) \.\. ([-+0-9.]+) %", re.M).search(text, m.end())
            spread = f" ({p.group(1)} .. {p.group(2)})" if p else ""
            print(f"| {w} | {sc} | {row} | {best} {med:.1f} | {shop:.1f} | {value:.1f} "
                  f"| {gain:+.1f} %{spread} | {won} of {n} | {crit} | {holds} |")
PY
note=""
for c in ${candidate[@]+"${candidate[@]}"}; do
  case "$c" in
    --slope-through-lags-only|--grey-five-sensors|--grey-without-short-mix)
      note+="; both_grey with $c" ;;
    --offset-candidates|--grey-candidates) note+="; the opt-in rows of $c" ;;
  esac
done
echo "(simulator only; seeds $first_seed..$((first_seed + seeds - 1))$note; the evaluations' tables: $out_dir)"
