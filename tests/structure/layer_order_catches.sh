#!/usr/bin/env bash
# layer_order.sh must fail on each kind of violation: it runs on copies of src/ and interp/
# with one wrong edge added each time (a product module including or linking a lab module, a lab
# header included by its tree path, an upward include into core, a same-layer include, an include
# the CMake links do not declare, a folder in no layer, on the wrong side or on no side, a link to
# a higher layer) and must exit 1
# naming it; on the unchanged copy it must pass. args: <source dir> <scratch dir>.
set -u
SRC="$1"; D="$2"
CHECK="$SRC/tests/structure/layer_order.sh"
P="$D/tree/src/product"; L="$D/tree/src/lab"
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

fresh  # a product module (drift) including a lab module (the machine world)
echo '#include "machine/scenarios.h"' >> "$P/drift/fit.cpp"
expect_failure "a product module including a lab module" \
  "product module 'drift' may include no lab module ('machine' is lab)"

fresh  # the product's 840D output (interp/, at the top level) including the strategy comparison
echo '#include "compare/compare.h"' >> "$D/tree/interp/sinumerik.h"
expect_failure "interp including a lab module" \
  "product module 'interp' may include no lab module ('compare' is lab)"

fresh  # a lab header reached by its path in the tree (the project root is an include root of interp)
echo '#include "src/lab/sim/simulator.h"' >> "$P/surface/surface.cpp"
expect_failure "an include by tree path" "include by tree path"

fresh  # a product module linking a lab module, without any include
echo 'target_link_libraries(whirl_surface PRIVATE whirl::sim)' >> "$P/surface/CMakeLists.txt"
expect_failure "a product module linking a lab module" \
  "product module 'surface' may link no lab module ('sim' is lab)"

fresh  # core (the bottom) including a product module above it
sed -i '0,/^#include "core\/csv.h"/s//#include "core\/csv.h"\n#include "drift\/model.h"/' \
  "$P/core/csv.cpp"
expect_failure "an upward include" 'src/product/core/csv.cpp:'

fresh  # a module including another of the same layer (drift and family)
echo '#include "family/family.h"' >> "$P/drift/model.h"
expect_failure "a same-layer include" "'drift' (layer 2) may include only modules of lower layers, 'family' is layer 2"

fresh  # a lower module, but not linked (drift does not link gp)
echo '#include "gp/gp.h"' >> "$P/drift/fit.cpp"
expect_failure "an include not linked" "does not link whirl::gp"

fresh  # a lab module including a lab module above it (the simulator including the machine world)
echo '#include "machine/field.h"' >> "$L/sim/simulator.cpp"
expect_failure "an upward include in the lab" "'sim' (layer"

fresh  # a new folder nobody placed
mkdir -p "$P/newroom"; echo '#include "core/error.h"' > "$P/newroom/a.cpp"
expect_failure "a folder in no layer" "module 'newroom'"

fresh  # a lab module moved to the product side (its layer is among the lab layers)
mv "$L/machine" "$P/machine"
expect_failure "a module on the wrong side" "module 'machine' ($P/machine) lies on the product side"

fresh  # a folder directly under src/, on no side
mkdir -p "$D/tree/src/stray"; echo '#include "core/error.h"' > "$D/tree/src/stray/a.cpp"
expect_failure "a folder on no side" "is on no side"

fresh  # a link to a higher layer
echo 'target_link_libraries(whirl_sim PRIVATE whirl::compare)' >> "$L/sim/CMakeLists.txt"
expect_failure "an upward link" "links whirl::compare"
echo "every kind of violation is caught"
