# Put first on PYTHONPATH by tests/lab/lab_common.sh: the lab tests run the scripts as CI does,
# where scikit-learn is not installed (scripts/setup.sh installs it only with
# WHIRL_SETUP_BENCH_PEERS=1), also on a machine that has it.
raise ImportError("scikit-learn is hidden from the lab tests (tests/lab/no_sklearn)")
