#!/usr/bin/python3
"""How noisy is "median test RMSE within 1 % of the best peer's median" at 10 tables per cell?

usage: median_rule_noise.py RUN.json [RUN.json ...]  (bench_peers.py --json files holding the
default as "current" and the peers loglinear, gp_ard, mlp_default, mlp_cv, brnn_whirl on the same
tables). Per (family, output) cell it draws 10 of the cell's tables many times and counts how
often each method's median is more than 1 % above the lowest median of the other peers, and the
same for a twin of the cell's best peer (its RMSE times the default's centred per-table log
ratio: equal to the best peer in median). docs/workpiece-model.md, "Seventeenth attempt: how
noisy is the 1 % rule at 10 tables"."""
import json, math, random, statistics, sys
PEERS = ["loglinear", "gp_ard", "mlp_default", "mlp_cv", "brnn_whirl"]
METHODS = ["current"] + PEERS
rows = []
for f in sys.argv[1:]:
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
