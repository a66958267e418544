#!/usr/bin/env bash
# Renders every report whirl writes (workpiece, machine, drift model, drift hold-out, monitor,
# monitor week, surface; all through core/report_render.h) in headless Chromium and checks that
# each page loads with every image present; nothing is wider than the window and no table
# scrolls inside itself (a long NC line must wrap, a wide table must fit); the "load onto the
# control" box is there (every report but the surface map, which has no program) and each of its
# links opens a file written with the report; every legend entry names a series of the page's
# table of strategies (methods, rules) and every one of those is in a legend; no two
# strategies share a colour (the truth, the prediction and the residual are not strategies); and
# every plotted prediction (a line of a strategy, method or rule but none) has its +-1 sd band
# in the same figure; a series without a look (a sensor) has one colour in every figure, no
# two alike.
# Args: <whirl> <scratch dir> <source dir>. Without Chromium (Debian: chromium or
# chromium-headless-shell) it says so loudly and exits 77, which CTest reports as skipped.
# WHIRL_REPORT_SCREENSHOTS=1 also saves <scratch>/<report>.png for each.
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
"$W" drift holdout --log "$D/runs/cutting_1.csv" --channels offset_um --no-network \
  --out-dir "$D/holdout" > "$D/holdout.txt" 2>&1 || fail "holdout: $(tail -5 "$D/holdout.txt")"
"$W" drift fit --run "$D/runs/cutting_1.csv" --error offset_um --out "$D/m.json" > /dev/null 2>&1 \
  || fail "drift fit"
"$W" drift monitor --model "$D/m.json" --run "$D/runs/cutting_1.csv" --out-dir "$D/monitor" \
  > "$D/monitor.txt" 2>&1 || fail "monitor: $(tail -5 "$D/monitor.txt")"
"$W" drift monitor --model "$D/m.json" --day "$D/runs/cutting_1.csv" --day "$D/runs/cutting_1.csv" \
  --out-dir "$D/week" > "$D/week.txt" 2>&1 || fail "monitor week: $(tail -5 "$D/week.txt")"
"$W" surface synth --field smooth --out "$D/points.csv" > /dev/null || fail "surface synth"
"$W" surface fit --points "$D/points.csv" --out "$D/s.json" --out-dir "$D/surface" > /dev/null \
  2>&1 || fail "surface fit"

# Writes probe.html beside a page: the page plus a script that, once everything has loaded,
# records into the DOM the images that failed, the page's width, the tables that scroll, the
# load box, each legend entry (data-series, data-colour) and the names of the tables of series.
probe() {  # probe <index.html>
  sed 's|</body></html>|<script>window.addEventListener("load", () => {\
  const broken = [...document.images].filter(i => !i.complete \|\| i.naturalWidth === 0)\
    .map(i => i.getAttribute("src"));\
  const scrolling = [...document.querySelectorAll("table, pre")]\
    .filter(t => t.scrollWidth > t.clientWidth + 1).map(t => t.textContent.slice(0, 60));\
  const legend = [...document.querySelectorAll("ul.legend li[data-series]")]\
    .map(li => [li.dataset.series, li.dataset.colour]);\
  const named = [...document.querySelectorAll("table.series td[data-series]")]\
    .map(td => td.dataset.series);\
  const unnamed = [...document.querySelectorAll("ul.legend li:not([data-series])")]\
    .map(li => [li.textContent, li.dataset.colour]);\
  const figures = [...document.querySelectorAll("figure")].map(f =>\
    [...f.querySelectorAll("ul.legend li[data-series]")].map(li => [li.dataset.series, li.dataset.kind]));\
  const p = document.createElement("pre"); p.id = "whirl-probe";\
  p.textContent = "WHIRL-PROBE " + JSON.stringify({images: document.images.length, broken,\
    scroll_width: document.documentElement.scrollWidth, window_width: window.innerWidth,\
    scrolling, legend, named, unnamed, figures, load_box: document.querySelectorAll("section.control#load").length});\
  document.body.appendChild(p); });</script></body></html>|' "$1" > "$(dirname "$1")/probe.html"
}

check_page() {  # check_page <name> <dir> [nobox]: files on disk, links of the box, the rendered page
  local name="$1" dir="$2" page="$2/index.html" box_wanted="${3:-box}"
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
  python3 - "$name" "$result" "$box_wanted" << 'PY' || exit 1
import json, sys
name, r, box = sys.argv[1], json.loads(sys.argv[2]), sys.argv[3]
def fail(msg): sys.exit(f"FAIL: {name}: {msg}")
if r["images"] == 0: fail("the browser saw no image")
if r["broken"]: fail(f"images not loaded: {r['broken']}")
if r["scroll_width"] > r["window_width"]:
    fail(f"page {r['scroll_width']} px wide in a {r['window_width']} px window")
if r["scrolling"]: fail(f"tables or text wider than the page: {r['scrolling']}")
if box == "box" and r["load_box"] != 1: fail(f"{r['load_box']} load boxes, want 1")
looks = {"measured", "prediction", "residual"}  # the truth and the model's curve: no strategy
colour = {}
for series, c in r["legend"]:
    if series in looks: continue
    if colour.setdefault(series, c) != c: fail(f"{series} drawn in {colour[series]} and {c}")
shared = {}
for series, c in colour.items():
    if c in shared: fail(f"{series} and {shared[c]} share the colour {c}")
    shared[c] = series
# Every plotted prediction (a line in the look of a strategy, method or rule, or the model's
# prediction) has its +-1 sd band, in the same look, in the same figure; only the truth, the
# residual and none (no compensation, nothing predicted) have none.
unbanded = {"measured", "residual", "none"}
for i, fig in enumerate(r["figures"]):
    banded = {s for s, kind in fig if kind == "band"}
    if "prediction" in banded: banded.add("model")  # the model's plan follows the prediction
    for s, kind in fig:
        if kind == "line" and s not in unbanded and s not in banded:
            fail(f"figure {i + 1}: the prediction {s} is plotted without its +-1 sd band")
# Series without a look (sensors): one colour per name in every figure, no two names alike.
drawn = {}
for title, c in r["unnamed"]:
    if drawn.setdefault(title, c) != c: fail(f"{title} drawn in {drawn[title]} and {c}")
if len(set(drawn.values())) != len(drawn):
    fail(f"series without a look share colours: {sorted(drawn.items(), key=lambda x: x[1])}")
named = set(r["named"])
if name in ("workpiece", "machine", "holdout", "monitor", "week") and not named:
    fail("no table of strategies (data-series) on the page")
if named:
    if not set(colour) <= named: fail(f"legend names {sorted(set(colour) - named)} not in the table")
    if not named <= set(colour): fail(f"strategies {sorted(named - set(colour))} in no legend")
print(f"{name}: {r['images']} images loaded, width {r['scroll_width']} px, "
      f"{len(colour)} strategies in the legends, {len(named)} in the table")
PY
  rm -f "$dir/probe.html"
  if [ "${WHIRL_REPORT_SCREENSHOTS:-0}" = 1 ]; then  # for a person to look at (about 1.5 s each)
    timeout 60 "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
      --window-size=1200,3000 --screenshot="$D/$name.png" "file://$page" > /dev/null 2>&1
    [ -s "$D/$name.png" ] || fail "$name: no screenshot"
  fi
}

check_page workpiece "$D/out/report"
check_page machine "$D/out/machine_report"
check_page drift "$D/drift"
check_page holdout "$D/holdout"
check_page monitor "$D/monitor"
check_page week "$D/week"
check_page surface "$D/surface" nobox
echo "OK"
