#!/usr/bin/env bash
# One command-line grammar: args <whirl> <scratch dir> <source dir>. Walks every subcommand's
# --help (so a new command or flag is covered without touching this test) and checks:
#  - every decimal (FLOAT) flag carries its unit in its name (-um, -mm, -s, -min, -c, -pct, ...)
#    unless it is dimensionless: the suffixes -fraction, -factor, -ratio, -sigma, -scale, -share
#    and the short list DIMENSIONLESS below (each with its reason);
#  - '--out' names one file and '--out-dir' a folder by their help texts, and every option whose
#    help states the output-directory rule ("a new or empty directory") is an --out-dir or *-dir;
#  - every command that computes something (every leaf command) has --json;
#  - 'whirl --help' and each group's --help list one line per subcommand;
#  - an unknown command is named with the closest match (exit 1);
# then that each old spelling (a hidden deprecated alias) is absent from --help, still works
# (same output as the new spelling) and prints "whirl: --old is deprecated, use --new" on stderr.
# KEEP_GOING=1 lists every grammar failure instead of stopping at the first.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"
source "$SRC/tests/support/cli_common.sh"

# Decimal flags without a unit, and why.
DIMENSIONLESS=(
  --shape-k               # shape of the arctangent curve
  --time-exponent         # exponent p of (t/t_s)^p
  --md32760               # MD32760, a velocity factor of the 840D
  --change                # relative change of the training objective
  --alpha --beta          # significance level; trainbr's weight coefficients
  --perturbation          # relative perturbation of network weights
  --prediction-tolerance  # relative tolerance
  --score-rows            # shares of a run's rows
  --threshold             # drift split: in the unit of the --at column, whatever it is
  --train --test          # drift holdout: shares of the rows
)
# Not yet renamed: the drift commands' flags wait for the drift rework in progress (then
# --lag-grid-min, --check-every-min / --check-every-samples, --refit-every-*, --start-*, --out-dir
# and --json on drift report). Each entry is "<command> <flag>" ("<command> --json": no --json
# yet); remove an entry when its flag is renamed, and the test checks it from then on.
PENDING=(
  "drift fit --lag-grid" "drift crossval --lag-grid" "drift holdout --lag-grid"
  "drift report --lag-grid" "drift holdout --report" "drift report --out" "drift report --json"
  "drift monitor --check-every" "drift monitor --refit-every" "drift monitor --start"
  "drift monitor --report"
)
pending() { local p; for p in "${PENDING[@]}"; do [ "$p" = "$1" ] && return 0; done; return 1; }
UNIT_SUFFIX='-(um|mm|m|s|min|h|k|c|pct|rpm|mm-min|m-min|hrc|urad|per-k|samples)$'
DIMENSIONLESS_SUFFIX='-(fraction|factor|ratio|sigma|scale|share)$'

failures=0
bad() {
  echo "FAIL: $*"; failures=$((failures + 1))
  [ "${KEEP_GOING:-0}" = 1 ] || exit 1
}
subcommands() { awk '/^Subcommands:/ {on = 1; next} on && /^  [a-z][a-z0-9-]* / {print $1}'; }
# Each option of a --help text on stdin as one line: "<flag>\t<type>\t<help text, joined>".
options() {
  awk '/^Options:/ {on = 1; next} /^Subcommands:/ {on = 0}
       on && /^ +(-[a-zA-Z],)?--[a-zA-Z0-9-]+/ {
         if (name != "") print name "\t" type "\t" text
         line = $0; sub(/^ +(-[a-zA-Z],)?/, "", line)
         name = line; sub(/ .*/, "", name)
         rest = substr(line, length(name) + 1); sub(/^ +/, "", rest)
         type = rest; sub(/ .*/, "", type); text = rest; next }
       on && name != "" && /^ {20,}/ { t = $0; sub(/^ +/, "", t); text = text " " t }
       END { if (name != "") print name "\t" type "\t" text }'
}
dimensionless() { local f; for f in "${DIMENSIONLESS[@]}"; do [ "$1" = "$f" ] && return 0; done; return 1; }

checked_flags=0; checked_commands=0
check_command() {  # check_command <help text> <command words...>
  local help="$1"; shift
  local name type text has_json=0
  while IFS=$'\t' read -r name type text; do
    [ -n "$name" ] || continue
    [ "$name" = --json ] && has_json=1
    pending "$* $name" && continue
    case "$type" in
      FLOAT*)
        checked_flags=$((checked_flags + 1))
        if ! [[ "$name" =~ $UNIT_SUFFIX || "$name" =~ $DIMENSIONLESS_SUFFIX ]] &&
           ! dimensionless "$name"; then
          bad "whirl $* $name: a decimal flag without a unit suffix (e.g. ${name}-mm)"
        fi ;;
    esac
    if [ "$name" = --out ] && grep -qiE 'director|folder' <<< "$text"; then
      bad "whirl $* --out names a folder ('$text'): use --out-dir"
    fi
    if [ "$name" = --out-dir ] && ! grep -qiE 'director|folder' <<< "$text"; then
      bad "whirl $* --out-dir does not say it is a folder: '$text'"
    fi
    if grep -q "a new or empty directory" <<< "$text" && ! [[ "$name" =~ -dir$ ]]; then
      bad "whirl $* $name names a folder: call it --out-dir (or *-dir)"
    fi
  done <<< "$(options <<< "$help")"
  [ "$has_json" = 1 ] || pending "$* --json" || bad "whirl $*: no --json (a JSON summary on stdout)"
  checked_commands=$((checked_commands + 1))
}

# The Subcommands section of a --help text: one line per subcommand, none continued.
check_listing() {  # check_listing <help text> <command words...>
  local help="$1"; shift
  local listed lines
  listed=$(subcommands <<< "$help" | wc -l)
  lines=$(awk '/^Subcommands:/ {on = 1; next} on && !NF {exit} on' <<< "$help" | wc -l)
  [ "$listed" -eq "$lines" ] ||
    bad "whirl $* --help: $lines lines for $listed subcommands (one line per command)"
}

walk() {  # walk <command words...>
  local help sub subs
  help=$("$W" "$@" --help) || fail "whirl $* --help failed"
  subs=$(subcommands <<< "$help")
  if [ -z "$subs" ]; then check_command "$help" "$@"; return; fi
  check_listing "$help" "$@"
  for sub in $subs; do walk "$@" "$sub"; done
}

top=$("$W" --help) || fail "whirl --help failed"
check_listing "$top"
for sub in $(subcommands <<< "$top"); do walk "$sub"; done
[ "$checked_commands" -gt 30 ] || fail "only $checked_commands commands found: has --help changed?"
[ "$checked_flags" -gt 50 ] || fail "only $checked_flags decimal flags found: has --help changed?"

# An unknown command: named, with the closest match, exit 1.
unknown() {  # unknown <closest> <command words...> [-- more arguments]
  local closest="$1"; shift
  local words=()
  while [ $# -gt 0 ] && [ "$1" != -- ]; do words+=("$1"); shift; done
  [ $# -gt 0 ] && shift
  "$W" "${words[@]}" "$@" > "$D/out.txt" 2> "$D/err.txt"; local rc=$?
  [ $rc -eq 1 ] || bad "whirl ${words[*]}: exit $rc, expected 1"
  grep -qF "unknown command '${words[*]}'" "$D/err.txt" ||
    bad "whirl ${words[*]}: not named: $(cat "$D/err.txt")"
  grep -qF "did you mean '$closest'" "$D/err.txt" ||
    bad "whirl ${words[*]}: no 'did you mean '$closest'': $(cat "$D/err.txt")"
}
unknown plan plna
unknown "drift fit" drift fitt
unknown "surface predict" surface predit -- --points x.csv
unknown "machine sensors" machine sensor
"$W" nosuch > "$D/out.txt" 2> "$D/err.txt"
[ $? -eq 1 ] && grep -qF "unknown command 'nosuch'; did you mean '" "$D/err.txt" ||
  bad "whirl nosuch: $(cat "$D/err.txt")"

[ "$failures" -eq 0 ] || fail "$failures grammar failures"
echo "grammar: $checked_commands commands, $checked_flags decimal flags"

# --- deprecated spellings ----------------------------------------------------------------------
S="$SRC/datasets/screws/reference_80x10x6000.json"
M="$SRC/datasets/machines/example_840d.json"
BB="$SRC/datasets/ballbar"
# alias <old> <new> <command words...> -- <rest of the arguments, with @ where the flag goes> [-- value]
# Runs the command with the new and with the old spelling; both must exit 0 with the same stdout,
# the old one with exactly the deprecation line on stderr more, and the old flag is not in --help.
alias_case() {
  local old="$1" new="$2"; shift 2
  local words=() args=()
  while [ "$1" != -- ]; do words+=("$1"); shift; done; shift
  args=("$@")
  "$W" "${words[@]}" --help | grep -qE -- "^ +${old}( |$)" && fail "whirl ${words[*]} --help lists $old"
  local with_new=() with_old=() a
  for a in "${args[@]}"; do
    with_new+=("${a//@FLAG@/$new}"); with_old+=("${a//@FLAG@/$old}")
  done
  "$W" "${words[@]}" "${with_new[@]}" > "$D/new.out" 2> "$D/new.err" ||
    fail "whirl ${words[*]} ${with_new[*]}: $(head -c 400 "$D/new.err")"
  "$W" "${words[@]}" "${with_old[@]}" > "$D/old.out" 2> "$D/old.err" ||
    fail "whirl ${words[*]} ${with_old[*]} (old spelling refused): $(head -c 400 "$D/old.err")"
  [ "$(grep -c "^whirl: $old is deprecated, use $new\$" "$D/old.err")" = 1 ] ||
    fail "whirl ${words[*]} $old: no deprecation line: $(head -c 400 "$D/old.err")"
  grep -q "deprecated" "$D/new.err" && fail "whirl ${words[*]} $new: deprecation line for the new spelling"
  # Same result (the paths that hold the spelling are normalized, the longer spelling first).
  local first="$new" second="$old"
  [ ${#old} -gt ${#new} ] && first="$old" second="$new"
  sed "s/_$first/_FLAG/g; s/_$second/_FLAG/g" "$D/new.out" > "$D/new.norm"
  sed "s/_$first/_FLAG/g; s/_$second/_FLAG/g" "$D/old.out" > "$D/old.norm"
  cmp -s "$D/new.norm" "$D/old.norm" || fail "whirl ${words[*]}: $old and $new give different output"
  aliases=$((aliases + 1))
}
aliases=0
# plan: R parameters and the curve's features.
PLAN=(--screw "$S" --machine "$M" --json)
alias_case --max-elongation --max-elongation-um plan -- "${PLAN[@]}" @FLAG@ 30 --settle-time-s 250
alias_case --settle-time --settle-time-s plan -- "${PLAN[@]}" --max-elongation-um 30 @FLAG@ 250
mkdir -p "$D/nc_--save-r" "$D/nc_--save-r-first"
alias_case --save-r --save-r-first plan -- --screw "$S" --max-elongation-um 30 --settle-time-s 250 \
  --start-position-mm 0 --machine-offset-mm 0 --sync-id-first 1 --sync-id-last 20 @FLAG@ 40 \
  --nc "$D/nc_@FLAG@/WHIRL_TEMP_COMP.SPF" --json
cmp -s "$D/nc_--save-r/WHIRL_TEMP_COMP.SPF" "$D/nc_--save-r-first/WHIRL_TEMP_COMP.SPF" ||
  fail "plan: --save-r and --save-r-first write different programs"
alias_case --max-elongation --max-elongation-um curve -- @FLAG@ 30 --settle-time-s 250 --json
alias_case --settle-time --settle-time-s curve -- --max-elongation-um 30 @FLAG@ 250
# predict: the five process inputs.
P5=(--hardness-hrc 62 --diameter-mm 80 --pitch-mm 10 --raceway-radius-mm 6 --cutting-speed-m-min 180)
for pair in hardness:hardness-hrc diameter:diameter-mm pitch:pitch-mm raceway-radius:raceway-radius-mm \
            cutting-speed:cutting-speed-m-min; do
  old="--${pair%%:*}"; new="--${pair#*:}"
  alias_case "$old" "$new" predict -- "${P5[@]/#$new/@FLAG@}" --json
done
# surface: positions and the report folder.
"$W" surface synth --out "$D/points.csv" > /dev/null || fail "surface synth"
"$W" surface fit --points "$D/points.csv" --out "$D/surface.json" > /dev/null || fail "surface fit"
alias_case --x --x-mm surface predict -- --surface "$D/surface.json" @FLAG@ 100 --y-mm 50
alias_case --y --y-mm surface predict -- --surface "$D/surface.json" --x-mm 100 @FLAG@ 50 --json
alias_case --report --out-dir surface fit -- --points "$D/points.csv" --no-plots \
  @FLAG@ "$D/fit_@FLAG@" --json
# ballbar drift: the bar's temperature correction.
for pair in bar-alpha-per-K:bar-alpha-per-k bar-alpha-sd-per-K:bar-alpha-sd-per-k \
            bar-reference-C:bar-reference-c; do
  old="--${pair%%:*}"; new="--${pair#*:}"
  case "$new" in *reference*) v=21 ;; *sd*) v=2e-6 ;; *) v=11e-6 ;; esac
  alias_case "$old" "$new" ballbar drift -- --readings "$BB/readings.csv" --pivots "$BB/pivots.json" \
    @FLAG@ "$v" --json
done
# Folders: the machine's sensor runs, the comparison and machine reports.
alias_case --out --out-dir machine sensors -- @FLAG@ "$D/runs_@FLAG@" --idle 1 --cutting 0 --json
alias_case --report --out-dir compare -- --model "$SRC/models/default.json" --screw "$S" --no-plots \
  @FLAG@ "$D/compare_@FLAG@" --json
alias_case --report --out-dir machine evaluate -- --machines 1 --screws 1 --train-runs 1 \
  @FLAG@ "$D/machine_@FLAG@" --json

# Both spellings at once: an error naming the old one; a bad value: named as typed.
expect_fail "--max-elongation" "$W" curve --max-elongation 30 --max-elongation-um 30 --settle-time-s 250
expect_fail "^error: --settle-time: '1e999' breaks the rule" "$W" curve --max-elongation-um 30 --settle-time 1e999
grep -- "^error:" "$D/err.txt" | grep -q -- "--settle-time-s" && fail "a refused old spelling is named as the new one"
echo "deprecated spellings: $aliases checked"
