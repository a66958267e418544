#!/usr/bin/python3
"""The eighth attempt's diagnosis (docs/design.md): why the designed screws trail random ones at 12
screws. Per case of a `design_study.py --json` run, the designed tables at 12 and 20 screws and the
random ones at 12 and 20 (the study's own random order), each trained as the study does:
  the default model's test RMSE and its choice per output (`whirl train --json`, "chosen");
  a power law alone on the same rows (`--family linear --transform log`);
  both trained on the generator's noise-free truth at the same rows (generator families only:
  what is left is bias, not scatter; None where `whirl train` refuses the table);
  the default model's RMSE also on the test rows inside the box (no coordinate in its outer
  10 % at either end) and on the others;
  the rows' geometry on log inputs scaled to the list's box, u in [0, 1]: mean |2u - 1|, the
  share of coordinates in the outer 10 % at either end, rows with none there ("inside"), the
  smallest distance between two rows and the rows closer than 0.1 to another.
Prints geometric means over the seeds per problem and output, choice counts and the geometry.

Usage: /usr/bin/python3 scripts/design_diagnosis.py --whirl build/whirl RUN.json OUT.json
         [--problems bent,additive]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_peers as bp  # noqa: E402
import design_study as ds  # noqa: E402

TABLES = ("design12", "random12", "random20", "design20")
POWER_LAW = ("--family", "linear", "--transform", "log")


def truth_pool(prob, seed):
    """The noise-free truth at the candidate list's rows (bench_peers.generated's draw)."""
    fid, params, sample, _ = bp.GENERATORS[prob]
    p = params(np.random.default_rng([fid, seed]))
    return sample(p, np.random.default_rng([fid, ds.POOL_ROWS, seed]), ds.POOL_ROWS)[1]


def fit(a, tmp, x, y, extra=()):
    """(choice summary, test RMSE per output) of `whirl train` on (x, y); None if it refuses.
    The RMSE is {"all", "inside", "edge"}: over every test row, the rows with no coordinate in
    the outer 10 % of the list's box (log inputs), and the others."""
    data, model = os.path.join(tmp, "t.csv"), os.path.join(tmp, "m.json")
    bp.write_table(data, x, y)
    r = subprocess.run([a.whirl, "train", "--data", data, "--out", model, "--seed", "1",
                        "--threads", "1", "--json", *extra], capture_output=True, text=True)
    if r.returncode:
        return None, None
    p = json.loads(ds.run([a.whirl, "predict", "--model", model, "--input",
                           os.path.join(tmp, "test.csv"), "--json"]))
    mean = np.array([[q["max_elongation_um"], q["settle_time_s"]] for q in p["predictions"]])
    truth, inside = a.truth_of[tmp]
    return json.loads(r.stdout), {"all": bp.rmse(mean, truth).tolist(),
                                  "inside": bp.rmse(mean[inside], truth[inside]).tolist(),
                                  "edge": bp.rmse(mean[~inside], truth[~inside]).tolist()}


def scaled(x, pool):
    """x's log inputs scaled to the box of pool's, u in [0, 1] inside it."""
    lo, hi = np.log(pool.min(0)), np.log(pool.max(0))
    return (np.log(x) - lo) / np.where(hi > lo, hi - lo, 1.0)


def geometry(x, rows):
    u = scaled(x[rows], x)
    edge = np.abs(u - 0.5) * 2  # 1 at a face of the box
    d = np.sqrt(((u[:, None] - u[None]) ** 2).sum(-1))
    d[np.diag_indices(len(rows))] = np.inf
    return {"mean_edge": float(edge.mean()), "share_edge": float((edge > 0.8).mean()),
            "inside": int((edge.max(1) < 0.8).sum()), "min_distance": float(d.min()),
            "close": int((d.min(1) < 0.1).sum())}


def case(a, prob, seed, picks):
    x, y, xte, truth = ds.problem(prob, seed, a.whirl, a.datasets, a.sim_cache)
    f = truth_pool(prob, seed) if prob != "simgen" else None
    order = [int(i) for i in np.random.default_rng([42, seed, len(prob)]).permutation(len(x))]
    rows_of = {"design12": picks[:12], "design20": picks[:20], "random12": order[:12],
               "random20": order[:20]}
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        bp.write_table(os.path.join(tmp, "test.csv"), xte)
        a.truth_of[tmp] = truth, (np.abs(scaled(xte, x) - 0.5) * 2).max(1) < 0.8
        for tab, rows in rows_of.items():
            t, rmse = fit(a, tmp, x[rows], y[rows])
            r = {"rmse": rmse["all"], "rmse_inside": rmse["inside"], "rmse_edge": rmse["edge"],
                 "chosen": t["chosen"], "geometry": geometry(x, rows),
                 "rmse_power_law": overall(fit(a, tmp, x[rows], y[rows], POWER_LAW)[1])}
            if f is not None:
                r["rmse_noise_free"] = overall(fit(a, tmp, x[rows], f[rows])[1])
                r["rmse_noise_free_power_law"] = overall(
                    fit(a, tmp, x[rows], f[rows], POWER_LAW)[1])
            out[tab] = r
    return prob, seed, out


def overall(rmse):
    return rmse and rmse["all"]


def kind(chosen, k):
    """'power law', 'stack' or 'one other' for output k of `whirl train`'s "chosen"."""
    part = chosen.split(", ")[k].split(": ", 1)[1]
    return "power law" if part == "linear/log" else "stack" if "+" in part else "one other"


def geometric_mean(v):
    v = [x for x in v if x is not None]
    return np.exp(np.mean(np.log(v))) if v else float("nan")


def summary(res):
    for prob in dict.fromkeys(p for p, _, _ in res):
        cases = [r for p, _, r in res if p == prob]
        for k, out in enumerate(bp.TARGETS):
            print(f"\n{prob}, {out}: geometric mean test RMSE over {len(cases)} seeds")
            for tab in TABLES:
                cells = []
                for key in ("rmse", "rmse_inside", "rmse_edge", "rmse_power_law",
                            "rmse_noise_free", "rmse_noise_free_power_law"):
                    if key in cases[0][tab]:
                        v = geometric_mean([c[tab][key] and c[tab][key][k] for c in cases])
                        cells.append(f"{key} {v:.3g}")
                kinds = [kind(c[tab]["chosen"], k) for c in cases]
                cells += [f"{n} {kinds.count(n)}" for n in ("power law", "stack", "one other")]
                print(f"  {tab}: " + ", ".join(cells))
        for tab in TABLES:
            g = [c[tab]["geometry"] for c in cases]
            print(f"  {tab} rows: " + ", ".join(f"{n} {np.mean([x[n] for x in g]):.2f}"
                                                for n in g[0]))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("run", help="a design_study.py --json run (with design_picks)")
    ap.add_argument("out", help="JSON of every case's figures")
    ap.add_argument("--whirl", default="build/whirl")
    ap.add_argument("--datasets", default=os.path.join(os.path.dirname(__file__), "..", "datasets"))
    ap.add_argument("--sim-cache", default=os.path.join(tempfile.gettempdir(), "whirl_design_sim"))
    ap.add_argument("--problems", help="only these (comma-separated)")
    a = ap.parse_args()
    a.truth_of = {}
    keep = a.problems.split(",") if a.problems else None
    try:
        base = json.load(open(a.run))
        todo = [(p, s, base["design_picks"][f"{p}/{s}"]) for p, s, _ in base["cases"]
                if keep is None or p in keep]
    except (OSError, ValueError, KeyError, TypeError) as e:
        sys.exit(f"design_diagnosis: {a.run}: not a design_study.py --json run with design_picks "
                 f"({type(e).__name__}: {e})")
    with ThreadPoolExecutor(2) as ex:
        res = list(ex.map(lambda c: case(a, *c), todo))
    json.dump(res, open(a.out, "w"))
    summary(res)


if __name__ == "__main__":
    main()
