#!/usr/bin/env bash
# The figures models/README.md quotes are the binary's: the validation errors of the shipped model
# and of the paper-sized 20-row model (trained as the README says) equal what `whirl predict`
# prints; `whirl --help` does not call train "the network" nor `whirl evaluate --help` the model a
# network (the default chooses a family).
# args <whirl> <scratch dir> <source dir>
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"
source "$SRC/tests/support/cli_common.sh"
errors() {  # errors <model>: "A % / B %" from predict's last line
  "$W" predict --model "$1" --input "$SRC/datasets/whirling_validation.csv" 2> /dev/null | tail -1 |
    sed -n 's/.*mean absolute error \([0-9.]*\) % (max elongation.*), \([0-9.]*\) % (settle time.*/\1 % \/ \2 %/p'
}
big="$(errors "$SRC/models/default.json")"
"$W" train --data "$SRC/datasets/whirling_train.csv" --out "$D/model20.json" --trainbr-matlab --seed 1 \
  --restarts 10 > /dev/null 2>&1 || fail "train the 20-row model"
small="$(errors "$D/model20.json")"
[ -n "$big" ] && [ -n "$small" ] || fail "predict printed no validation errors"
text="$(tr '\n' ' ' < "$SRC/models/README.md" | tr -s ' ')"
grep -qF "$big for the 500-row model against $small for the 20-row model" <<< "$text" ||
  fail "models/README.md does not quote '$big for the 500-row model against $small for the 20-row model'"
"$W" --help > "$D/help.txt" || fail "whirl --help"
grep -E "^ +train " "$D/help.txt" | grep -q "the network" && fail "whirl --help: train is not only the network"
"$W" evaluate --help > "$D/evaluate.txt" || fail "whirl evaluate --help"
grep -q "network" "$D/evaluate.txt" && fail "whirl evaluate --help calls the model a network"
echo "ok: $big (500 rows), $small (20 rows)"
