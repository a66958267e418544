#!/usr/bin/env bash
# Cost of the drift commands on long logs: CPU time, wall time and peak memory (max RSS, from GNU
# time) per command and log length, on one core (taskset -c 0), with rows per CPU second.
# The logs come from scripts/make_long_log.py (seed 1, 15-s samples, 8 columns: time_min,
# spindle_rpm, t1_C..t5_C, ch1_um; 2,000,000 rows are 347 days); the model of monitor and predict
# and the training run of report are the first 10,000 rows (the same generator's shorter log).
# Commands (the issue-43 set):
#   fit      drift fit --run LOG --error ch1_um --out m.json
#   predict  drift predict --model M --run LOG --out p.csv
#   monitor  drift monitor --model M --run LOG
#   split    drift split --log LOG --out-dir d
#   report   drift report --train-run T --run LOG --error ch1_um --out-dir r
# Usage: scripts/bench_drift.sh [--whirl BIN] [--rows "10000 100000 1000000 2000000"]
#                               [--commands "fit predict monitor split report"] [--dir DIR]
# DIR (default build/bench_drift) keeps the logs between runs (about 120 MB for 2,000,000 rows).
# Prints one line per command and length: rows, command, CPU s (user + sys), wall s, max RSS MB,
# rows per CPU second, exit status. The machine is shared: CPU time is the comparable figure.
set -euo pipefail
cd "$(dirname "$0")/.."
W=build/whirl
ROWS="10000 100000 1000000 2000000"
COMMANDS="fit predict monitor split report"
DIR=build/bench_drift
while [ $# -gt 0 ]; do
  case "$1" in
    --whirl) W="$2"; shift 2 ;;
    --rows) ROWS="$2"; shift 2 ;;
    --commands) COMMANDS="$2"; shift 2 ;;
    --dir) DIR="$2"; shift 2 ;;
    *) echo "usage: $0 [--whirl BIN] [--rows LIST] [--commands LIST] [--dir DIR]" >&2; exit 2 ;;
  esac
done
[ -x /usr/bin/time ] || { echo "needs GNU time (/usr/bin/time; Debian package time)" >&2; exit 2; }
PIN=()
command -v taskset > /dev/null && PIN=(taskset -c 0)
mkdir -p "$DIR"
log() {
  local f="$DIR/log_$1.csv"
  [ -s "$f" ] || python3 scripts/make_long_log.py --rows "$1" --out "$f"
  echo "$f"
}
TRAIN=$(log 10000)
MODEL="$DIR/model_10000.json"
[ -s "$MODEL" ] || "$W" drift fit --run "$TRAIN" --error ch1_um --out "$MODEL" > /dev/null 2>&1

# One measured command: rows, name, then the command line.
measure() {
  local rows="$1" name="$2"
  shift 2
  rm -rf "$DIR/out_$name" "$DIR/out_$name.csv" "$DIR/out_$name.json"
  local status=0
  "${PIN[@]}" /usr/bin/time -f "%U %S %e %M" -o "$DIR/time.txt" "$@" > "$DIR/stdout.txt" \
    2> "$DIR/stderr.txt" || status=$?
  read -r user sys wall rss_kb < <(tail -1 "$DIR/time.txt")
  awk -v n="$rows" -v c="$name" -v u="$user" -v s="$sys" -v w="$wall" -v m="$rss_kb" -v st="$status" \
    'BEGIN { cpu = u + s; printf "%9d  %-8s %8.2f %8.2f %8.1f %12.0f  %s\n", n, c, cpu, w, m / 1024,
             (cpu > 0 ? n / cpu : 0), (st == 0 ? "ok" : "exit " st) }'
  [ "$status" = 0 ] || sed -n '1,3p' "$DIR/stderr.txt" | sed 's/^/           /'
}

echo "whirl: $W ($(git rev-parse --short HEAD 2>/dev/null || echo ?)); $(nproc) cores, pinned: ${PIN[*]:-no}"
echo "     rows  command     CPU s   wall s   RSS MB   rows/CPU s  status"
for n in $ROWS; do
  f=$(log "$n")
  for c in $COMMANDS; do
    case "$c" in
      fit) measure "$n" fit "$W" drift fit --run "$f" --error ch1_um --out "$DIR/out_fit.json" ;;
      predict) measure "$n" predict "$W" drift predict --model "$MODEL" --run "$f" --out "$DIR/out_predict.csv" ;;
      monitor) measure "$n" monitor "$W" drift monitor --model "$MODEL" --run "$f" ;;
      split) measure "$n" split "$W" drift split --log "$f" --out-dir "$DIR/out_split" ;;
      report) measure "$n" report "$W" drift report --train-run "$TRAIN" --run "$f" --error ch1_um --out-dir "$DIR/out_report" ;;
      *) echo "unknown command $c" >&2; exit 2 ;;
    esac
  done
done
