#!/usr/bin/env bash
# The include graph of the library and the command line against the architecture
# (docs/development.md, "Architecture"): two sides and a layer order.
#   product  src/product/<module>/ and interp/: what a shop runs. A product module may include or
#            link no lab module: a violation fails with "product module ... lab module".
#   lab      src/lab/<module>/: simulators, machine worlds, comparisons and evaluations, on top
#            of the product.
#   cli      src/cli/: the command line on top of both.
# Within the order a module may include headers only of modules in a lower layer, and its
# CMakeLists.txt must link each of them (whirl::<module>). A module in no layer or on the wrong
# side, an include of a module of the same or a higher layer (an upward edge, the start of a
# cycle), an include the CMake links do not declare, or an include by tree path ("src/lab/...",
# which the project root, an include root of interp, would resolve) fails with the file, the line
# and the rule.
# args: <source dir>. The layers, from the bottom (the CMake links of each folder, made strict:
# no two modules of one layer include each other); every product layer lies below every lab
# layer:
PRODUCT_LAYERS=(
  "core"                       # errors, CSV, JSON, numbers, atomic files, curves, parallel-for
  "screw lead nn gp fit"       # the screw, lead metrics, the network, Gaussian processes, curve
                               # fits and features (core only)
  "family drift"               # model families (gp, nn), drift (nn)
  "interp workpiece"           # 840D output (drift, fit), the workpiece model (family, nn)
  "plan ballbar surface design"  # plan files (interp, screw), ball bar (interp), worktable (drift,
                               # interp), which screws to measure (workpiece)
)
LAB_LAYERS=(
  "sim torch synthetic"        # the simulator, the LibTorch cross-check (nn), synthetic ball-bar
                               # and worktable data (ballbar, surface)
  "machine compare"            # machine worlds (drift, sim), strategy comparison (sim, interp, ...)
  "machine_eval"               # the machine evaluation (compare, machine)
  "machine_report"             # one screw's report and combined programs (machine_eval)
)
CLI_LAYERS=("cli")             # the command line: parses and calls the library
set -u
SRC="$1"

declare -A LAYER  # module -> its index in the whole order (product, then lab, then cli)
declare -A SIDE   # module -> the side its layer list names
LAYERS=("${PRODUCT_LAYERS[@]}" "${LAB_LAYERS[@]}" "${CLI_LAYERS[@]}")
for i in "${!LAYERS[@]}"; do
  side=cli
  [ "$i" -lt $(( ${#PRODUCT_LAYERS[@]} + ${#LAB_LAYERS[@]} )) ] && side=lab
  [ "$i" -lt "${#PRODUCT_LAYERS[@]}" ] && side=product
  for m in ${LAYERS[$i]}; do LAYER[$m]=$i; SIDE[$m]=$side; done
done

failures=0
fail_line() { echo "FAIL: $*"; failures=$((failures + 1)); }

# The module folders and the side their place in the tree gives them.
folders=()
declare -A FOLDER_SIDE
add_folder() { [ -d "$1" ] && folders+=("${1%/}") && FOLDER_SIDE[$(basename "$1")]=$2; }
for d in "$SRC"/src/product/*/ "$SRC"/interp/; do add_folder "$d" product; done
for d in "$SRC"/src/lab/*/; do add_folder "$d" lab; done
add_folder "$SRC"/src/cli/ cli
for d in "$SRC"/src/*/; do  # a folder directly under src/ other than the three sides
  case "$(basename "$d")" in product | lab | cli) ;;
    *) fail_line "folder $d is on no side: move it under src/product/ or src/lab/" ;;
  esac
done
declare -A IS_MODULE
for d in "${folders[@]}"; do IS_MODULE[$(basename "$d")]=1; done

edges=0
for d in "${folders[@]}"; do
  mod=$(basename "$d")
  mine=${LAYER[$mod]:-}
  if [ -z "$mine" ]; then
    fail_line "module '$mod' ($d) is in no layer: place it in the layers of its side in $0"
    continue
  fi
  if [ "${SIDE[$mod]}" != "${FOLDER_SIDE[$mod]}" ]; then
    fail_line "module '$mod' ($d) lies on the ${FOLDER_SIDE[$mod]} side but its layer is listed among the ${SIDE[$mod]} layers"
    continue
  fi
  # The modules this folder's CMakeLists.txt links (comments left out).
  links=" $(sed 's/#.*//' "$d/CMakeLists.txt" 2>/dev/null | grep -oE 'whirl::[a-z_]+' |
            sed 's/whirl:://' | sort -u | tr '\n' ' ')"
  for l in $links; do
    [ "$l" = "$mod" ] && continue
    theirs=${LAYER[$l]:-}
    if [ "${FOLDER_SIDE[$mod]}" = product ] && [ "${FOLDER_SIDE[$l]:-}" = lab ]; then
      fail_line "$d/CMakeLists.txt links whirl::$l: product module '$mod' may link no lab module ('$l' is lab)"
    elif [ -n "$theirs" ] && [ "$theirs" -ge "$mine" ]; then
      fail_line "$d/CMakeLists.txt links whirl::$l: '$mod' (layer $mine) may link only lower layers, '$l' is layer $theirs"
    fi
  done
  # Every #include "<module>/..." (or <...>) of a source or header in the folder.
  while IFS= read -r hit; do
    file=${hit%%:*}; rest=${hit#*:}; line=${rest%%:*}; text=${rest#*:}
    [[ "$text" =~ include[[:space:]]*[\"\<]([a-z_0-9]+)/ ]] || continue
    inc=${BASH_REMATCH[1]}
    if [ "$inc" = src ]; then  # "src/lab/sim/..." would pass the include roots by the back door
      fail_line "$file:$line: $text: include by tree path: name the module (\"sim/...\"), not src/"
      continue
    fi
    [ "$inc" = "$mod" ] && continue
    [ -n "${IS_MODULE[$inc]:-}" ] || continue  # a third-party header (nlohmann/..., CLI/...)
    edges=$((edges + 1))
    theirs=${LAYER[$inc]:-}
    if [ "${FOLDER_SIDE[$mod]}" = product ] && [ "${FOLDER_SIDE[$inc]}" = lab ]; then
      fail_line "$file:$line: $text: product module '$mod' may include no lab module ('$inc' is lab)"
    elif [ -z "$theirs" ] || [ "$theirs" -ge "$mine" ]; then
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
n_product=0; n_lab=0
for m in "${!FOLDER_SIDE[@]}"; do
  case "${FOLDER_SIDE[$m]}" in product) n_product=$((n_product + 1)) ;; lab) n_lab=$((n_lab + 1)) ;; esac
done
echo "layer order holds: ${#IS_MODULE[@]} modules ($n_product product, $n_lab lab, the command line), $edges includes across modules; no product module includes or links a lab module"
