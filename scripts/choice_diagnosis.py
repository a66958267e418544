#!/usr/bin/python3
"""The thirteenth attempt's diagnosis at 20 rows (docs/workpiece-history.md, "Thirteenth attempt:
diagnosis at 20 rows"): from bench_peers.py --json files holding, per table, the default
("default") and each candidate alone (family_bench --candidates NAME --no-cv: linlog, linid,
gplog, gpm52, gpse, net), and on some tables the peers:
  1. per failing cell, the median's % above the best peer's median (tables with peers) and each
     candidate's geometric mean ratio of test RMSE to the default's (all tables); "oracle" the
     per-table best candidate in hindsight;
  2. which candidates the default gives weight to;
  3. coverage: +-1 / +-2 sd, the spread of the test residuals and of the held-out residuals
     (the candidates' cv_rmse the choice saw) against the sd;
  4. single-candidate choices against the same candidate alone, and selection optimism.
A cell whose family no file holds is left out; without tables that hold every peer the peer
columns read "-"; the +-1 sd coverage of 10-table blocks needs seeds of one block (1-10, 11-20,
...) all present ("-" otherwise).
--cells FAMILY/ROWS/OUT,... (e.g. friedman23/20/out1): these cells instead, each on its tables of
ROWS rows only, in every section (the 40-table diagnosis of the acceptance's five cells behind,
section "Where the five cells lose").
Usage: scripts/choice_diagnosis.py [--cells FAMILY/ROWS/OUT,...] d_1_20.json d_4001_20.json ..."""
import json
import math
import sys

import numpy as np

ACCEPT = ["loglinear", "gp_ard", "mlp_default", "mlp_cv", "brnn_whirl"]
CANDS = ["linlog", "linid", "gplog", "gpm52", "gpse", "net"]
args = sys.argv[1:]
CELL_SPEC = None
if args[:1] == ["--cells"]:
    if len(args) < 2:
        sys.exit(__doc__)
    try:
        CELL_SPEC = [(f, int(n), {"out1": 0, "out2": 1}[o]) for f, n, o in
                     (c.split("/") for c in args[1].split(","))]
    except (ValueError, KeyError):
        sys.exit(f"choice_diagnosis.py: --cells {args[1]}: each cell must be FAMILY/ROWS/out1|out2")
    args = args[2:]
if not args:
    sys.exit(__doc__)
try:
    recs = [r for f in args for r in json.load(open(f))]
except (OSError, ValueError) as e:
    sys.exit(f"choice_diagnosis.py: not a bench_peers.py --json file: {e}")
ok = lambda r, m: m in r["methods"] and "rmse" in r["methods"][m]
RMSE_CELLS = [("powerlaw", 1), ("friedman", 0), ("friedman", 1), ("additive", 0), ("additive", 1),
              ("friedman23", 0), ("friedman23", 1), ("powerlaw_noisy", 0), ("hetero", 1)]
COV_CELLS = [("friedman", 1), ("hetero", 1), ("saturating", 1), ("simgen", 0), ("simgen", 1)]
if CELL_SPEC:  # (family, output, rows): the cell's tables of those rows only
    RMSE_CELLS = COV_CELLS = [(f, k, n) for f, n, k in CELL_SPEC]


def cell_recs(cell):
    """The tables of a cell (family, output[, rows]) that hold the default."""
    return [r for r in recs if r["problem"] == cell[0] and ok(r, "default")
            and (len(cell) < 3 or r["rows"] == cell[2])]


def label(cell):
    return f"{cell[0]} {cell[2]} rows out{cell[1] + 1}" if len(cell) > 2 else f"{cell[0]} out{cell[1] + 1}"


def rmse(r, m, k):
    return r["methods"][m]["rmse"][k]


def pct(a, b):
    return 100 * (a / b - 1)


print(f"| cell | best peer, {'' if CELL_SPEC else 'tuning '}seeds with peers (n) | default | "
      + " | ".join(CANDS) + " | oracle |")
print("|" + "---|" * (4 + len(CANDS)))
for cell in RMSE_CELLS:
    k = cell[1]
    rs = cell_recs(cell)
    if not rs:
        continue
    wp = [r for r in rs if all(ok(r, p) for p in ACCEPT)]
    med = {p: np.median([rmse(r, p, k) for r in wp]) for p in ACCEPT} if wp else {}
    best = min(med, key=med.get) if wp else None
    above = lambda v: f"{pct(np.median(v), med[best]):+.1f} %" if wp else "-"  # noqa: E731
    cells = []
    for m in ["default"] + CANDS:
        mp = above([rmse(r, m, k) for r in wp])
        g = math.exp(np.mean([math.log(rmse(r, m, k) / rmse(r, "default", k)) for r in rs]))
        cells.append(mp if m == "default" else f"{mp} / {g:.2f}")
    orc = [min(rmse(r, m, k) for m in CANDS) for r in rs]
    og = math.exp(np.mean([math.log(o / rmse(r, "default", k)) for o, r in zip(orc, rs)]))
    om = above([min(rmse(r, m, k) for m in CANDS) for r in wp])
    peer = f"{best} {med[best]:.4g} ({len(wp)})" if wp else "- (0)"
    print(f"| {label(cell)} | {peer} | " + " | ".join(cells) + f" | {om} / {og:.2f} ({len(rs)}) |")

# which candidates the default gives weight to, per cell (share of tables where it appears)
print()
for cell in dict.fromkeys(RMSE_CELLS + COV_CELLS):  # friedman out2 is in both
    k = cell[1]
    rs = cell_recs(cell)
    if not rs:
        continue
    outname = ["max_elongation_um", "settle_time_s"][k]
    cnt = {}
    for r in rs:
        desc = [p for p in r["methods"]["default"]["chosen"].split(", ") if p.startswith(outname)][0]
        for part in desc.split(": ", 1)[1].split(" + "):
            name = part.split(" ")[-1]
            cnt[name] = cnt.get(name, 0) + 1
    print(f"{label(cell)} ({len(rs)} tables): " + ", ".join(f"{n} {c}" for n, c in
                                                         sorted(cnt.items(), key=lambda x: -x[1])))

# coverage: test residual spread / sd, held-out RMSE / sd, per method
print()
NAMES = {"linlog": "linear/log", "linid": "linear/identity", "gplog": "gp-matern52-linear/log",
         "gpm52": "gp-matern52-constant/identity", "gpse": "gp-se-constant/identity",
         "net": "network-h2/identity"}
print("| cell | method | cov +-1 / +-2 sd | 10-table blocks +-1 sd min-max | test resid / sd | held-out / sd | test resid / held-out |")
print("|---|---|---|---|---|---|---|")
for cell in COV_CELLS:
    k = cell[1]
    rs = cell_recs(cell)
    if not rs:
        continue
    for m in ["default"] + CANDS:
        mm = [r["methods"][m] for r in rs]
        c1 = 100 * np.mean([x["cover1"][k] for x in mm]); c2 = 100 * np.mean([x["cover2"][k] for x in mm])
        tr = math.exp(np.mean([math.log(x["resid_rms"][k] / x["sd_rms"][k]) for x in mm]))
        if m == "default":
            ho = [min(v[k] for v in r["methods"]["default"]["cv_rmse"].values()) for r in rs]
        else:
            ho = [r["methods"]["default"]["cv_rmse"].get(NAMES[m], [math.nan, math.nan])[k] for r in rs]
        hs = math.exp(np.nanmean([math.log(h / x["sd_rms"][k]) for h, x in zip(ho, mm)]))
        th = math.exp(np.nanmean([math.log(x["resid_rms"][k] / h) for h, x in zip(ho, mm)]))
        blocks = {}
        for r, x in zip(rs, mm):
            blocks.setdefault((r["seed"] - 1) // 10, []).append(x["cover1"][k])
        bm = [100 * np.mean(v) for v in blocks.values() if len(v) == 10]
        span = f"{min(bm):.0f}-{max(bm):.0f}" if bm else "-"
        print(f"| {label(cell)} ({len(rs)}) | {m} | {c1:.0f} / {c2:.0f} | {span} ({len(bm)}) | {tr:.2f} | {hs:.2f} | {th:.2f} |")

# Single-candidate choices: the default's sd (after its narrowing to the held-out residuals)
# against the same candidate fitted alone (its own calibration, no narrowing), all families.
print()
INV = {v: k for k, v in NAMES.items()}
rows = {}
low = []
for r in recs:
    if not ok(r, "default"):
        continue
    for k, outname in enumerate(["max_elongation_um", "settle_time_s"]):
        desc = [p for p in r["methods"]["default"]["chosen"].split(", ") if p.startswith(outname)][0]
        c = desc.split(": ", 1)[1]
        d = r["methods"]["default"]
        if d["cover1"][k] < 0.45:
            low.append((r["problem"], r["seed"], k + 1, d["cover1"][k], c))
        if " " in c or INV.get(c) is None:
            kind = "stack"
            rows.setdefault(kind, []).append((d["cover1"][k], d["cover2"][k], math.nan, d["resid_rms"][k] / d["sd_rms"][k]))
            continue
        a = r["methods"][INV[c]]
        kind = "single " + c
        rows.setdefault(kind, []).append((d["cover1"][k], d["cover2"][k], d["sd_rms"][k] / a["sd_rms"][k],
                                          d["resid_rms"][k] / d["sd_rms"][k], a["cover1"][k], a["cover2"][k]))
print(f"| the default's choice for an output ({'all tables of the files' if CELL_SPEC else 'all tuning tables, 8 families'}) | outputs | cov +-1 / +-2 sd | sd / the candidate alone's sd | test resid / sd | the candidate alone: cov +-1 / +-2 |")
print("|---|---|---|---|---|---|")
for kind, v in sorted(rows.items(), key=lambda x: -len(x[1])):
    v = np.array([list(t) + [math.nan] * (6 - len(t)) for t in v])
    print(f"| {kind} | {len(v)} | {100*np.mean(v[:,0]):.0f} / {100*np.mean(v[:,1]):.0f} | "
          f"{math.exp(np.nanmean(np.log(v[:,2]))) if kind != 'stack' else float('nan'):.2f} | "
          f"{math.exp(np.mean(np.log(v[:,3]))):.2f} | "
          + (f"{100*np.nanmean(v[:,4]):.0f} / {100*np.nanmean(v[:,5]):.0f} |" if kind != "stack" else "- |"))
print(f"\noutputs with +-1 sd coverage below 45 % ({len(low)}):")
for t in low:
    print(" ", t[0], t[1], f"out{t[2]}", f"{100*t[3]:.0f} %", t[4])

# Selection optimism: a candidate's test residual spread over its held-out RMSE, on the outputs
# where the default chose it alone, against all outputs (the same candidate fitted alone).
print()
print("| candidate | test resid / held-out: chosen alone (n) | all tables (n) |")
print("|---|---|---|")
for m, name in NAMES.items():
    ch, al = [], []
    for r in recs:
        if not ok(r, "default") or not ok(r, m):
            continue
        for k, outname in enumerate(["max_elongation_um", "settle_time_s"]):
            h = r["methods"]["default"]["cv_rmse"].get(name)
            if not h:
                continue
            v = math.log(r["methods"][m]["resid_rms"][k] / h[k])
            al.append(v)
            desc = [p for p in r["methods"]["default"]["chosen"].split(", ") if p.startswith(outname)][0]
            if desc.split(": ", 1)[1] == name:
                ch.append(v)
    print(f"| {name} | {math.exp(np.mean(ch)) if ch else float('nan'):.2f} ({len(ch)}) | {math.exp(np.mean(al)):.2f} ({len(al)}) |")
