#!/usr/bin/env bash
# Renders every report whirl writes in headless Chromium and checks that each page loads with
# every image present and nothing wider than the window (a long NC line must wrap), and that
# each link of the "load onto the control" box opens a file written with the report.
# Args: <whirl> <scratch dir> <source dir>. Without Chromium (Debian: chromium or
# chromium-headless-shell) it says so loudly and exits 77, which CTest reports as skipped.
# WHIRL_REPORT_SCREENSHOTS=1 also saves <scratch>/{workpiece,machine,drift}.png.
set -u
W="$1"; D="$2"; SRC="$3"
rm -rf "$D"; mkdir -p "$D"
source "$SRC/tests/support/cli_common.sh"

browser=""
for b in chromium chromium-headless-shell chromium-browser google-chrome; do
  if command -v "$b" > /dev/null; then browser="$b"; break; fi
done
if [ -z "$browser" ]; then
  echo "SKIPPED: no headless Chromium found (apt-get install chromium-headless-shell);"
  echo "SKIPPED: the reports were NOT rendered or checked in a browser"
  exit 77
fi
command -v gnuplot > /dev/null || { echo "SKIPPED: gnuplot missing, reports have no plots"; exit 77; }

# The reports: workpiece (demo), machine (demo step 7), drift (on a simulated machine's day log).
(cd "$D" && "$W" demo --out-dir out > demo.txt 2>&1) || fail "demo: $(tail -5 "$D/demo.txt")"
"$W" machine sensors --out-dir "$D/runs" --idle 0 --cutting 1 > /dev/null \
  || fail "machine sensors"
"$W" drift report --train-cutting "$D/runs/cutting_1.csv" --error offset_um \
  --out-dir "$D/drift" > "$D/drift.txt" 2>&1 || fail "drift report: $(tail -5 "$D/drift.txt")"

# Writes probe.html beside a page: the page plus a script that, once everything has loaded,
# records the images that failed and the page's width into the DOM.
probe() {  # probe <index.html>
  sed 's|</body></html>|<script>window.addEventListener("load", () => {\
  const broken = [...document.images].filter(i => !i.complete \|\| i.naturalWidth === 0)\
    .map(i => i.getAttribute("src"));\
  const p = document.createElement("pre"); p.id = "whirl-probe";\
  p.textContent = "WHIRL-PROBE " + JSON.stringify({images: document.images.length, broken,\
    scroll_width: document.documentElement.scrollWidth, window_width: window.innerWidth});\
  document.body.appendChild(p); });</script></body></html>|' "$1" > "$(dirname "$1")/probe.html"
}

check_page() {  # check_page <name> <dir>: images on disk, links of the box, the rendered page
  local name="$1" dir="$2" page="$2/index.html"
  [ -s "$page" ] || fail "$name: no $page"
  local imgs; imgs=$(grep -o "<img src='[^']*'" "$page" | sed "s/<img src='//; s/'$//")
  [ -n "$imgs" ] || fail "$name: no image in the page"
  for f in $imgs; do [ -s "$dir/$f" ] || fail "$name: image $f missing or empty"; done
  local box; box=$(sed -n "/<section class='control'/,/<\/section>/p" "$page")
  for f in $(echo "$box" | grep -o "href='[^']*'" | sed "s/href='//; s/'$//"); do
    [ -s "$dir/$f" ] || fail "$name: the control box links $f, which is missing or empty"
  done
  probe "$page"
  timeout 60 "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
    --allow-file-access-from-files --virtual-time-budget=15000 --window-size=1200,2000 \
    --dump-dom "file://$dir/probe.html" > "$D/$name.dom" 2> "$D/$name.browser.log" \
    || fail "$name: $browser failed: $(tail -3 "$D/$name.browser.log")"
  local result; result=$(grep -o 'WHIRL-PROBE {.*}' "$D/$name.dom" | sed 's/^WHIRL-PROBE //')
  [ -n "$result" ] || fail "$name: the page did not finish loading in $browser"
  python3 - "$name" "$result" << 'PY' || exit 1
import json, sys
name, r = sys.argv[1], json.loads(sys.argv[2])
if r["images"] == 0: sys.exit(f"FAIL: {name}: the browser saw no image")
if r["broken"]: sys.exit(f"FAIL: {name}: images not loaded: {r['broken']}")
if r["scroll_width"] > r["window_width"]:
    sys.exit(f"FAIL: {name}: page {r['scroll_width']} px wide in a {r['window_width']} px window")
print(f"{name}: {r['images']} images loaded, width {r['scroll_width']} px")
PY
  rm -f "$dir/probe.html"
  if [ "${WHIRL_REPORT_SCREENSHOTS:-0}" = 1 ]; then  # for a person to look at (about 1.5 s each)
    timeout 60 "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
      --window-size=1200,3000 --screenshot="$D/$name.png" "file://$page" > /dev/null 2>&1
    [ -s "$D/$name.png" ] || fail "$name: no screenshot"
  fi
}

check_page workpiece "$D/out/report"
grep -q "<section class='control'" "$D/out/report/index.html" || fail "workpiece: no control box"
check_page machine "$D/out/machine_report"
grep -q "<section class='control'" "$D/out/machine_report/index.html" || fail "machine: no control box"
check_page drift "$D/drift"
echo "OK"
