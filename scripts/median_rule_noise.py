#!/usr/bin/python3
"""How noisy is "median test RMSE within 1 % of the best peer's median", and the acceptance's
verdicts per cell with intervals.

usage: median_rule_noise.py RUN.json [RUN.json ...]
       median_rule_noise.py --verdicts [--draws B] [--twins T] [--method NAME] [--against NAME]
                            RUN.json [RUN.json ...]
(bench_peers.py --json files holding the default as "current" and the peers loglinear, gp_ard,
mlp_default, mlp_cv, brnn_whirl on the same tables; with --verdicts the records of one table in
several files are merged).

Without --verdicts (docs/workpiece-history.md, "Seventeenth attempt: how noisy is the 1 % rule at
10 tables"): per (family, output) cell it draws 10 of the cell's tables many times and counts how
often each method's median is more than 1 % above the lowest median of the other peers, and the
same for a twin of the cell's best peer (its RMSE times the default's centred per-table log
ratio: equal to the best peer in median).

--verdicts (docs/workpiece-history.md, "Acceptance measured at N tables per cell: split"): per
(family, rows, output) cell of N tables, R = the default's median / the lowest peer median, with a
90 % interval from a paired bootstrap over the cell's tables (the best peer recomputed in each
draw): "behind" if its lower end > 1.01, "within" if its upper end <= 1.01, else "undecided"; the
default's mean +-1 / +-2 sd coverage with 90 % intervals from the same draws: "inside" if both
intervals lie inside 60-76 / 90-98 %, "outside" if either lies entirely outside its band, else
"undecided"; and the noise floor at N tables, for a twin of each cell's best peer (equal to it in
median, as dispersed per table as the default): (i) cells whose twin median is more than 1 %
above the lowest peer median on N tables drawn with replacement, (ii) cells the verdict calls
"behind" for the twin.
--method NAME judges another method of the runs the same way (default "current", whirl's default;
e.g. cv_peers, or a peer, which is then judged against the best of the OTHER peers); --against
NAME judges it against that one method instead of the best peer (docs/workpiece-choice-limits.md).
Coverage uses the tables on which the judged method has one (a peer without an sd: NaN or none);
a cell without any says "n/a". Where the method's records name its choice per output
("cv_chosen", bench_peers.py's cv_peers) the choices are counted per cell."""
import argparse, json, math, os, random, statistics, sys
import numpy as np
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_peers import in_bands, load_runs  # noqa: E402

PEERS = ["loglinear", "gp_ard", "mlp_default", "mlp_cv", "brnn_whirl"]
METHODS = ["current"] + PEERS
TOL = 1.01                             # "more than 1 % behind"
BANDS = ((60.0, 76.0), (90.0, 98.0))   # +-1 / +-2 sd coverage, %


def seventeenth(files):
    """The seventeenth attempt's study: draws of 10 tables per (family, output) cell."""
    rows = []
    for f in files:
        rows += json.load(open(f))
    cells = {}
    for r in rows:
        for k in range(2):
            cells.setdefault((r["problem"], k), []).append(
                {m: r["methods"][m]["rmse"][k] for m in METHODS})
    rng = random.Random(17)
    DRAWS = 4000
    def behind(tables, m):
        med = {x: statistics.median(t[x] for t in tables) for x in METHODS}
        others = min(med[x] for x in PEERS if x != m)
        return med[m] > 1.01 * others
    print("cell | best peer (40) | P(behind) at 10 tables, without / with replacement: current, " + ", ".join(PEERS))
    tot = {m: [0.0, 0.0] for m in METHODS}; best_tot = [0.0, 0.0]; twin = [0.0, 0.0]
    for key in sorted(cells):
        t = cells[key]
        med40 = {x: statistics.median(e[x] for e in t) for x in METHODS}
        best = min(PEERS, key=lambda x: med40[x])
        out = []
        for mode in (0, 1):
            cnt = {m: 0 for m in METHODS}; tw = 0
            for _ in range(DRAWS):
                d = rng.sample(t, 10) if mode == 0 else [rng.choice(t) for _ in range(10)]
                for m in METHODS: cnt[m] += behind(d, m)
                # a twin of the best peer: its value on another, independent draw of 10 tables
                d2 = [rng.choice(t) for _ in range(10)]
                medb = statistics.median(e[best] for e in d2)
                oth = min(statistics.median(e[x] for e in d) for x in PEERS)
                tw += medb > 1.01 * oth
            for m in METHODS: tot[m][mode] += cnt[m] / DRAWS
            best_tot[mode] += cnt[best] / DRAWS; twin[mode] += tw / DRAWS
            out.append(cnt)
        print(f"{key[0]} out{key[1]+1} | {best} {med40[best]:.4g} (current {100*(med40['current']/med40[best]-1):+.1f} %) | " +
              ", ".join(f"{m} {out[0][m]/DRAWS:.2f}/{out[1][m]/DRAWS:.2f}" for m in METHODS))
    n = len(cells)
    print(f"\nexpected cells behind of {n} (without / with replacement):")
    for m in METHODS: print(f"  {m}: {tot[m][0]:.1f} / {tot[m][1]:.1f}")
    print(f"  the best peer of each cell (40 tables): {best_tot[0]:.1f} / {best_tot[1]:.1f}")
    print(f"  an independent twin of the best peer (its median on other tables): {twin[0]:.1f} / {twin[1]:.1f}")

    # A paired twin of the best peer: on each table the best peer's RMSE times exp(l - median l), l a
    # log ratio ln(current / best peer) drawn from the cell's 40 tables (the default's spread around
    # the best peer, centred: equal to the best peer in median, as dispersed per table as the default).
    print("\npaired twin (best peer x the default's centred per-table log ratio), P(behind) per cell:")
    totp = 0.0; per = []
    for key in sorted(cells):
        t = cells[key]
        med40 = {x: statistics.median(e[x] for e in t) for x in METHODS}
        best = min(PEERS, key=lambda x: med40[x])
        l = [math.log(e["current"] / e[best]) for e in t]; ml = statistics.median(l)
        cnt = 0
        for _ in range(DRAWS):
            d = rng.sample(t, 10)
            tw = statistics.median(e[best] * math.exp(rng.choice(l) - ml) for e in d)
            oth = min(statistics.median(e[x] for e in d) for x in PEERS)
            cnt += tw > 1.01 * oth
        totp += cnt / DRAWS; per.append(f"{key[0]} out{key[1]+1} {cnt/DRAWS:.2f}")
    print("; ".join(per))
    print(f"  expected cells behind of {len(cells)}: {totp:.1f}")

    # Spread of the count of cells behind (cells drawn independently, 10 tables each, without replacement).
    print("\ncount of the 16 cells > 1 % behind per draw (10 tables per cell): 5th / 50th / 95th percentile")
    counts = {"current": [], "best": [], "twin": []}
    cellinfo = []
    for key in sorted(cells):
        t = cells[key]
        med40 = {x: statistics.median(e[x] for e in t) for x in METHODS}
        best = min(PEERS, key=lambda x: med40[x])
        l = [math.log(e["current"] / e[best]) for e in t]
        cellinfo.append((t, best, l, statistics.median(l)))
    for _ in range(2000):
        c = {"current": 0, "best": 0, "twin": 0}
        for t, best, l, ml in cellinfo:
            d = rng.sample(t, 10)
            c["current"] += behind(d, "current"); c["best"] += behind(d, best)
            tw = statistics.median(e[best] * math.exp(rng.choice(l) - ml) for e in d)
            c["twin"] += tw > 1.01 * min(statistics.median(e[x] for e in d) for x in PEERS)
        for m in c: counts[m].append(c[m])
    for m, v in counts.items():
        v.sort(); print(f"  {m}: {v[100]} / {v[1000]} / {v[1900]} (mean {sum(v)/len(v):.1f})")


def cells_of(files, method="current", peers=PEERS):
    """{(problem, rows, output k): arrays} of the merged records: cur (N,) the judged method's RMSE,
    peers (N, len(peers)), cover (N, 2) in % (+-1, +-2 sd; NaN where the method has none), seeds
    (N,), chosen (N,) the method's "cv_chosen" if it has one. A table on which a method has no
    finite RMSE (a failed fit, a table whirl refuses) is left out of both its cells and named on
    stderr."""
    cells = {}
    methods = [method] + list(peers)
    for r in load_runs(files):
        m = r["methods"]
        missing = [x for x in methods if "rmse" not in m.get(x, {})]
        if missing:
            sys.exit(f"median_rule_noise: {r['problem']}, {r['rows']} rows, seed {r['seed']}: "
                     f"no {', '.join(missing)} in {' '.join(files)}")
        bad = [x for x in methods if not all(math.isfinite(v) and v > 0 for v in m[x]["rmse"])]
        if bad:
            print(f"median_rule_noise: left out {r['problem']}, {r['rows']} rows, seed {r['seed']}: "
                  f"no finite RMSE of {', '.join(bad)}", file=sys.stderr)
            continue
        for k in (0, 1):
            c = cells.setdefault((r["problem"], r["rows"], k), {"cur": [], "peers": [], "cover": [],
                                                               "seeds": [], "chosen": []})
            c["cur"].append(m[method]["rmse"][k])
            c["peers"].append([m[p]["rmse"][k] for p in peers])
            c["cover"].append([100 * m[method].get(b, [math.nan] * 2)[k] for b in ("cover1", "cover2")])
            c["seeds"].append(r["seed"])
            c["chosen"].append(m[method].get("cv_chosen", [""] * 2)[k])
    return {key: {f: np.asarray(v, dtype=object if f == "chosen" else float) for f, v in c.items()}
            for key, c in cells.items()}


def median_verdict(lo, hi):
    """The ratio's verdict from its 90 % interval [lo, hi]."""
    return "behind" if lo > TOL else "within" if hi <= TOL else "undecided"


def band_verdict(lo, hi, band):
    """A coverage interval [lo, hi] (%) against a band."""
    if band[0] <= lo and hi <= band[1]:
        return "inside"
    return "outside" if hi < band[0] or lo > band[1] else "undecided"


def coverage_verdict(v1, v2):
    """Both bands: outside if either is, inside if both are, else undecided."""
    return "outside" if "outside" in (v1, v2) else "inside" if v1 == v2 == "inside" else "undecided"


def ratio_draws(cur, peers, idx):
    """R = median(cur) / lowest peer median per bootstrap draw (rows of idx)."""
    return np.median(cur[idx], axis=1) / np.median(peers[idx], axis=1).min(axis=1)


def interval(x):
    lo, hi = np.percentile(x, [5, 95])
    return float(lo), float(hi)


def twin_floor(c, rng, draws, twins):
    """The cell's twin of its best peer: (i) P(twin median > 1.01 x lowest peer median) on N tables
    drawn with replacement, (ii) per twin (twins of them) whether the verdict calls it behind."""
    cur, peers = c["cur"], c["peers"]
    n = len(cur)
    best = int(np.argmin(np.median(peers, axis=0)))
    l = np.log(cur / peers[:, best])
    spread = np.exp(l - np.median(l))
    idx = rng.integers(0, n, size=(draws, n))
    twin = peers[idx, best] * spread[rng.integers(0, n, size=(draws, n))]
    point = float(np.mean(np.median(twin, axis=1) > TOL * np.median(peers[idx], axis=1).min(axis=1)))
    low_peer = np.median(peers[idx], axis=1).min(axis=1)
    behind = np.empty(twins, dtype=bool)
    for t in range(twins):
        tw = peers[:, best] * spread[rng.integers(0, n, size=n)]
        behind[t] = interval(np.median(tw[idx], axis=1) / low_peer)[0] > TOL
    return point, behind


def coverage_cell(cover, idx, rng):
    """The judged method's mean +-1 / +-2 sd coverage of a cell over the tables that have one,
    their 90 % intervals (the bootstrap draws idx, or draws among those tables when some have
    none) and the verdict; (None, None, "n/a", 0) without any."""
    ok = np.isfinite(cover).all(axis=1)
    if not ok.any():
        return None, None, "n/a", 0
    if not ok.all():
        idx = np.flatnonzero(ok)[rng.integers(0, ok.sum(), size=(idx.shape[0], ok.sum()))]
    ci = [interval(cover[idx, b].mean(axis=1)) for b in (0, 1)]
    cv = coverage_verdict(*(band_verdict(*ci[b], BANDS[b]) for b in (0, 1)))
    return cover[ok].mean(axis=0), ci, cv, int(ok.sum())


def choices(cells):
    """A Markdown table of how often the judged method chose each name per cell (cv_chosen)."""
    names = sorted({x for c in cells.values() for x in c["chosen"] if x})
    if not names:
        return
    print("\n| problem | rows | out | " + " | ".join(names) + " |")
    print("|---|---|---|" + "---|" * len(names))
    for key in sorted(cells, key=lambda k: (k[1], k[0], k[2])):
        ch = list(cells[key]["chosen"])
        print(f"| {key[0]} | {key[1]} | out{key[2] + 1} | " +
              " | ".join(str(ch.count(x)) for x in names) + " |")


def verdicts(files, draws, twins, twin_draws=1000, seed=40, method="current", against=None):
    """Per-cell verdicts (median ratio, coverage) and the twin noise floor of `method` against
    the best of the peers (without itself) or against the one method `against`; prints Markdown."""
    peers = [against] if against else [p for p in PEERS if p != method]
    cells = cells_of(files, method, peers)
    rng = np.random.default_rng(seed)
    if method != "current" or against:
        print(f"{method} judged against {'the best of ' if len(peers) > 1 else ''}"
              f"{', '.join(peers)}\n")
    print("| problem | rows | out | N | best peer (median) | ratio | 90 % interval | verdict | "
          "+-1 sd % (90 %) | +-2 sd % (90 %) | coverage |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    count = {}
    point_behind, point_out, first10 = [], [], [0, 0]
    floor_point, floor_behind = [], []
    for key in sorted(cells, key=lambda k: (k[1], k[0], k[2])):
        c = cells[key]
        n = len(c["cur"])
        idx = rng.integers(0, n, size=(draws, n))
        med = np.median(c["peers"], axis=0)
        best = int(np.argmin(med))
        ratio = float(np.median(c["cur"]) / med[best])
        lo, hi = interval(ratio_draws(c["cur"], c["peers"], idx))
        mv = median_verdict(lo, hi)
        cov, ci, cv, n_cov = coverage_cell(c["cover"], idx, rng)
        for what, v in (("median", mv), ("coverage", cv.split(" (")[0])):
            count.setdefault((what, key[1], v), []).append(f"{key[0]} out{key[2] + 1}")
        if ratio > TOL:
            point_behind.append(f"{key[0]} {key[1]} out{key[2] + 1} {100 * (ratio - 1):+.1f} %")
        if cov is not None and not in_bands(*cov):
            point_out.append(f"{key[0]} {key[1]} out{key[2] + 1} {cov[0]:.1f}/{cov[1]:.1f}")
        ten = c["seeds"] < c["seeds"].min() + 10
        first10[0] += np.median(c["cur"][ten]) > TOL * np.median(c["peers"][ten], axis=0).min()
        ten_cov = c["cover"][ten & np.isfinite(c["cover"]).all(axis=1)]
        first10[1] += len(ten_cov) > 0 and not in_bands(*ten_cov.mean(axis=0))
        p, b = twin_floor(c, rng, min(draws, twin_draws), twins)
        floor_point.append(p); floor_behind.append(b)
        cover = " | ".join(f"{cov[b]:.1f} ({ci[b][0]:.1f}-{ci[b][1]:.1f})" for b in (0, 1)) \
            if cov is not None else "- | -"
        cv += f" ({n_cov} of {n} with an sd)" if 0 < n_cov < n else ""
        print(f"| {key[0]} | {key[1]} | out{key[2] + 1} | {n} | {peers[best]} {med[best]:.4g} | "
              f"{ratio:.3f} | {lo:.3f}-{hi:.3f} | {mv} | {cover} | {cv} |")
    nc = len(cells)
    print(f"\n{nc} cells; bootstrap {draws} draws, 90 % percentile intervals; twins {twins} per cell, "
          f"{min(draws, twin_draws)} draws each")
    no_sd = ("n/a",) if any(k[0] == "coverage" and k[2] == "n/a" for k in count) else ()
    for what, vs in (("median", ("behind", "within", "undecided")),
                     ("coverage", ("inside", "outside", "undecided") + no_sd)):
        for rows in sorted({k[1] for k in cells}):
            print(f"{what} {rows} rows: " + "; ".join(
                f"{v} {len(count.get((what, rows, v), []))}" +
                (f" ({', '.join(count[(what, rows, v)])})" if v != vs[1 if what == 'median' else 0]
                 and count.get((what, rows, v)) else "") for v in vs))
        print(f"{what} total: " + ", ".join(
            f"{v} {sum(len(count.get((what, r, v), [])) for r in {k[1] for k in cells})}" for v in vs))
    print(f"point rule on all N tables: {len(point_behind)} of {nc} medians more than 1 % behind: "
          + "; ".join(point_behind))
    print(f"point rule: coverage outside 60-76 / 90-98 % on {len(point_out)} of {nc} cells: "
          + "; ".join(point_out))
    print(f"point rule on the first 10 seeds: {first10[0]} medians behind, {first10[1]} coverage "
          "cells outside")
    names = [f"{k[0]} {k[1]} out{k[2] + 1}" for k in sorted(cells, key=lambda k: (k[1], k[0], k[2]))]
    print("twin judged 'behind', share of twins per cell (cells above 0): " + "; ".join(
        f"{nm} {float(np.mean(b)):.2f}" for nm, b in zip(names, floor_behind) if np.any(b)))
    counts = np.sum(np.asarray(floor_behind), axis=0)
    print(f"noise floor (twin of the best peer) at N tables: (i) point rule {sum(floor_point):.1f} "
          f"of {nc} cells expected behind; (ii) verdict 'behind' {float(np.mean(counts)):.2f} "
          f"expected (count per set of twins 5th / 50th / 95th percentile "
          f"{np.percentile(counts, 5):.0f} / {np.percentile(counts, 50):.0f} / "
          f"{np.percentile(counts, 95):.0f})")
    choices(cells)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("runs", nargs="+", metavar="RUN.json")
    ap.add_argument("--verdicts", action="store_true",
                    help="per-cell verdicts with bootstrap intervals and the twin noise floor")
    ap.add_argument("--draws", type=int, default=2000, help="bootstrap draws per cell (--verdicts)")
    ap.add_argument("--twins", type=int, default=200, help="twins per cell for the floor (ii)")
    ap.add_argument("--method", default="current",
                    help="the method judged (--verdicts; default current, whirl's default); a peer "
                         "is judged against the best of the other peers")
    ap.add_argument("--against", metavar="NAME",
                    help="judge --method against this one method instead of the best peer")
    a = ap.parse_args()
    if (a.method != "current" or a.against) and not a.verdicts:
        sys.exit("median_rule_noise: --method and --against need --verdicts")
    if a.against == a.method:
        sys.exit(f"median_rule_noise: --against {a.against} is the judged method itself")
    for f in a.runs:
        if not os.path.exists(f):
            sys.exit(f"median_rule_noise: {f}: no such file")
    if a.draws < 20 or a.twins < 1:
        sys.exit("median_rule_noise: --draws needs at least 20 and --twins at least 1")
    if a.verdicts:
        verdicts(a.runs, a.draws, a.twins, method=a.method, against=a.against)
    else:
        seventeenth(a.runs)


if __name__ == "__main__":
    main()
