#!/usr/bin/python3
"""Which screws to measure: test RMSE of the default `whirl train` model against the number of
measured screws N for four ways of choosing them (docs/design.md, src/product/design/design.h).

Per problem and seed: a candidate list ("pool", the screw types coming up) of POOL_ROWS screws with
their noisy measured targets, and a test set with the noise-free truth. Every strategy picks its N
screws from the pool (it can only measure what production makes), the default model is trained on
them (`whirl train`, seed 1) and its test RMSE per output is measured against the truth:
  random   the first N of a random order of the pool;
  lhs      a Latin hypercube of N points over the pool's input box (McKay, Beckman & Conover 1979),
           each matched to the nearest unused pool screw (inputs scaled to the box);
  natural  the shop's natural order: production in campaigns of CAMPAIGN screws of one product
           family (the pool split by the nearest of FAMILIES random centres), families in random
           order;
  design   `whirl design`: a first design of FIRST screws (--criterion), then batches of --batch
           next screws from the model trained on the screws so far (`whirl design --model`).
Problems: "simgen" (pool: `whirl dataset --count POOL_ROWS --seed 200000 + seed`, the simulator;
test: datasets/whirling_500.csv, whose targets carry the simulator's scatter) and the generator
families of scripts/bench_peers.py (pool: the family's training rows at POOL_ROWS; test: its 1000
noise-free rows). `whirl train` refuses fewer than 8 rows, so N starts at 8 (N = 6 is reported as
untrainable for every strategy).

Usage: python3 scripts/design_study.py --whirl build/whirl --problems simgen,powerlaw \\
         --seeds 1-10 --criterion d --batch 4 --json out.json [--plot out.png]
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_peers as bp  # noqa: E402

POOL_ROWS = 200
SIZES = [8, 12, 16, 20, 30]
FIRST = 8
CAMPAIGN = 5
FAMILIES = 6
STRATEGIES = ["random", "lhs", "natural", "design"]
PICKS = {}  # "problem/seed" -> the design's pool rows in the order picked (--json: design_picks)


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        kept = ""
        if "--data" in cmd:  # keep the table that failed to train for a bug report
            kept = os.path.join(tempfile.gettempdir(), "design_study_failed_" + os.path.basename(
                os.path.dirname(cmd[cmd.index("--data") + 1])) + ".csv")
            shutil.copy(cmd[cmd.index("--data") + 1], kept)
            kept = f" (table kept: {kept})"
        sys.exit(f"design_study: {' '.join(cmd)} failed{kept}: {r.stderr}")
    return r.stdout


def problem(prob, seed, whirl, datasets, cache):
    """(pool x, pool y, test x, test truth)."""
    if prob == "simgen":
        path = os.path.join(cache, f"pool_{seed}.csv")
        if not os.path.exists(path):
            run([whirl, "dataset", "--count", str(POOL_ROWS), "--seed", str(200000 + seed),
                 "--out", path, "--threads", "1"])
        x, y = bp.read_table(path)
        xte, yte = bp.read_table(os.path.join(datasets, "whirling_500.csv"))
        return x, y, xte, yte
    x, y, xte, fte, _ = bp.generated(prob, POOL_ROWS, seed)
    return x, y, xte, fte


def unit(x, lo, hi):
    return (x - lo) / np.where(hi > lo, hi - lo, 1.0)


def lhs_pick(x, n, rng):
    lo, hi = x.min(axis=0), x.max(axis=0)
    u = unit(x, lo, hi)
    pts = (np.array([rng.permutation(n) for _ in range(x.shape[1])]).T + rng.uniform(size=(n, 5))) / n
    used, out = set(), []
    for p in pts:
        d = ((u - p) ** 2).sum(axis=1)
        for i in np.argsort(d):
            if i not in used:
                used.add(i)
                out.append(int(i))
                break
    return out


def natural_order(x, rng):
    lo, hi = x.min(axis=0), x.max(axis=0)
    u = unit(x, lo, hi)
    centres = rng.uniform(size=(FAMILIES, 5))
    fam = np.argmin(((u[:, None, :] - centres[None]) ** 2).sum(axis=2), axis=1)
    queues = {f: list(rng.permutation(np.flatnonzero(fam == f))) for f in range(FAMILIES)}
    order = []
    while len(order) < len(x):
        live = [f for f in queues if queues[f]]
        f = live[rng.integers(len(live))]
        order += [int(i) for i in queues[f][:CAMPAIGN]]
        queues[f] = queues[f][CAMPAIGN:]
    return order


class Evaluator:
    def __init__(self, whirl, tmp, x, y, xte, truth):
        self.whirl, self.tmp, self.x, self.y, self.truth = whirl, tmp, x, y, truth
        self.test = os.path.join(tmp, "test.csv")
        bp.write_table(self.test, xte)

    def train(self, rows, name):
        data, model = (os.path.join(self.tmp, f"{name}.{e}") for e in ("csv", "json"))
        bp.write_table(data, self.x[rows], self.y[rows])
        run([self.whirl, "train", "--data", data, "--out", model, "--seed", "1", "--threads", "1"])
        return model

    def rmse(self, model):
        p = json.loads(run([self.whirl, "predict", "--model", model, "--input", self.test, "--json"]))
        mean = np.array([[r["max_elongation_um"], r["settle_time_s"]] for r in p["predictions"]])
        return bp.rmse(mean, self.truth).tolist()


def designed(ev, criterion, batch, first_lhs=None, fill_first=0, fill_next=0, variance=None,
             inside=(), picks=None):
    """RMSE per size of the sequential design: FIRST by the first design (or the Latin hypercube
    picks `first_lhs`), then batches; fill_first / fill_next: `whirl design --space-filling`;
    variance: extra `whirl design` arguments of the next screws (--variance ..., None: defaults;
    the hyperparameters go to the first design too); inside: the first design's own options
    (`--inside K`, `--potential-terms`, `--tau`);
    picks: a list that receives the pool rows picked, in order."""
    pool = os.path.join(ev.tmp, "pool.csv")
    bp.write_table(pool, ev.x)
    if first_lhs is not None:
        picked = list(first_lhs)
    else:
        hyper = [a for f, v in zip(variance[::2], variance[1::2])
                 if f not in ("--variance", "--switch-ratio", "--space-filling-when",
                              "--departure-evidence")
                 for a in (f, v)] if variance else []
        out = json.loads(run([ev.whirl, "design", "--candidates", pool, "--count", str(FIRST),
                              "--criterion", criterion, "--space-filling", str(fill_first),
                              "--json"] + hyper + inside))
        picked = [int(p["source"].split()[1]) - 2 for p in out["picks"]]  # line -> row
    result = {}
    while True:
        model = ev.train(picked, "design")
        if len(picked) in SIZES:
            result[len(picked)] = ev.rmse(model)
        if len(picked) >= max(SIZES):
            if picks is not None:
                picks += picked
            return result
        nxt = min(s for s in SIZES if s > len(picked))
        k = min(batch, nxt - len(picked))
        left = [i for i in range(len(ev.x)) if i not in set(picked)]
        cand = os.path.join(ev.tmp, "left.csv")
        bp.write_table(cand, ev.x[left])
        measured = os.path.join(ev.tmp, "measured.csv")
        bp.write_table(measured, ev.x[picked], ev.y[picked])  # targets: --variance switch
        fill = min(fill_next, k)
        out = json.loads(run([ev.whirl, "design", "--model", model, "--candidates", cand,
                              "--count", str(k), "--space-filling", str(fill), "--measured",
                              measured, "--json"] + (variance or [])))
        picked += [left[int(p["source"].split()[1]) - 2] for p in out["picks"]]


def one_case(prob, seed, a, cache):
    with tempfile.TemporaryDirectory() as tmp:
        x, y, xte, truth = problem(prob, seed, a.whirl, a.datasets, cache)
        ev = Evaluator(a.whirl, tmp, x, y, xte, truth)
        rng = np.random.default_rng([42, seed, len(prob)])
        res = {}
        if not a.design_only:
            order = [int(i) for i in rng.permutation(len(x))]
            nat = natural_order(x, rng)
            res["random"] = {n: ev.rmse(ev.train(order[:n], "r")) for n in SIZES}
            res["lhs"] = {n: ev.rmse(ev.train(lhs_pick(x, n, rng), "l")) for n in SIZES}
            res["natural"] = {n: ev.rmse(ev.train(nat[:n], "n")) for n in SIZES}
        first = lhs_pick(x, FIRST, np.random.default_rng([7, seed])) if a.first == "lhs" else None
        res["design"] = designed(ev, a.criterion, a.batch, first, a.fill_first, a.fill_next,
                                 variance_args(a),
                                 first_design_args(a),
                                 PICKS.setdefault(f"{prob}/{seed}", []))
        return prob, seed, res


def first_design_args(a):
    """The first design's own `whirl design` options given to the study (none: the defaults)."""
    out = []
    for flag, v in (("--inside", a.inside), ("--potential-terms", a.potential_terms),
                    ("--tau", a.tau)):
        if v is not None:
            out += [flag, str(v)]
    return out


def variance_args(a):
    """The next screws' `whirl design` options given to the study (none: the defaults)."""
    out = []
    for flag, v in (("--variance", a.variance), ("--departure-ratio", a.departure_ratio),
                    ("--length-scale", a.length_scale), ("--switch-ratio", a.switch_ratio),
                    ("--space-filling-rule", a.fill_rule),
                    ("--space-filling-when", a.fill_when),
                    ("--departure-evidence", a.departure_evidence)):
        if v is not None:
            out += [flag, str(v)]
    return out


# A replaced generator seed s (negative target in its candidate list) becomes the first of
# s + k * REPLACEMENT_STRIDE (k = 1, 2, ...) whose list has none: seeds of --seeds stay below the
# stride, so ranges that do not overlap get disjoint seeds, replacements included (the rule
# scripts/bench_peers.py applies to its tables).
REPLACEMENT_STRIDE = bp.REPLACEMENT_STRIDE
SEED_RULES = ["stride", "next-after-range"]
SEED_RULE_HELP = ("how a seed whose candidate list holds a negative target is replaced: 'stride' "
                  "(s + k x 1,000,000) or 'next-after-range' (the rule of the figures published "
                  "in docs/design.md before 2026-11-30; reproduces them)")


def seeds_of(text):
    """The seeds of --seeds "LO-HI" or "S" (1 <= LO <= HI < REPLACEMENT_STRIDE)."""
    lo, _, hi = text.partition("-")
    try:
        seeds = list(range(int(lo), int(hi or lo) + 1))
    except ValueError:
        sys.exit(f"design_study: --seeds '{text}': expected LO-HI or one seed (integers)")
    if not seeds or seeds[0] < 1 or seeds[-1] >= REPLACEMENT_STRIDE:
        sys.exit(f"design_study: --seeds '{text}': expected 1 <= LO <= HI < {REPLACEMENT_STRIDE}")
    return seeds


def usable_seeds(prob, seeds, rule="stride"):
    """`seeds`, where a generator seed s whose candidate list holds a negative target (which
    `whirl train` refuses) is replaced. rule "stride" (the default since 2026-11-30): by the first
    s + k REPLACEMENT_STRIDE, k = 1, 2, ..., that does not, so that ranges that do not overlap
    share no seed. rule "next-after-range": by the next seed after the range that does not (the
    rule every figure of docs/design.md was made with; the next range of seeds also uses it), kept
    so that those figures' commands reproduce them."""
    if prob == "simgen":
        return seeds
    ok = lambda s: (bp.generated(prob, POOL_ROWS, s)[1] >= 0).all()  # noqa: E731
    if rule == "next-after-range":
        out, nxt = [s for s in seeds if ok(s)], max(seeds) + 1
        while len(out) < len(seeds):
            if ok(nxt):
                out.append(nxt)
            nxt += 1
        return out
    out = []
    for s in seeds:
        r = bp.replacement_seed(ok, s)
        if r != s:
            print(f"design_study: {prob} seed {s} replaced by {r} (a negative target in its "
                  "candidate list)", file=sys.stderr)
        out.append(r)
    return out


def summarize(results, problems):
    """Median over seeds of RMSE per output, per problem, strategy and size."""
    table = {}
    for prob in problems:
        cases = [r for p, _, r in results if p == prob]
        table[prob] = {}
        for s in STRATEGIES:
            if not all(s in r for r in cases):
                continue
            table[prob][s] = {n: np.median([r[s][n] for r in cases], axis=0).tolist()
                              for n in SIZES}
    return table


def print_markdown(table):
    for prob, rows in table.items():
        for k, out in enumerate(bp.TARGETS):
            print(f"\n{prob}, {out}: median test RMSE over seeds (N = {', '.join(map(str, SIZES))})\n")
            print("| strategy | " + " | ".join(f"N={n}" for n in SIZES) + " |")
            print("|---|" + "---|" * len(SIZES))
            for s, r in rows.items():
                print(f"| {s} | " + " | ".join(f"{r[n][k]:.4g}" for n in SIZES) + " |")
            if "random" in rows and "design" in rows:
                r20 = rows["random"][20][k]
                reach = [n for n in SIZES if rows["design"][n][k] <= r20]
                worse = [n for n in SIZES if rows["design"][n][k] > rows["random"][n][k]]
                print(f"\ndesign reaches random@20 ({r20:.4g}) at N = {reach[0] if reach else 'never'}"
                      f"; worse than random at N = {worse or 'none'}")


def score(table):
    """The second attempt's rule (docs/design.md): cells where the design's median is above
    random's, outputs where it reaches random's 20-screw median with <= 12 screws, and the
    geometric mean of design / random over all cells."""
    worse, reach12, ratios = [], 0, []
    for prob, rows in table.items():
        if "random" not in rows or "design" not in rows:
            continue
        for k, out in enumerate(bp.TARGETS):
            d, r = rows["design"], rows["random"]
            worse += [f"{prob}/{out}/N={n}" for n in SIZES if d[n][k] > r[n][k]]
            reach12 += any(d[n][k] <= r[20][k] for n in SIZES if n <= 12)
            ratios += [d[n][k] / r[n][k] for n in SIZES]
    if ratios:
        print(f"\nscore: {len(worse)} cells worse than random ({', '.join(worse) or 'none'}); "
              f"random@20 reached with <= 12 screws on {reach12} outputs; geometric mean "
              f"design / random {np.exp(np.mean(np.log(ratios))):.4f}")


def cases_of(results):
    """{(problem, seed): {strategy: {N: [rmse per output]}}} with integer N (also from --json)."""
    return {(p, s): {k: {int(n): v for n, v in r.items()} for k, r in res.items()}
            for p, s, res in results}


def paired_t(d):
    """(mean, standard error, t = mean / se) of paired differences d."""
    d = np.asarray(d, dtype=float)
    se = d.std(ddof=1) / np.sqrt(len(d)) if len(d) > 1 else float("nan")
    return d.mean(), se, d.mean() / se if se > 0 else float("nan")


def log_ratios(cases, a, b, outputs=(0, 1), sizes=SIZES):
    """Per case (problem, seed): the mean over `outputs` and `sizes` of ln(RMSE_a / RMSE_b); a
    and b: (cases, strategy)."""
    (ca, sa), (cb, sb) = a, b
    out = {}
    for key in ca:
        if key in cb and sa in ca[key] and sb in cb[key]:
            out[key] = np.mean([np.log(ca[key][sa][n][k] / cb[key][sb][n][k])
                                for n in sizes for k in outputs])
    return out


def print_paired_cells(cases):
    """Design against random per problem, output and N: the paired ratio exp(mean log-ratio)
    over the seeds and its t (the acceptance's "never worse than random at any N")."""
    if not all("random" in c and "design" in c for c in cases.values()):
        return
    print("\npaired, design / random per cell: ratio (t) at N = " + ", ".join(map(str, SIZES)))
    for prob in dict.fromkeys(p for p, _ in cases):
        one = {key: c for key, c in cases.items() if key[0] == prob}
        for k, out in enumerate(bp.TARGETS):
            cells = []
            for n in SIZES:
                d = log_ratios(one, (one, "design"), (one, "random"), (k,), (n,))
                m, _, t = paired_t(list(d.values()))
                cells.append(f"{np.exp(m):.3f} ({t:+.1f})")
            print(f"  {prob}, {out}: " + ", ".join(cells))


def print_twelve_against_twenty(cases):
    """The sixth attempt's suggested paired criterion for "with at most 12 designed screws the
    accuracy of 20 random screws": per problem and output, exp of the mean over seeds of
    ln(RMSE_design(12) / RMSE_random(20)) and its t (a ratio <= 1 reaches it)."""
    if not all("random" in c and "design" in c for c in cases.values()):
        return
    print("\npaired, design at 12 / random at 20 per problem and output: ratio (t)")
    for prob in dict.fromkeys(p for p, _ in cases):
        cells = []
        for k, out in enumerate(bp.TARGETS):
            d = [np.log(c["design"][12][k] / c["random"][20][k])
                 for key, c in cases.items() if key[0] == prob]
            m, _, t = paired_t(d)
            cells.append(f"{out} {np.exp(m):.3f} ({t:+.1f})")
        print(f"  {prob}: " + ", ".join(cells))


def print_paired(d, title):
    """The fourth attempt's paired statistic (docs/design.md): mean, se and t of the per-case
    log-ratios, the sign count, and per problem (nothing without cases: --design-only)."""
    if not d:
        return
    mean, se, t = paired_t(list(d.values()))
    below = sum(v < 0 for v in d.values())
    nonzero = sum(v != 0 for v in d.values())
    print(f"\n{title}: {len(d)} cases, mean log-ratio {mean:+.4f} (ratio {np.exp(mean):.3f}), "
          f"se {se:.4f}, t {t:+.2f}; lower in {below} of {nonzero} cases with a difference")
    for prob in dict.fromkeys(p for p, _ in d):
        m, e, tp = paired_t([v for (p, _), v in d.items() if p == prob])
        print(f"  {prob}: mean {m:+.4f} (ratio {np.exp(m):.3f}), se {e:.4f}, t {tp:+.2f}")


def paired_report(results, base=None):
    """Design against random per output, and (base: an earlier --json run) this run's design
    against the base run's design on the same cases."""
    cases = cases_of(results)
    for k, out in enumerate(bp.TARGETS):
        print_paired(log_ratios(cases, (cases, "design"), (cases, "random"), (k,)),
                     f"paired, design / random, {out}")
    print_paired_cells(cases)
    print_twelve_against_twenty(cases)
    if base:
        other = cases_of(json.load(open(base))["cases"])
        print_paired(log_ratios(cases, (cases, "design"), (other, "design")),
                     f"paired, this design / the design of {base}, both outputs")


def plot(table, path, gnuplot="gnuplot"):
    with tempfile.TemporaryDirectory() as tmp:
        cmds = [f"set terminal pngcairo size 1400,{420 * len(table)} font ',10'",
                f"set output '{path}'", f"set multiplot layout {len(table)},2",
                "set logscale y", "set xlabel 'measured screws N'", "set key top right",
                "set grid", "set termoption noenhanced"]
        for prob, rows in table.items():
            for k, out in enumerate(bp.TARGETS):
                files = []
                for s, r in rows.items():
                    f = os.path.join(tmp, f"{prob}_{k}_{s}.dat")
                    with open(f, "w") as h:
                        h.writelines(f"{n} {r[n][k]}\n" for n in SIZES)
                    files.append((f, s))
                cmds.append(f"set title '{prob}: {out} (median test RMSE)'")
                cmds.append("plot " + ", ".join(f"'{f}' using 1:2 with linespoints title '{s}'"
                                                 for f, s in files))
        cmds.append("unset multiplot")
        script = os.path.join(tmp, "p.gp")
        with open(script, "w") as h:
            h.write("\n".join(cmds) + "\n")
        subprocess.run([gnuplot, script], check=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--whirl", default="build/whirl")
    ap.add_argument("--datasets", default=os.path.join(os.path.dirname(__file__), "..", "datasets"))
    ap.add_argument("--problems", default="simgen,powerlaw")
    ap.add_argument("--seeds", default="1-10")
    ap.add_argument("--seed-rule", default="stride", choices=SEED_RULES, help=SEED_RULE_HELP)
    ap.add_argument("--criterion", default="d", choices=["d", "i", "bayes-d"])
    ap.add_argument("--potential-terms", choices=["squares", "squares+interactions"],
                    help="whirl design --potential-terms of the first design (--criterion bayes-d)")
    ap.add_argument("--tau", type=float, help="whirl design --tau of the first design (bayes-d)")
    ap.add_argument("--batch", type=int, default=2)
    ap.add_argument("--first", default="design", choices=["design", "lhs"],
                    help="the design strategy's first 8 screws: whirl design, or a Latin hypercube")
    ap.add_argument("--fill-first", type=int, default=0,
                    help="whirl design --space-filling of the first design [screws]")
    ap.add_argument("--fill-next", type=int, default=0,
                    help="whirl design --space-filling of every next batch [screws]")
    ap.add_argument("--variance", help="whirl design --variance of the next screws (default: "
                    "whirl design's)")
    ap.add_argument("--departure-ratio", type=float, help="whirl design --departure-ratio")
    ap.add_argument("--length-scale", type=float, help="whirl design --length-scale")
    ap.add_argument("--switch-ratio", type=float, help="whirl design --switch-ratio")
    ap.add_argument("--fill-rule", choices=["maximin", "coverage"],
                    help="whirl design --space-filling-rule (with --fill-first / --fill-next)")
    ap.add_argument("--fill-when", choices=["always", "departure"],
                    help="whirl design --space-filling-when of every next batch")
    ap.add_argument("--departure-evidence", choices=["lack-of-fit", "choice"],
                    help="whirl design --departure-evidence of every next batch")
    ap.add_argument("--inside", type=int, help="whirl design --inside of the first design")
    ap.add_argument("--jobs", type=int, default=2, help="parallel cases (at most 2 on shared machines)")
    ap.add_argument("--design-only", action="store_true", help="only the design strategy")
    ap.add_argument("--sim-cache", default=os.path.join(tempfile.gettempdir(), "whirl_design_sim"))
    ap.add_argument("--random-from", help="an earlier --json run of the same problems and seeds: "
                    "its random, lhs and natural cases are used (with --design-only)")
    ap.add_argument("--json", help="write every case's RMSE and the medians here")
    ap.add_argument("--plot", help="PNG of the medians (gnuplot)")
    ap.add_argument("--from-json", help="print (and --plot) the medians of an earlier --json run")
    ap.add_argument("--paired-with", help="an earlier --json run of the same problems and seeds: "
                    "the paired log-ratio of this run's design against its design (docs/design.md, "
                    "fourth attempt)")
    a = ap.parse_args()
    if a.from_json:
        saved = json.load(open(a.from_json))
        table = {p: {s: {int(n): v for n, v in r.items()} for s, r in rows.items()}
                 for p, rows in saved["medians"].items()}
        print(f"criterion {saved['criterion']}, batch {saved['batch']}, seeds {saved['seeds']}")
        print_markdown(table)
        score(table)
        paired_report(saved["cases"], a.paired_with)
        if a.plot:
            plot(table, a.plot)
        return
    os.makedirs(a.sim_cache, exist_ok=True)
    problems = a.problems.split(",")
    cases = [(p, s) for p in problems for s in usable_seeds(p, seeds_of(a.seeds), a.seed_rule)]
    with ThreadPoolExecutor(max_workers=min(a.jobs, 2)) as pool:
        results = list(pool.map(lambda c: one_case(c[0], c[1], a, a.sim_cache), cases))
    if a.random_from:
        earlier = {(p, s): r for p, s, r in json.load(open(a.random_from))["cases"]}
        for p, s, r in results:
            r.update({k: {int(n): v for n, v in earlier[(p, s)][k].items()}
                      for k in STRATEGIES if k != "design"})
    table = summarize(results, problems)
    print(f"criterion {a.criterion}, batch {a.batch}, space filling {a.fill_first} (first) / "
          f"{a.fill_next} (next), first design {' '.join(first_design_args(a)) or 'defaults'}, "
          f"next screws "
          f"{' '.join(variance_args(a)) or 'defaults'}, "
          f"seeds {a.seeds}, pool {POOL_ROWS}")
    print_markdown(table)
    score(table)
    if a.json:
        with open(a.json, "w") as h:
            json.dump({"criterion": a.criterion, "batch": a.batch, "seeds": a.seeds,
                       "fill_first": a.fill_first, "fill_next": a.fill_next,
                       "next_screws": variance_args(a) or "whirl design defaults",
                       "inside": a.inside, "first_design": first_design_args(a),
                       "command": " ".join(sys.argv),
                       "cases": results, "medians": table, "design_picks": PICKS}, h)
    paired_report(results, a.paired_with)
    if a.plot:
        plot(table, a.plot)


if __name__ == "__main__":
    main()
