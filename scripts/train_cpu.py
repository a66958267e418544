#!/usr/bin/python3
"""CPU time of `whirl train --threads 1` (the default model) on generated tables, per family.

Usage: train_cpu.py WHIRL ROWS SEEDS FAMILIES
  ROWS: comma-separated table sizes (e.g. 20,100); SEEDS: tables per size (seeds 1001, 1002, ...
  of scripts/bench_peers.py's confirmation part); FAMILIES: comma-separated problems of
  bench_peers.py (powerlaw, bent, friedman, additive, simgen, friedman23, interacting,
  powerlaw_noisy).
Prints per family and size the median and largest CPU time (user + system of the whirl process,
from the kernel's accounting: it includes starting the process and reading and writing the files,
about 4 ms). Needs numpy (Debian python3-numpy; scripts/bench_peers.sh installs it).
"""
import importlib.util
import os
import resource
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location("bench_peers", os.path.join(HERE, "bench_peers.py"))
bp = importlib.util.module_from_spec(spec)
spec.loader.exec_module(bp)


def child_cpu_ms():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return 1000.0 * (r.ru_utime + r.ru_stime)


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    whirl, rows, seeds, families = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
    datasets = os.path.join(HERE, "..", "datasets")
    with tempfile.TemporaryDirectory() as tmp:
        table, model = os.path.join(tmp, "t.csv"), os.path.join(tmp, "m.json")
        for fam in families.split(","):
            for n in (int(r) for r in rows.split(",")):
                cpu = []
                for seed in range(1001, 1001 + seeds):
                    xtr, ytr, *_ = bp.problem_data(fam, n, seed, whirl, datasets, tmp)
                    bp.write_table(table, xtr, ytr)
                    before = child_cpu_ms()
                    subprocess.run([whirl, "train", "--data", table, "--out", model, "--threads",
                                    "1", "--seed", str(seed)], check=True, capture_output=True)
                    cpu.append(child_cpu_ms() - before)
                print(f"{fam:15s} {n:5d} rows: median CPU {np.median(cpu):7.1f} ms, "
                      f"max {max(cpu):7.1f} ms ({len(cpu)} tables)", flush=True)


if __name__ == "__main__":
    main()
