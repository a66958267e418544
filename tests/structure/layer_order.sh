#!/usr/bin/env bash
# The include graph of the library and the command line against the layer order: a module (a
# folder src/<module>/, and interp/) may include headers only of modules in a lower layer, and
# its CMakeLists.txt must link each of them (whirl::<module>). A module in no layer, an include
# of a module of the same or a higher layer (an upward edge, the start of a cycle) or an include
# the CMake links do not declare fails with the file, the line and the rule.
# args: <source dir>. The layers, from the bottom (the CMake links of each folder, made strict:
# no two modules of one layer include each other):
LAYERS=(
  "core"                       # errors, CSV, JSON, numbers, atomic files, curves, parallel-for
  "sim nn gp"                  # the simulator, the network, Gaussian processes
  "fit family drift torch"     # curve fits (sim), model families (gp, nn), drift (nn), LibTorch (nn)
  "interp machine workpiece"   # 840D output (drift, fit), machine errors (drift, sim), the
                               # workpiece model (family, nn)
  "ballbar surface compare design"  # ball bar, worktable, strategy comparison (machine, interp,
                               # ...), which screws to measure (workpiece)
  "machine_eval"               # the machine evaluation (compare, machine)
  "cli"                        # the command line: parses and calls the library
)
set -u
SRC="$1"

declare -A LAYER  # module -> its index in LAYERS
for i in "${!LAYERS[@]}"; do for m in ${LAYERS[$i]}; do LAYER[$m]=$i; done; done

failures=0
fail_line() { echo "FAIL: $*"; failures=$((failures + 1)); }

# The module folders: src/<module>/ and interp/.
folders=()
for d in "$SRC"/src/*/ "$SRC"/interp/; do [ -d "$d" ] && folders+=("${d%/}"); done
declare -A IS_MODULE
for d in "${folders[@]}"; do IS_MODULE[$(basename "$d")]=1; done

edges=0
for d in "${folders[@]}"; do
  mod=$(basename "$d")
  mine=${LAYER[$mod]:-}
  if [ -z "$mine" ]; then
    fail_line "module '$mod' ($d) is in no layer: place it in LAYERS of $0"
    continue
  fi
  # The modules this folder's CMakeLists.txt links (comments left out).
  links=" $(sed 's/#.*//' "$d/CMakeLists.txt" 2>/dev/null | grep -oE 'whirl::[a-z_]+' |
            sed 's/whirl:://' | sort -u | tr '\n' ' ')"
  for l in $links; do
    [ "$l" = "$mod" ] && continue
    theirs=${LAYER[$l]:-}
    if [ -n "$theirs" ] && [ "$theirs" -ge "$mine" ]; then
      fail_line "$d/CMakeLists.txt links whirl::$l: '$mod' (layer $mine) may link only lower layers, '$l' is layer $theirs"
    fi
  done
  # Every #include "<module>/..." (or <...>) of a source or header in the folder.
  while IFS= read -r hit; do
    file=${hit%%:*}; rest=${hit#*:}; line=${rest%%:*}; text=${rest#*:}
    [[ "$text" =~ include[[:space:]]*[\"\<]([a-z_0-9]+)/ ]] || continue
    inc=${BASH_REMATCH[1]}
    [ "$inc" = "$mod" ] && continue
    [ -n "${IS_MODULE[$inc]:-}" ] || continue  # a third-party header (nlohmann/..., CLI/...)
    edges=$((edges + 1))
    theirs=${LAYER[$inc]:-}
    if [ -z "$theirs" ] || [ "$theirs" -ge "$mine" ]; then
      fail_line "$file:$line: $text: '$mod' (layer $mine) may include only modules of lower layers, '$inc' is layer ${theirs:-none} (an upward include)"
    elif [[ "$links" != *" $inc "* ]]; then
      fail_line "$file:$line: $text: '$mod' includes '$inc' but $d/CMakeLists.txt does not link whirl::$inc"
    fi
  done < <(grep -rnE '^[[:space:]]*#[[:space:]]*include[[:space:]]*["<][a-z_0-9]+/' \
             --include='*.h' --include='*.cpp' "$d")
done

# The scan itself must see the graph: the command line alone includes ten modules.
[ "$edges" -gt 50 ] || fail_line "only $edges includes across modules found: has the layout changed?"
if [ "$failures" -gt 0 ]; then
  echo "$failures violation(s) of the layer order"
  exit 1
fi
echo "layer order holds: ${#IS_MODULE[@]} modules, $edges includes across modules"
