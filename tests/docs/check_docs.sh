#!/usr/bin/env bash
# The documentation stays navigable and the README short:
#   - every relative link in README.md and docs/*.md points to an existing file or folder
#     (anchors and web addresses are not checked); links into pages listed in
#     tests/docs/pending_docs.txt may be missing (pages other work adds; the list is emptied when
#     they are in the tree, and a listed page that exists is checked like any other);
#   - README.md has at most 260 lines;
#   - the README's first code block holds the two commands of a fresh machine, scripts/demo.sh and
#     scripts/test.sh, and .ci/run runs scripts/test.sh, the README's test command.
# Usage: check_docs.sh <source dir>
set -uo pipefail
src="${1:?source dir}"
cd "$src" || exit 1
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

pending=()
while IFS= read -r line; do
  line="${line%%#*}"; line="${line//[[:space:]]/}"
  [ -n "$line" ] && pending+=("$line")
done < tests/docs/pending_docs.txt
is_pending() { local p; for p in "${pending[@]}"; do [ "$p" = "$1" ] && return 0; done; return 1; }

# Normalizes a path of the form a/b/../c (no symbolic-link resolution; the files must exist anyway).
normalize() {
  local IFS=/ part out=()
  for part in $1; do
    case "$part" in
      ''|.) ;;
      ..) [ ${#out[@]} -gt 0 ] && unset 'out[${#out[@]}-1]' ;;
      *) out+=("$part") ;;
    esac
  done
  echo "${out[*]}"
}

checked=0
for page in README.md docs/*.md; do
  [ -f "$page" ] || continue
  dir="$(dirname "$page")"
  # [text](target) and [text](target "title"); code spans may hold brackets, so drop them first.
  while IFS= read -r target; do
    target="${target#](}"; target="${target%)}"; target="${target%% *}"
    case "$target" in
      http://*|https://*|mailto:*|'#'*|'') continue ;;
    esac
    file="${target%%#*}"
    path="$(normalize "$dir/$file")"
    checked=$((checked + 1))
    if [ ! -e "$path" ]; then
      if is_pending "$path"; then
        echo "note: $page links to $path, pending (tests/docs/pending_docs.txt)"
      else
        fail "$page: link '$target' -> $path does not exist"
      fi
    fi
  done < <(sed -e 's/`[^`]*`//g' "$page" | grep -oE '\]\([^)]+\)')
done
[ "$checked" -gt 0 ] || fail "no relative links found in README.md and docs/*.md"

for p in "${pending[@]}"; do
  [ -e "$p" ] && echo "note: $p exists: remove it from tests/docs/pending_docs.txt"
done

lines=$(wc -l < README.md)
[ "$lines" -le 260 ] || fail "README.md has $lines lines (at most 260; move detail to docs/)"

first_block="$(awk '/^```/ { if (inside) exit; inside = 1; next } inside' README.md)"
for cmd in scripts/demo.sh scripts/test.sh; do
  grep -q "^$cmd" <<< "$first_block" || fail "README.md's first code block lacks $cmd"
done
grep -q '^bash scripts/test.sh' .ci/run || fail ".ci/run does not run scripts/test.sh"

[ "$fails" -eq 0 ] || { echo "$fails failure(s)"; exit 1; }
echo "ok: $checked relative links, README.md $lines lines"
