#!/usr/bin/python3
"""The tenth attempt's bound (docs/design.md): how well can ANY 12 screws of the candidate list do
with the default model? An ORACLE that knows the truth picks them; it is a bound, not a method (no
shop knows the test error). Per case (problem, output, seed) of `design_study.py`'s problems, with
the study's candidate list, noisy measured targets and noise-free test truth:
  forward   greedy: from the better (by the output's test RMSE) of the default design's first 8
            and the study's random first 8 (`whirl train` refuses fewer than 8 rows, so no table
            grows from one screw), screws 9-12 one at a time, each the best of --greedy random
            unused screws of the list by the test RMSE after adding it;
  backward  greedy elimination: from the study's random 20, the screw whose removal keeps the
            test RMSE lowest is dropped, one at a time, down to 12 (can 8 of random's 20 go?);
  exchange  from the best 12 of forward, backward, the default design's 12 and random's first
            12: one pass over the 12, each screw in turn replaced by the best of --exchange
            random unused screws of the list if that lowers the test RMSE (Fedorov's exchange
            with the truth as its criterion).
Every evaluation trains the default model (`whirl train --seed 1`, as the study) on the picked rows
and measures the output's RMSE against the test truth. Also per case: the default design's 12
(`whirl design`, first design 8 and two batches of 2, as the study) and the study's random 12 and
20. The oracle's criterion (--draws):
  0   the list's own measured targets, as in the study. The oracle then also picks screws whose
      scatter happens to help: on fresh scatter at the same screws its gain does not hold
      (docs/design.md, tenth attempt), so this is a bound on luck, not on placement;
  R   the geometric mean RMSE over R fresh noise draws of the list's targets at its screws
      (generator families only: the simulator cannot redraw its scatter at given screws); the
      figures of the tables are then their retraining on --held-out-draws other draws, which the
      oracle never saw (rmse_held_out), beside the selection draws (rmse) and the list's own
      targets (rmse_list).
It is greedy on a subsample, not the best 12 of the list: its error is an upper bound on the best
12's, and its placement one that no shop could find without the truth.

Placement: log inputs scaled to the list's box, u in [0, 1]; per input the share of the picked
screws' coordinates in the outer 10 % at either end ("edge") and in the middle half
(|2u - 1| < 0.5), and the screws with no coordinate at an edge ("inside").

Usage: /usr/bin/python3 scripts/design_oracle.py --whirl build/whirl --seeds 9901-9906 \\
         --cases bent:0,additive:0,additive:1,interacting:1,powerlaw:1 --greedy 4 --exchange 0 \\
         --draws 4 --held-out-draws 4 --json placement.json
       /usr/bin/python3 scripts/design_oracle.py --from-json placement.json
       /usr/bin/python3 scripts/design_oracle.py --from-json oracle.json --fresh-noise 4
"""
import argparse
import json
import os
import sys
import tempfile
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_peers as bp  # noqa: E402
import design_study as ds  # noqa: E402
from design_diagnosis import scaled, truth_pool  # noqa: E402

MULTIPLICATIVE = ("powerlaw", "bent", "powerlaw_noisy")  # f exp(sd N(0, 1)); the others f + sd N


class Scorer:
    """The output's test RMSE of the default model trained on a set of the list's rows, the
    geometric mean over the evaluators (one per noise draw of the list's targets; cached)."""

    def __init__(self, evs, k):
        self.evs, self.k, self.cache, self.count = evs, k, {}, 0

    def __call__(self, rows):
        key = tuple(sorted(rows))
        if key not in self.cache:
            self.cache[key] = float(np.exp(np.mean(
                [np.log(ev.rmse(ev.train(list(rows), "o"))[self.k]) for ev in self.evs])))
            self.count += len(self.evs)
        return self.cache[key]


def noisy(prob, seed, draw):
    """A fresh noise draw of the list's targets at its screws (generator families)."""
    f = truth_pool(prob, seed)
    sd = bp.GENERATORS[prob][1](np.random.default_rng([bp.GENERATORS[prob][0], seed]))["noise"]
    e = np.random.default_rng([77, seed, draw]).normal(size=f.shape) * sd
    return f * np.exp(e) if prob in MULTIPLICATIVE else f + e


def some_free(rng, picked, n_pool, tries):
    """`tries` random rows of the list (0 .. n_pool - 1) not in `picked`."""
    free = [i for i in range(n_pool) if i not in picked]
    return rng.choice(free, min(tries, len(free)), replace=False)


def best_of(score, base, tries):
    """(rmse, row) of the best row of `tries` added to `base`."""
    return min((score(base + [i]), i) for i in tries)


def exchange(score, picked, n_pool, tries, rng):
    """One pass: each screw in turn replaced by the best of `tries` random free rows if better."""
    picked, now = list(picked), score(picked)
    for pos in range(len(picked)):
        rest = picked[:pos] + picked[pos + 1:]
        r, i = best_of(score, rest, some_free(rng, picked, n_pool, tries))
        if r < now:
            picked, now = rest[:pos] + [int(i)] + rest[pos:], r
    return picked


def forward(score, start, n_pool, tries, rng):
    """Greedy: from `start`, add the best of `tries` random free rows until 12."""
    picked = list(start)
    while len(picked) < 12:
        picked.append(int(best_of(score, picked, some_free(rng, picked, n_pool, tries))[1]))
    return picked


def backward(score, rows):
    """Greedy elimination: drop the row whose removal keeps the score lowest until 12."""
    rows = list(rows)
    while len(rows) > 12:
        rows = min((score(rows[:i] + rows[i + 1:]), rows[:i] + rows[i + 1:])
                   for i in range(len(rows)))[1]
    return rows


def oracle(score, tables, n_pool, a, rng):
    """The oracle's 12 rows and the RMSE of each stage (tables: the study's own)."""
    start = min((score(t[:8]), t[:8]) for t in (tables["design12"], tables["random12"]))[1]
    stages = {"forward": forward(score, start, n_pool, a.greedy, rng),
              "backward": backward(score, tables["random20"])}
    best = min((score(t), t) for t in [*stages.values(), tables["design12"],
                                       tables["random12"]])[1]
    stages["exchange"] = exchange(score, best, n_pool, a.exchange, rng) if a.exchange \
        else best
    return stages["exchange"], {k: score(v) for k, v in stages.items()}


def placement(x, rows):
    """Per input: shares of coordinates at an edge and in the middle half; screws inside."""
    edge = np.abs(scaled(x[rows], x) - 0.5) * 2
    return {"edge": (edge > 0.8).mean(0).tolist(), "middle": (edge < 0.5).mean(0).tolist(),
            "inside": int((edge.max(1) <= 0.8).sum())}


def case(a, prob, k, seed):
    x, y, xte, truth = ds.problem(prob, seed, a.whirl, a.datasets, a.sim_cache)
    order = [int(i) for i in np.random.default_rng([42, seed, len(prob)]).permutation(len(x))]
    with tempfile.TemporaryDirectory() as tmp:
        ev = ds.Evaluator(a.whirl, tmp, x, y, xte, truth)
        design = []
        ds.designed(ev, "d", 2, inside=[], picks=design)  # ds.SIZES = [8, 12]: the default's 12
        rows = {"design12": design[:12], "random12": order[:12], "random20": order[:20]}
        # the oracle scores on the list's own targets (--draws 0) or on --draws fresh draws
        sel = [ds.Evaluator(a.whirl, tmp, x, noisy(prob, seed, d), xte, truth)
               for d in range(a.draws)] or [ev]
        score = Scorer(sel, k)
        rng = np.random.default_rng([99, seed, k, len(prob)])
        rows["oracle12"], trace = oracle(score, rows, len(x), a, rng)
        out = {"rmse": {t: score(r) for t, r in rows.items()}, "trace": trace,
               "evaluations": score.count, "rows": rows,
               "placement": {t: placement(x, r) for t, r in rows.items()}}
        if a.draws:  # the tables retrained on other fresh draws than the oracle saw
            held = Scorer([ds.Evaluator(a.whirl, tmp, x, noisy(prob, seed, 100 + d), xte, truth)
                           for d in range(a.held_out_draws)], k)
            out["rmse_held_out"] = {t: held(r) for t, r in rows.items()}
            out["rmse_list"] = {t: Scorer([ev], k)(r) for t, r in rows.items()}
    if prob != "simgen":  # the input(s) the truth bends in, where the family says
        p = bp.GENERATORS[prob][1](np.random.default_rng([bp.GENERATORS[prob][0], seed]))
        out["bent_input"] = int(p["j"][k]) if "j" in p else None
    if a.progress:  # one line per case as it ends: a run stopped early still has its cases
        with a.lock, open(a.progress, "a") as h:
            h.write(json.dumps([prob, k, seed, out]) + "\n")
    print(f"{prob}/{bp.TARGETS[k]}/{seed}: oracle12 {out['rmse']['oracle12']:.4g}, random20 "
          f"{out['rmse']['random20']:.4g}, design12 {out['rmse']['design12']:.4g} "
          f"({score.count} fits)", flush=True)
    return prob, k, seed, out


def refit(a, prob, k, seed, rows, draws):
    """The output's test RMSE of each table of `rows` retrained on `draws` fresh noise draws of
    the list's targets at the same screws (generator families: is the oracle's gain its placement
    or the luck of the list's scatter?); the geometric mean over the draws per table."""
    x, _, xte, truth = ds.problem(prob, seed, a.whirl, a.datasets, a.sim_cache)
    with tempfile.TemporaryDirectory() as tmp:
        score = Scorer([ds.Evaluator(a.whirl, tmp, x, noisy(prob, seed, 100 + d), xte, truth)
                        for d in range(draws)], k)
        return {t: score(r) for t, r in rows.items()}


def fresh_noise(a, res):
    todo = [(p, k, s, c["rows"]) for p, k, s, c in res if p != "simgen"]
    with ThreadPoolExecutor(min(a.jobs, 2)) as ex:
        got = list(ex.map(lambda c: (c[0], c[1], c[2], refit(a, *c, a.fresh_noise)), todo))
    print(f"\nfresh noise ({a.fresh_noise} draws of the list's scatter at the same screws, "
          "geometric mean per seed; paired over seeds):")
    for prob, k in dict.fromkeys((p, k) for p, k, _, _ in got):
        r = {t: np.array([g[t] for p, kk, _, g in got if (p, kk) == (prob, k)])
             for t in got[0][3]}
        print(f"  {prob}, {bp.TARGETS[k]}: oracle12 / random20 "
              f"{paired(r['oracle12'] / r['random20'])}, design12 / random20 "
              f"{paired(r['design12'] / r['random20'])}, random12 / random20 "
              f"{paired(r['random12'] / r['random20'])}")
    return got


def paired(v):
    m, _, t = ds.paired_t(np.log(v))
    return f"{np.exp(m):.3f} ({t:+.1f})"


def summary(res):
    print("\nper output: paired ratios over seeds, exp(mean ln) (t); oracle 12 is a bound")
    for prob, k in dict.fromkeys((p, k) for p, k, _, _ in res):
        cs = [c for p, kk, _, c in res if (p, kk) == (prob, k)]
        r = {t: np.array([c["rmse"][t] for c in cs]) for t in cs[0]["rmse"]}
        reach = sum(r["oracle12"] <= r["random20"])
        print(f"\n{prob}, {bp.TARGETS[k]} ({len(cs)} seeds): oracle12 / random20 "
              f"{paired(r['oracle12'] / r['random20'])}, reached on {reach} of {len(cs)} seeds; "
              f"design12 / random20 {paired(r['design12'] / r['random20'])}; oracle12 / design12 "
              f"{paired(r['oracle12'] / r['design12'])}; stages / random20: "
              + ", ".join(f"{s} {paired(np.array([c['trace'][s] for c in cs]) / r['random20'])}"
                          for s in cs[0]["trace"]) + "; medians "
              + ", ".join(f"{t} {np.median(v):.4g}" for t, v in r.items())
              + f"; fits {int(np.mean([c['evaluations'] for c in cs]))} per case")
        for key, what in (("rmse_held_out", "held-out draws (the figure of a placement)"),
                          ("rmse_list", "the list's own targets")):
            if key in cs[0]:
                h = {t: np.array([c[key][t] for c in cs]) for t in cs[0][key]}
                print(f"  on {what}: oracle12 / random20 {paired(h['oracle12'] / h['random20'])}"
                      f", reached on {sum(h['oracle12'] <= h['random20'])} of {len(cs)} seeds; "
                      f"design12 / random20 {paired(h['design12'] / h['random20'])}; random12 / "
                      f"random20 {paired(h['random12'] / h['random20'])}")
        for t in ("oracle12", "design12", "random20"):
            pl = [c["placement"][t] for c in cs]
            edge, mid = (np.mean([q[s] for q in pl], 0) for s in ("edge", "middle"))
            print(f"  {t}: inside {np.mean([q['inside'] for q in pl]):.2f}; edge share per input "
                  + " ".join(f"{v:.2f}" for v in edge) + "; middle-half share per input "
                  + " ".join(f"{v:.2f}" for v in mid))
        if cs[0].get("bent_input") is not None:
            for t in ("oracle12", "design12", "random20"):
                j = [c["bent_input"] for c in cs]
                e = np.mean([c["placement"][t]["edge"][jj] for c, jj in zip(cs, j)])
                m = np.mean([c["placement"][t]["middle"][jj] for c, jj in zip(cs, j)])
                print(f"  {t} on the bent input: edge {e:.2f}, middle half {m:.2f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--whirl", default="build/whirl")
    ap.add_argument("--datasets", default=os.path.join(os.path.dirname(__file__), "..", "datasets"))
    ap.add_argument("--sim-cache", default=os.path.join(tempfile.gettempdir(), "whirl_design_sim"))
    ap.add_argument("--seeds", default="9901-9910")
    ap.add_argument("--seed-rule", default="stride", choices=ds.SEED_RULES, help=ds.SEED_RULE_HELP)
    ap.add_argument("--cases", default="bent:0,additive:0,additive:1,interacting:1,simgen:1,"
                    "powerlaw:1", help="problem:output (0 max elongation, 1 settle time)")
    ap.add_argument("--greedy", type=int, default=24, help="tries per forward step 9-12")
    ap.add_argument("--exchange", type=int, default=8, help="tries per screw, exchange of the 12")
    ap.add_argument("--draws", type=int, default=0, help="the oracle's criterion: the geometric "
                    "mean RMSE over this many fresh noise draws of the list's targets (generator "
                    "families; 0: the list's own targets)")
    ap.add_argument("--held-out-draws", type=int, default=4, help="with --draws: the tables "
                    "retrained on this many other draws, for the figures")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--json", help="write every case here")
    ap.add_argument("--progress", help="append each case here as a JSON line when it ends")
    ap.add_argument("--fresh-noise", type=int, default=0, help="with --from-json: retrain every "
                    "generator case's tables on this many fresh noise draws")
    ap.add_argument("--from-json", help="print the summary of an earlier --json run (or of a "
                    "--progress file)")
    a = ap.parse_args()
    if a.from_json:
        try:
            text = open(a.from_json).read()
            res = (json.loads(text)["cases"] if text.startswith("{") else
                   [json.loads(line) for line in text.splitlines() if line.strip()])
        except (OSError, ValueError, KeyError) as e:
            sys.exit(f"design_oracle: {a.from_json}: not a --json run or --progress file "
                     f"({type(e).__name__}: {e})")
        summary(res)
        if a.fresh_noise:
            got = fresh_noise(a, res)
            if a.json:
                with open(a.json, "w") as h:
                    json.dump(got, h)
        return
    a.lock = threading.Lock()
    ds.SIZES = [8, 12]  # the study's design loop, stopped at 12 screws
    os.makedirs(a.sim_cache, exist_ok=True)
    specs = [(p, int(k)) for p, k in (c.split(":") for c in a.cases.split(","))]
    seeds = {p: ds.usable_seeds(p, ds.seeds_of(a.seeds), a.seed_rule) for p, _ in specs}
    todo = [(p, k, seeds[p][i]) for i in range(len(ds.seeds_of(a.seeds))) for p, k in specs]
    with ThreadPoolExecutor(min(a.jobs, 2)) as ex:
        res = list(ex.map(lambda c: case(a, *c), todo))
    if a.json:
        with open(a.json, "w") as h:
            json.dump({"command": " ".join(sys.argv), "cases": res}, h)
    summary(res)


if __name__ == "__main__":
    main()
