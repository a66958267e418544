#!/usr/bin/python3
"""Writes the generated tables of tests/bench/bench_family.cpp's BM_WorkpieceGenerated.

Usage: bench_tables.py OUT_DIR
One table per family and size, seed 1001 (the first table of scripts/train_cpu.py, seeds 1001- of
scripts/bench_peers.py's confirmation part), from bench_peers.py's own generator
(problem_data): OUT_DIR/FAMILY_ROWS.csv, its first line a '#' comment naming this command.
Needs numpy (Debian python3-numpy).
"""
import importlib.util
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location("bench_peers", os.path.join(HERE, "bench_peers.py"))
bp = importlib.util.module_from_spec(spec)
spec.loader.exec_module(bp)

FAMILIES = ("friedman23", "additive", "interacting", "powerlaw_noisy")
ROWS = (20, 100)
SEED = 1001


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    for fam in FAMILIES:
        for n in ROWS:
            xtr, ytr, *_ = bp.problem_data(fam, n, SEED, None, None, None)
            path = os.path.join(out, f"{fam}_{n}.csv")
            bp.write_table(path, xtr, ytr)
            with open(path) as f:
                body = f.read()
            with open(path, "w") as f:
                f.write(f"# scripts/bench_tables.py: bench_peers.py problem_data('{fam}', {n}, "
                        f"seed {SEED}), the training rows\n" + body)


if __name__ == "__main__":
    main()
