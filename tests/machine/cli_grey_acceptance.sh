#!/usr/bin/env bash
# Smoke test of scripts/grey_acceptance.sh (issue 41's acceptance table) and of
# scripts/grey_residuals.py (a planted evaluation, below): --help, bad arguments
# refused with exit 2 and a message naming the argument, and the evaluation's --past-days range
# (1..40: 8 weeks) enforced with a clear error. The table itself takes minutes (not run here).
set -u
W="$1"; D="$2"; S="$3"
rm -rf "$D"; mkdir -p "$D"
source "$S/tests/support/cli_common.sh"
G="$S/scripts/grey_acceptance.sh"
bash "$G" --help > "$D/help.txt" || fail "--help"
grep -q "thread medians" "$D/help.txt" || fail "--help does not say what is measured"
bash "$G" --weeks 9 > "$D/out.txt" 2> "$D/err.txt"; rc=$?
[ $rc -eq 2 ] || fail "--weeks 9: expected exit 2, got $rc"
grep -q "'9'" "$D/err.txt" && grep -q "1..8" "$D/err.txt" || fail "--weeks 9: $(cat "$D/err.txt")"
bash "$G" --frobnicate > "$D/out.txt" 2> "$D/err.txt"; rc=$?
[ $rc -eq 2 ] && grep -q "frobnicate" "$D/err.txt" || fail "unknown argument not named"
bash "$G" --first-seed 0 > "$D/out.txt" 2> "$D/err.txt"; rc=$?
[ $rc -eq 2 ] && grep -q "first-seed" "$D/err.txt" || fail "--first-seed 0 accepted"
bash "$G" --seeds 21 > "$D/out.txt" 2> "$D/err.txt"; rc=$?
[ $rc -eq 2 ] && grep -q "1..20" "$D/err.txt" || fail "--seeds 21 accepted"
# --first-seed reaches the evaluation: a stand-in whirl records its arguments.
mkdir -p "$D/fake"
printf '#!/usr/bin/env bash\necho "$*" >> "%s/args.txt"\n' "$D" > "$D/fake/whirl"
chmod +x "$D/fake/whirl"
WHIRL_BUILD_DIR="$D/fake" bash "$G" --first-seed 101 --seeds 3 --weeks "1 8" --out-dir "$D/o" \
  > "$D/out.txt" 2> "$D/err.txt" || fail "stand-in run: $(cat "$D/err.txt")"
[ "$(grep -c -- "--seed 101 --seeds 3 " "$D/args.txt")" -eq 2 ] || fail "seeds: $(cat "$D/args.txt")"
grep -q -- "--past-days 40 " "$D/args.txt" || fail "8 weeks: $(cat "$D/args.txt")"
grep -q "seeds 101..103" "$D/out.txt" || fail "the seeds are not reported: $(cat "$D/out.txt")"
grep -q -- "--slope-through-lags-only" "$D/args.txt" "$D/out.txt" && fail "the candidate without asking"
# An opt-in flag ($1) reaches both weeks' evaluations (out-dir $D/$2) and the table says so ($3).
flag_reaches_every_evaluation() {
  rm -f "$D/args.txt"
  WHIRL_BUILD_DIR="$D/fake" bash "$G" --weeks "1 8" "$1" --out-dir "$D/$2" \
    > "$D/out.txt" 2> "$D/err.txt" || fail "$1 run: $(cat "$D/err.txt")"
  [ "$(grep -c -- "--markdown $1" "$D/args.txt")" -eq 2 ] || fail "$1: $(cat "$D/args.txt")"
  grep -q -- "$3" "$D/out.txt" || fail "$1 not reported: $(cat "$D/out.txt")"
}
flag_reaches_every_evaluation --slope-through-lags-only c "both_grey with --slope-through-lags-only"
flag_reaches_every_evaluation --offset-candidates k "the opt-in rows of --offset-candidates"
grep -q "| weeks | scenario | row |" "$D/out.txt" || fail "no row column: $(cat "$D/out.txt")"
flag_reaches_every_evaluation --grey-candidates g "the opt-in rows of --grey-candidates"
flag_reaches_every_evaluation --grey-five-sensors f "both_grey with --grey-five-sensors"
# Each scenario's row gets its own per-seed range (the gain lines name no scenario): a stand-in
# prints two planted scenario blocks whose ranges differ.
python3 - "$D/planted.md" <<'PY'
import sys
rows = ("both_grey", "grey_warmup_k0", "grey_mean_k0")
out = []
for sc, lo in (("production", 1), ("duty-changes", 5)):
    out += [f"| {sc} | {r} | 1.0 [1.0-1.0] | 1.0 | {8 + i}.0 [7.0-9.0] | 9 | 1 | 1 / 1 |"
            for i, r in enumerate(rows)]
for sc, lo in (("production", 1), ("duty-changes", 5)):
    out.append(f"- {sc}: the strongest sensor-free strategy is warmup (thread median 10.0 um, x")
    out += [f"- {r} vs warmup over the thread: +{20 - i}.0 % (per seed +{lo}.0 .. +{lo + i}.5 %; x"
            for i, r in enumerate(rows)]
    out += [f"- {sc}: {r} (sensors) beats the strongest sensor-free strategy warmup over the "
            f"thread by {20 - i}.0 % (better in 5 of 5 seeds)" for i, r in enumerate(rows)]
open(sys.argv[1], "w").write("\n".join(out) + "\n")
PY
printf '#!/usr/bin/env bash\ncat "%s/planted.md"\n' "$D" > "$D/fake/whirl"
WHIRL_BUILD_DIR="$D/fake" bash "$G" --weeks 8 --offset-candidates --out-dir "$D/p" \
  > "$D/out.txt" 2> "$D/err.txt" || fail "planted run: $(cat "$D/err.txt")"
grep -q "| 8 | production | grey_mean_k0 | warmup 10.0 | nan | 10.0 | +18.0 % (+1.0 .. +3.5) | 5 of 5 |" \
  "$D/out.txt" || fail "production's range: $(cat "$D/out.txt")"
grep -q "| 8 | duty-changes | grey_warmup_k0 | warmup 10.0 | nan | 9.0 | +19.0 % (+5.0 .. +6.5) | 5 of 5 |" \
  "$D/out.txt" || fail "duty-changes' range: $(cat "$D/out.txt")"
expect_fail "past-days" "$W" machine evaluate --past-days 41 --machines 1 --test-days 1
# scripts/grey_residuals.py on a planted evaluation of two screws (hand-computed figures): slope
# part |b| x l_u = 2 um/m x 3 m = 6 and 1 x 3 = 3, median 4.5; the hindsight choice min(grey, sf)
# per screw 4 and 5, median 4.5; the 30 % line 0.7 x median(8, 10) = 6.3.
R="$S/scripts/grey_residuals.py"
python3 - "$D/planted.json" <<'PY'
import json, sys
def m(total, b, band):
    return {"metrics": {"accumulated_total_um": total, "mean_line_slope_um_per_m": b,
                        "useful_travel_mm": 3000, "v_u_um": band, "accumulated_1000_um": 1}}
screws = []
for grey, b, sf, start in ((4, 2, 8, "cold"), (6, -1, 5, "warm")):
    screws.append({"ok": True, "start_type": start, "residual_workpiece_total_um": 3,
                   "strategies": {"both_grey": m(grey, b, 2), "both_shop": m(7, 0, 1),
                                  "warmup": m(sf, 0, 1), "workpiece": m(12, 3, 4)}})
screws[1]["strategies"]["warmup"]["metrics"]["accumulated_total_um"] = 10
json.dump({"scenarios": [{"scenario": "production", "seeds": [1], "strongest_sensor_free": "warmup",
                          "runs": [{"screws": screws}]}]}, open(sys.argv[1], "w"))
PY
python3 "$R" "$D/planted.json" > "$D/res.txt" 2> "$D/err.txt" || fail "grey_residuals: $(cat "$D/err.txt")"
grep -Eq "^  both_grey +5.00 +4.50 +2.00 +\+0.50 +1.50" "$D/res.txt" || fail "medians: $(cat "$D/res.txt")"
grep -q "30 % line 6.30; better of both_grey and warmup per screw (hindsight) 5.00" "$D/res.txt" ||
  fail "hindsight: $(cat "$D/res.txt")"
echo "not json" > "$D/bad.json"
python3 "$R" "$D/bad.json" > "$D/out.txt" 2> "$D/err.txt" && fail "a bad file was accepted"
grep -q "bad.json" "$D/err.txt" || fail "the bad file is not named: $(cat "$D/err.txt")"
echo "cli_grey_acceptance: ok"
