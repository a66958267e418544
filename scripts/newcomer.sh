#!/usr/bin/env bash
# A newcomer's path: README.md's "Your machine, step by step" (steps 1-5) run as written, in a fresh
# folder, with generated files shaped like a shop's own (no comment lines, the README's names):
#   1-2. curves/screw01.csv (a noisy 30-min elongation record), table.csv (24 screws), screw.json
#        and machine.json (copies of the files the README names), runs/c1..c3.csv (cutting logs),
#        lead.csv (a measured lead deviation, 0.5 mm apart);
#   3-5. every `whirl ...` line of the section's code blocks and every complete `whirl ... --flag`
#        in its text (lead-report), in order, read from README.md itself.
# Twice: (A) with the README's example profile and logs whose sensors are its analog inputs
# (t1_C..t8_C); (B) the machine half again on logs of `whirl machine sensors` with the profile the
# README names for them (whirling_840d.json; `plan` gets --start-position-mm, as the README says).
# Fails on any non-zero exit, an output a command names (--out, --out-dir, --nc, --reset-nc,
# --csv) that is missing or empty, and any "warning:" the README does not mention (ALLOWED below:
# each warning pattern with the README words that announce it; the words must be in README.md).
# Usage: scripts/newcomer.sh [whirl binary] [scratch dir] [source dir]   (CTest: newcomer)
set -uo pipefail
SRC="${3:-$(cd "$(dirname "$0")/.." && pwd)}"
W="$(realpath "${1:-$SRC/build/whirl}")"
D="${2:-$(mktemp -d)}"
rm -rf "$D"; mkdir -p "$D"
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# warning pattern (grep -E) | the README's words for it
ALLOWED=(
  "machine profile .* is the shipped example|warn that it is the shipped example"
  "samples have an input outside the model's training range|when its inputs leave the training range"
)

# The section's commands, one per line (continuations joined, comments dropped).
commands() {
  python3 - "$SRC/README.md" <<'PY'
import re, sys
text = open(sys.argv[1], encoding="utf-8").read()
section = text.split("## Your machine, step by step", 1)[1].split("\n## ", 1)[0]
out, block, pending = [], False, ""
for line in section.splitlines():
    if line.lstrip().startswith("```"):
        block = not block
        continue
    if block:
        line = re.split(r"\s#\s", " " + line.strip())[0].strip()
        if pending or line.startswith("whirl "):
            pending += " " + line.rstrip("\\").strip()
            if not line.endswith("\\"):
                out.append(pending.strip()); pending = ""
        continue
    for span in re.findall(r"`(whirl [^`]*--[^`]*)`", line):
        out.append(span)
print("\n".join(out))
PY
}

# Step 1-2: files of one's own.
own_files() {
  local dir="$1"
  mkdir -p "$dir/curves" "$dir/runs"
  cp "$SRC/datasets/screws/reference_80x10x6000.json" "$dir/screw.json"
  cp "$SRC/datasets/machines/example_840d.json" "$dir/machine.json"
  # A measured elongation record: 1 s steps for 30 min, arctangent rise to 19 um at 320 s, noise.
  awk 'BEGIN { print "time_s,elongation_um"; L = 19; ts = 320; k = 5.6
    for (t = 0; t <= 1800; t++) { u = t < ts ? t / ts : 1
      printf "%d,%.4f\n", t, L * atan2(k * u, 1) / atan2(k, 1) + 0.2 * sin(t * 1.7) + 0.1 * sin(t * 0.37) } }' \
    > "$dir/curves/screw01.csv"
  # 24 screws measured over the years (rows of the shipped history, no comment lines).
  grep -v '^#' "$SRC/datasets/whirling_500.csv" | awk 'NR == 1 || (NR > 100 && NR <= 124)' > "$dir/table.csv"
  # The screw types the shop makes (candidates for `whirl design`): the five inputs of 40 rows.
  grep -v '^#' "$SRC/datasets/whirling_500.csv" | cut -d, -f1-5 | awk 'NR == 1 || (NR > 200 && NR <= 240)' \
    > "$dir/types.csv"
  # Cutting logs every minute for 4 h: four of the profile's sensors and the check-bar offset.
  for r in 1 2 3; do
    awk -v r="$r" 'BEGIN { print "time_min,t1_C,t2_C,t3_C,t4_C,offset_um"
      for (m = 0; m <= 240; m++) { a = 6 * (1 - exp(-m / (40 + 5 * r))); b = 3 * (1 - exp(-m / 90))
        c = 0.5 * sin(m / 30 + r); d = m / 120
        printf "%d,%.3f,%.3f,%.3f,%.3f,%.3f\n", m, 20 + a, 21 + b, 20.5 + c, 19 + d,
               2.1 * a + 1.3 * b - 0.8 * d + 0.15 * sin(7 * m + r) } }' > "$dir/runs/c$r.csv"
  done
  # A lead deviation after cooling: 5000 mm of thread every 0.5 mm.
  awk 'BEGIN { print "position_mm,deviation_um"
    for (i = 0; i <= 10000; i++) { x = i / 2; printf "%.1f,%.4f\n", x, 0.002 * x + 1.5 * sin(x / 300) + 0.3 * sin(x * 0.628) } }' \
    > "$dir/lead.csv"
}

# The README's words for an allowed warning must still be in the README.
allowed() {
  local line="$1" entry
  for entry in "${ALLOWED[@]}"; do
    grep -qE -- "${entry%%|*}" <<< "$line" || continue
    grep -qF -- "${entry#*|}" "$SRC/README.md" && return 0
  done
  return 1
}

# run <dir> <command line from the README> [extra arguments]
run() {
  local dir="$1" line="$2"; shift 2
  local args
  read -r -a args <<< "${line#whirl }"
  (cd "$dir" && "$W" "${args[@]}" "$@" > out.txt 2> err.txt)
  local rc=$?
  [ $rc -eq 0 ] || { fail "($dir) '$line' $*: exit $rc: $(head -c 600 "$dir/err.txt")"; return; }
  local w
  while IFS= read -r w; do
    allowed "$w" || fail "($dir) '$line': a warning the README does not mention: $w"
  done < <(grep "warning" "$dir/err.txt")
  local i
  for ((i = 0; i < ${#args[@]} - 1; i++)); do
    case "${args[i]}" in
      --out|--out-dir|--nc|--reset-nc|--csv)
        [ -s "$dir/${args[i + 1]}" ] || [ -n "$(ls -A "$dir/${args[i + 1]}" 2> /dev/null)" ] ||
          fail "($dir) '$line': ${args[i]} ${args[i + 1]} was not written" ;;
    esac
  done
  ran=$((ran + 1))
}

mapfile -t LINES < <(commands)
[ "${#LINES[@]}" -ge 10 ] || fail "only ${#LINES[@]} commands found in the README's step by step"
for needed in "whirl fit " "whirl train " "whirl plan " "whirl compare " "whirl drift nc " \
              "whirl lead-report "; do
  printf '%s\n' "${LINES[@]}" | grep -q "^$needed" || fail "the README's steps have no '$needed'"
done

grep -q "logs of \`whirl machine sensors\`.*whirling_840d.json" "$SRC/README.md" ||
  fail "the README does not name the profile for logs of whirl machine sensors (whirling_840d.json)"

ran=0
# (A) The shipped example profile, logs of its own sensors.
own_files "$D/a"
for line in "${LINES[@]}"; do run "$D/a" "$line"; done

# (B) The machine half on the simulated machine's logs, with the profile named for them.
own_files "$D/b"
cp "$SRC/datasets/machines/whirling_840d.json" "$D/b/machine.json"
(cd "$D/b" && "$W" machine sensors --out-dir sim --idle 0 --cutting 3 > /dev/null 2> err.txt) ||
  fail "machine sensors: $(cat "$D/b/err.txt")"
for r in 1 2 3; do cp "$D/b/sim/cutting_$r.csv" "$D/b/runs/c$r.csv" 2> /dev/null || fail "no cutting_$r.csv"; done
cp "$D/a/model.json" "$D/b/model.json" 2> /dev/null || fail "step A wrote no model.json"
for line in "${LINES[@]}"; do
  case "$line" in
    "whirl drift "*) run "$D/b" "$line" ;;
    "whirl plan "*--with-drift-action*) run "$D/b" "$line" --start-position-mm 5600 ;;  # as docs/machine.md
  esac
done

[ "$fails" -eq 0 ] || { echo "$fails failure(s) in $ran commands (files kept in $D)"; exit 1; }
echo "ok: $ran README commands ran on a newcomer's files ($D)"
