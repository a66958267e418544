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
  --tau                   # design: the potential terms' prior sd over the scatter's (the paper's tau)
)
# Flags not yet renamed, each "<command> <flag>" ("<command> --json": no --json yet): skipped by
# the walk until renamed. Empty: every command follows the grammar.
PENDING=()
pending() { local p; for p in ${PENDING[@]+"${PENDING[@]}"}; do [ "$p" = "$1" ] && return 0; done; return 1; }
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

# Every --help names the docs page that explains the command's terms (fuzzy equivalence,
# lambda-cuts, grey grade, ...), and the page exists.
check_docs_page() {  # check_docs_page <help text> <command words...>
  local help="$1"; shift
  local page
  page=$(grep -oE "Documentation: docs/[A-Za-z0-9-]+\.md" <<< "$help" | head -1 | sed 's/^Documentation: //')
  if [ -z "$page" ]; then bad "whirl $* --help names no docs page ('Documentation: docs/...')"
  elif [ ! -f "$SRC/$page" ]; then bad "whirl $* --help names $page, which does not exist"; fi
}

walk() {  # walk <command words...>
  local help sub subs
  if without_torch "$@"; then echo "skipped: whirl $* (no whirl-torch in this build)"; return; fi
  help=$("$W" "$@" --help) || fail "whirl $* --help failed"
  check_docs_page "$help" "$@"
  subs=$(subcommands <<< "$help")
  if [ -z "$subs" ]; then check_command "$help" "$@"; return; fi
  check_listing "$help" "$@"
  for sub in $subs; do walk "$@" "$sub"; done
}

top=$("$W" --help) || fail "whirl --help failed"
check_listing "$top"
check_docs_page "$top"
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
  "$W" "${words[@]}" --help > "$D/help.txt" || fail "whirl ${words[*]} --help exits non-zero"
  grep -qE -- "^ +${old}( |$)" "$D/help.txt" && fail "whirl ${words[*]} --help lists $old"
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
  --history "$SRC/datasets/whirling_500.csv" \
  @FLAG@ "$D/compare_@FLAG@" --json
alias_case --report --out-dir machine evaluate -- --machines 1 --test-days 1 --past-days 1 \
  @FLAG@ "$D/machine_@FLAG@" --json

# drift: a run log with time and one without (its time is the sample index); the error follows
# sensor a through a first-order lag of 20 min (so the dynamic model's lag grid matters).
awk 'BEGIN { print "time_min,a_C,b_C,err_um";
  for (k = 0; k < 300; k++) { A = 8 * (1 - exp(-k / 30)) + 2 * sin(k / 25); B = k / 40;
    L += (A - L) / 20;
    printf "%d,%.4f,%.4f,%.4f\n", k, 20 + A, 21 + B, 2 * L - 1.5 * B + 0.05 * sin(7 * k) } }' \
  > "$D/drift.csv"
cut -d, -f2- "$D/drift.csv" > "$D/drift_samples.csv"
DR=(--run "$D/drift.csv" --error err_um --sensors a_C,b_C)
alias_case --lag-grid --lag-grid-min drift holdout -- --log "$D/drift.csv" --no-network \
  @FLAG@ 10,40 --json
# --errors-from-start stood for --error-zero run-start (a flag for an option with its value).
HO=(drift holdout --log "$D/drift.csv" --no-network --json)
"$W" "${HO[@]}" --help > "$D/help.txt" || fail "holdout --help exits non-zero"
grep -q -- "--errors-from-start" "$D/help.txt" && fail "holdout --help lists --errors-from-start"
"$W" "${HO[@]}" --error-zero run-start > "$D/new.out" 2> "$D/new.err" || fail "holdout --error-zero"
"$W" "${HO[@]}" --errors-from-start > "$D/old.out" 2> "$D/old.err" ||
  fail "holdout --errors-from-start refused: $(cat "$D/old.err")"
grep -qx "whirl: --errors-from-start is deprecated, use --error-zero run-start" "$D/old.err" ||
  fail "--errors-from-start: no deprecation line: $(cat "$D/old.err")"
cmp -s "$D/new.out" "$D/old.out" || fail "--errors-from-start and --error-zero run-start differ"
expect_fail "errors-from-start" "$W" "${HO[@]}" --errors-from-start --error-zero fixed
aliases=$((aliases + 1))
"$W" drift fit "${DR[@]}" --out "$D/drift_model.json" > /dev/null || fail "drift fit"
MON=(--model "$D/drift_model.json" --run "$D/drift.csv" --threshold-um 1)
alias_case --check-every --check-every-min drift monitor -- "${MON[@]}" @FLAG@ 60 --json
alias_case --refit-every --refit-every-min drift monitor -- "${MON[@]}" --refit-samples 2 @FLAG@ 7 --json
alias_case --start --start-min drift monitor -- "${MON[@]}" @FLAG@ 30 --json
alias_case --report --out-dir drift monitor -- "${MON[@]}" @FLAG@ "$D/monitor_@FLAG@" --json
alias_case --report --out-dir drift holdout -- --log "$D/drift.csv" --no-network @FLAG@ \
  "$D/holdout_@FLAG@" --json
alias_case --out --out-dir drift report -- --train-run "$D/drift.csv" --error err_um \
  --sensors a_C,b_C @FLAG@ "$D/report_@FLAG@" --json
# The unit follows the run's time axis: a -min flag on a run without recorded time (or -samples
# on one with time) is refused naming the flag to use; the old spelling keeps its meaning there
# (samples), with a warning; the -samples flag acts (its output differs from the default's).
"$W" drift fit --run "$D/drift_samples.csv" --error err_um --sensors a_C,b_C \
  --out "$D/drift_model_samples.json" > /dev/null 2>&1 || fail "drift fit on a run without time"
MS=(drift monitor --model "$D/drift_model_samples.json" --run "$D/drift_samples.csv" --threshold-um 1 --json)
HS=(drift holdout --log "$D/drift_samples.csv" --no-network --json)
for c in "MS check-every 60" "MS refit-every 7" "MS start 30" "HS lag-grid 10,40"; do
  read -r cmd flag value <<< "$c"
  [ "$cmd" = MS ] && args=("${MS[@]}" --refit-samples 2) || args=("${HS[@]}")
  expect_fail "--$flag-min $value: the run has no recorded time.*use --$flag-samples" \
    "$W" "${args[@]}" "--$flag-min" "$value"
  "$W" "${args[@]}" "--$flag-samples" "$value" > "$D/new.out" 2> /dev/null || fail "--$flag-samples"
  "$W" "${args[@]}" > "$D/default.out" 2> /dev/null || fail "${args[*]}"
  cmp -s "$D/new.out" "$D/default.out" && fail "--$flag-samples $value changes nothing"
  "$W" "${args[@]}" "--$flag" "$value" > "$D/old.out" 2> "$D/old.err" || fail "--$flag on samples"
  cmp -s "$D/new.out" "$D/old.out" || fail "--$flag on a run without time is not read in samples"
  grep -q "^warning: --$flag: the run has no recorded time.*use --$flag-samples" "$D/old.err" ||
    fail "--$flag on samples: no warning: $(cat "$D/old.err")"
done
expect_fail "--check-every-samples 60: the run records time: use --check-every-min" \
  "$W" drift monitor "${MON[@]}" --check-every-samples 60
expect_fail "--lag-grid-samples 10: the run records time: use --lag-grid-min" \
  "$W" drift holdout --log "$D/drift.csv" --no-network --lag-grid-samples 10

# Both spellings at once: an error naming the old one; a bad value: named as typed.
expect_fail "--max-elongation" "$W" curve --max-elongation 30 --max-elongation-um 30 --settle-time-s 250
expect_fail "^error: --settle-time: '1e999' breaks the rule" "$W" curve --max-elongation-um 30 --settle-time 1e999
grep -- "^error:" "$D/err.txt" | grep -q -- "--settle-time-s" && fail "a refused old spelling is named as the new one"
# An error raised after parsing (here a folder with a foreign file) names the spelling typed.
mkdir -p "$D/foreign" && echo x > "$D/foreign/f.txt"
expect_fail "^error: --out (now --out-dir) '" "$W" machine sensors --out "$D/foreign" --idle 1 --cutting 0
expect_fail "^error: --out-dir '" "$W" machine sensors --out-dir "$D/foreign" --idle 1 --cutting 0
grep -q "(now" "$D/err.txt" && fail "the current spelling is shown as an old one: $(cat "$D/err.txt")"
echo "deprecated spellings: $aliases checked"

# A mistyped flag is named with the closest option of its command, before any "X is required".
expect_fail "^error: unknown option '--dta' for 'whirl train'; did you mean '--data'" \
  "$W" train --dta "$D/x.csv" --out "$D/never.json"
expect_fail "unknown option '--hiden' for 'whirl train'; did you mean '--hidden'" \
  "$W" train --data "$D/x.csv" --hiden 4 --out "$D/never.json"
expect_fail "unknown option '--out-dri' for 'whirl drift monitor'; did you mean '--out-dir'" \
  "$W" drift monitor --model m.json --run r.csv --out-dri=x
[ ! -e "$D/never.json" ] || fail "a mistyped flag wrote an output"
echo "mistyped flags: named with the closest option"
