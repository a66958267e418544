#!/usr/bin/python3
"""MD5 of the model files `whirl train --threads 1 --seed 1` writes for a fixed set of tables: the
proof that a speed change left every model bit for bit as it was (docs/workpiece-model.md, "Speed").

Usage: model_md5.py WHIRL [WHIRL ...]
Tables: datasets/whirling_train.csv; the first 100 rows and all of datasets/whirling_500.csv;
seeds 1001 and 1002 of scripts/bench_peers.py's ten generator families (powerlaw, bent, friedman,
additive, friedman23, interacting, powerlaw_noisy, saturating, powerlaw_step, hetero) at 8, 9, 20,
40, 70 and 100 rows; seed 1001 of bent and friedman at 300 and 2,000 rows (127 tables). Prints one
line per table with each binary's MD5 and "same" or "DIFFERENT", then the count; exits 1 if any
table's files differ between the binaries. Needs numpy (Debian python3-numpy).
"""
import hashlib
import importlib.util
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location("bench_peers", os.path.join(HERE, "bench_peers.py"))
bp = importlib.util.module_from_spec(spec)
spec.loader.exec_module(bp)

TEN = ("powerlaw", "bent", "friedman", "additive", "friedman23", "interacting", "powerlaw_noisy",
       "saturating", "powerlaw_step", "hetero")


def tables(tmp):
    """(name, path) of every table, written into tmp."""
    datasets = os.path.join(HERE, "..", "datasets")
    out = [("whirling_train", os.path.join(datasets, "whirling_train.csv")),
           ("whirling_500", os.path.join(datasets, "whirling_500.csv"))]
    with open(out[1][1]) as f:
        lines = f.readlines()
    first100 = os.path.join(tmp, "whirling_500_first100.csv")
    with open(first100, "w") as f:
        f.writelines(lines[:101])
    out.append(("whirling_500_first100", first100))
    cases = [(fam, n, seed) for fam in TEN for n in (8, 9, 20, 40, 70, 100) for seed in (1001, 1002)]
    cases += [(fam, n, 1001) for fam in ("bent", "friedman") for n in (300, 2000)]
    for fam, n, seed in cases:
        xtr, ytr, *_ = bp.problem_data(fam, n, seed, None, None, None)
        path = os.path.join(tmp, f"{fam}_{n}_{seed}.csv")
        bp.write_table(path, xtr, ytr)
        out.append((f"{fam}_{n}_{seed}", path))
    return out


def model_md5(whirl, table, model):
    subprocess.run([whirl, "train", "--data", table, "--out", model, "--threads", "1", "--seed",
                    "1"], check=True, capture_output=True)
    with open(model, "rb") as f:
        return hashlib.md5(f.read()).hexdigest()


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    differ = 0
    with tempfile.TemporaryDirectory() as tmp:
        all_tables = tables(tmp)
        model = os.path.join(tmp, "m.json")
        for name, path in all_tables:
            sums = [model_md5(w, path, model) for w in sys.argv[1:]]
            same = len(set(sums)) == 1
            differ += 0 if same else 1
            print(f"{name:28s} {' '.join(sums)} {'same' if same else 'DIFFERENT'}", flush=True)
    print(f"{len(all_tables)} tables, {differ} with different model files")
    sys.exit(1 if differ else 0)


if __name__ == "__main__":
    main()
