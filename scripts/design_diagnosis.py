#!/usr/bin/python3
"""The eighth attempt's diagnosis (docs/design.md): per case of a `design_study.py --json` run, the
designed tables at 12 and 20 screws and the random ones at 12 and 20 (the study's own random
order): the default model's test RMSE and choice per output, a power law alone on the same rows
(`--family linear --transform log`), both trained on the noise-free truth at the same rows (the
generator families: what is left is bias, not scatter), and the rows' geometry on log inputs
scaled to the list's box (mean |u - 0.5| * 2, share of coordinates in the outer 10 % at either
end, rows with no such coordinate, smallest distance, rows closer than 0.1 to another).

Usage: /usr/bin/python3 scripts/design_diagnosis.py --whirl build/whirl RUN.json OUT.json"""
import json, os, subprocess, sys, tempfile
from concurrent.futures import ThreadPoolExecutor
import numpy as np
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_peers as bp
import design_study as ds

WHIRL = "build/whirl"
DATASETS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "datasets")

def truth_pool(prob, seed):
    fid, params, sample, _ = bp.GENERATORS[prob]
    p = params(np.random.default_rng([fid, seed]))
    rng = np.random.default_rng([fid, ds.POOL_ROWS, seed])
    u, f, y = sample(p, rng, ds.POOL_ROWS)
    return f

def run_checked(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode:
        raise subprocess.CalledProcessError(r.returncode, cmd, r.stdout, r.stderr)
    return r

def train_pred(tmp, name, x, y, xte, extra=()):
    d, m = os.path.join(tmp, name + ".csv"), os.path.join(tmp, name + ".json")
    bp.write_table(d, x, y)
    t = json.loads(run_checked([WHIRL, "train", "--data", d, "--out", m, "--seed", "1", "--threads", "1", "--json", *extra]).stdout)
    test = os.path.join(tmp, "test.csv")
    p = json.loads(subprocess.run([WHIRL, "predict", "--model", m, "--input", test, "--json"], capture_output=True, text=True, check=True).stdout)
    mean = np.array([[r["max_elongation_um"], r["settle_time_s"]] for r in p["predictions"]])
    return t, mean

def geometry(x, rows, lo, hi):
    u = (np.log(x[rows]) - np.log(lo)) / np.where(hi > lo, np.log(hi) - np.log(lo), 1)
    edge = np.abs(u - 0.5) * 2  # 1 at a face
    d = np.sqrt(((u[:, None] - u[None]) ** 2).sum(-1)); d[np.diag_indices(len(rows))] = np.inf
    return {"mean_edge": float(edge.mean()), "frac_coords_edge": float((edge > 0.8).mean()),
            "interior_pts": int((edge.max(1) < 0.8).sum()), "min_dist": float(d.min()),
            "n_close": int((d.min(1) < 0.1).sum())}

def case(args):
    prob, seed, picks = args
    x, y, xte, truth = ds.problem(prob, seed, WHIRL, DATASETS,
                                  os.path.join(tempfile.gettempdir(), "whirl_design_sim"))
    f = truth_pool(prob, seed) if prob != "simgen" else None
    rng = np.random.default_rng([42, seed, len(prob)])
    order = [int(i) for i in rng.permutation(len(x))]
    lo, hi = x.min(0), x.max(0)
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        bp.write_table(os.path.join(tmp, "test.csv"), xte)
        for tab, rows in (("design12", picks[:12]), ("design20", picks[:20]), ("random12", order[:12]), ("random20", order[:20])):
            r = {}
            t, mean = train_pred(tmp, "d", x[rows], y[rows], xte)
            r["rmse"] = bp.rmse(mean, truth).tolist(); r["chosen"] = t["chosen"]; r["sd_scale"] = list(t["sd_scale"].values())
            _, mean = train_pred(tmp, "p", x[rows], y[rows], xte, ("--family", "linear", "--transform", "log"))
            r["rmse_pl"] = bp.rmse(mean, truth).tolist()
            if f is not None:
                try:
                    _, mean = train_pred(tmp, "f", x[rows], f[rows], xte)
                    r["rmse_nf"] = bp.rmse(mean, truth).tolist()
                except subprocess.CalledProcessError as e:
                    r["rmse_nf"] = None; r["nf_err"] = e.stderr[-300:]
                try:
                    _, mean = train_pred(tmp, "fp", x[rows], f[rows], xte, ("--family", "linear", "--transform", "log"))
                    r["rmse_nf_pl"] = bp.rmse(mean, truth).tolist()
                except subprocess.CalledProcessError as e:
                    r["rmse_nf_pl"] = None
            r["geom"] = geometry(x, rows, lo, hi)
            out[tab] = r
    return prob, seed, out

if __name__ == "__main__":
    args = sys.argv[1:]
    if args[:1] == ["--whirl"]:
        WHIRL, args = os.path.abspath(args[1]), args[2:]
    base = json.load(open(args[0]))
    probs = args[2].split(",") if len(args) > 2 else None
    todo = [(p, s, base["design_picks"][f"{p}/{s}"]) for p, s, _ in base["cases"] if probs is None or p in probs]
    with ThreadPoolExecutor(2) as ex:
        res = list(ex.map(case, todo))
    json.dump(res, open(args[1], "w"))
