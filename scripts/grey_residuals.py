#!/usr/bin/env python3
"""Where the grey box's lead error goes, per screw of a `whirl machine evaluate --json` run.

Usage: scripts/grey_residuals.py EVAL.json   (EVAL.json: `whirl machine evaluate ... --json`)

Per scenario, medians over every screw of every seed (um): the accumulated lead error over the
thread (total), its slope part |b| x l_u (b: the slope of the residual's mean travel line, l_u the
useful travel) and its band v_u about that line (what changes along the cut), the mean and sd of
b (um/m), for both_grey, both_shop, the strongest sensor-free rule and the workpiece plan alone;
then per start type; the workpiece plan's own residual (both_shop's residual_workpiece_total_um,
the same plan in every both_* row); and what a per-screw choice with hindsight of the better of
two models would leave beside the 30 % line (0.7 x the strongest sensor-free rule's median).
Simulator figures only.
"""
import json
import math
import statistics as st
import sys


def corr(a, b):
    ma, mb = sum(a) / len(a), sum(b) / len(b)
    den = math.sqrt(sum((x - ma) ** 2 for x in a) * sum((y - mb) ** 2 for y in b))
    return sum((x - ma) * (y - mb) for x, y in zip(a, b)) / den if den > 0 else float("nan")


def screws(scenario):
    for run in scenario["runs"]:
        for s in run["screws"]:
            if s.get("ok"):
                yield s


def parts(s, name):
    m = s["strategies"][name]["metrics"]
    b = m["mean_line_slope_um_per_m"]
    return {"total": m["accumulated_total_um"], "slope": abs(b) * m["useful_travel_mm"] / 1000,
            "band": m["v_u_um"], "b": b, "w1000": m["accumulated_1000_um"]}


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    try:
        doc = json.load(open(sys.argv[1]))
        scenarios = doc["scenarios"]
    except (OSError, ValueError, KeyError) as e:
        sys.exit(f"grey_residuals.py: {sys.argv[1]}: not a `whirl machine evaluate --json` file ({e})")
    for sc in scenarios:
        sf = sc["strongest_sensor_free"]
        rows = list(screws(sc))
        if not rows:
            print(f"{sc['scenario']}: no screw evaluated")
            continue
        print(f"{sc['scenario']} (seeds {sc['seeds']}): {len(rows)} screws, strongest "
              f"sensor-free {sf}")
        print("  model        total  slope  band   b mean  b sd  within 1000 mm")
        for name in ("both_grey", "both_shop", sf, "workpiece"):
            p = [parts(s, name) for s in rows]
            med = {k: st.median(x[k] for x in p) for k in ("total", "slope", "band", "w1000")}
            bs = [x["b"] for x in p]
            print(f"  {name:11s} {med['total']:6.2f} {med['slope']:6.2f} {med['band']:6.2f} "
                  f"{st.mean(bs):+7.2f} {st.pstdev(bs):5.2f} {med['w1000']:6.2f}")
        for start in sorted({s["start_type"] for s in rows}):
            sub = [s for s in rows if s["start_type"] == start]
            m = {n: st.median(parts(s, n)["total"] for s in sub) for n in ("both_grey", "both_shop", sf)}
            print(f"  start {start:11s} n={len(sub):3d}: both_grey {m['both_grey']:.2f}, both_shop "
                  f"{m['both_shop']:.2f}, {sf} {m[sf]:.2f}")
        g = [parts(s, "both_grey")["total"] for s in rows]
        f = [parts(s, sf)["total"] for s in rows]
        h = [parts(s, "both_shop")["total"] for s in rows]
        line = 0.7 * st.median(f)
        print(f"  workpiece plan's own residual (median) {st.median(s['residual_workpiece_total_um'] for s in rows):.2f}")
        print(f"  corr(both_grey, {sf}) per screw {corr(g, f):.2f}; slopes both_grey/both_shop "
              f"{corr([parts(s, 'both_grey')['b'] for s in rows], [parts(s, 'both_shop')['b'] for s in rows]):.2f}")
        print(f"  30 % line {line:.2f}; better of both_grey and {sf} per screw (hindsight) "
              f"{st.median(min(a, b) for a, b in zip(g, f)):.2f}; of both_grey and both_shop "
              f"{st.median(min(a, b) for a, b in zip(g, h)):.2f}")


if __name__ == "__main__":
    main()
