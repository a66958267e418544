#!/usr/bin/env bash
# layer_order.sh must fail on each kind of violation: it runs on copies of src/ and interp/
# with one wrong edge added each time (an upward include into core, an include the CMake links
# do not declare, a folder in no layer, a link to a higher layer) and must exit 1 naming it;
# on the unchanged copy it must pass. args: <source dir> <scratch dir>.
set -u
SRC="$1"; D="$2"
CHECK="$SRC/tests/structure/layer_order.sh"
fresh() {  # a copy of the module folders (and the script's view of the tree) in $D/tree
  rm -rf "$D"; mkdir -p "$D/tree"
  cp -r "$SRC/src" "$SRC/interp" "$D/tree/"
}
expect_failure() {  # expect_failure <what> <text the message must hold>
  bash "$CHECK" "$D/tree" > "$D/out.txt" 2>&1; local rc=$?
  if [ $rc -ne 1 ] || ! grep -qF -- "$2" "$D/out.txt"; then
    echo "FAIL: $1 not caught (exit $rc, expected a message with '$2'):"; cat "$D/out.txt"; exit 1
  fi
  echo "caught: $1: $(grep -F -- "$2" "$D/out.txt" | head -1)"
}

fresh
bash "$CHECK" "$D/tree" > "$D/out.txt" 2>&1 || { echo "FAIL: the unchanged copy fails:"; cat "$D/out.txt"; exit 1; }

fresh  # core (the bottom) including the strategy comparison
sed -i '0,/^#include "core\/csv.h"/s//#include "core\/csv.h"\n#include "compare\/compare.h"/' \
  "$D/tree/src/core/csv.cpp"
expect_failure "an upward include" 'src/core/csv.cpp:'

fresh  # a module including another of the same layer (drift and fit)
echo '#include "fit/arctan_curve.h"' >> "$D/tree/src/drift/model.h"
expect_failure "a same-layer include" "'drift' (layer 2) may include only modules of lower layers, 'fit' is layer 2"

fresh  # a lower module, but not linked (drift does not link gp)
echo '#include "gp/gp.h"' >> "$D/tree/src/drift/fit.cpp"
expect_failure "an include not linked" "does not link whirl::gp"

fresh  # a new folder nobody placed
mkdir -p "$D/tree/src/newroom"; echo '#include "core/error.h"' > "$D/tree/src/newroom/a.cpp"
expect_failure "a folder in no layer" "module 'newroom'"

fresh  # a link to a higher layer
echo 'target_link_libraries(whirl_sim PRIVATE whirl::compare)' >> "$D/tree/src/sim/CMakeLists.txt"
expect_failure "an upward link" "links whirl::compare"
echo "every kind of violation is caught"
