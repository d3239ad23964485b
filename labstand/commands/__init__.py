"""One module per sub-command; each exposes ``register(subparsers)``.

A module imports at its top only what its parser needs (argparse, light tables such as
the situations): numba, scipy, pandas, matplotlib, h5py, mcap and pymodbus are imported
inside the function that runs the command, so ``labstand CMD --help`` answers at once
(tests/core/test_cli_startup.py, benchmarks/bench_startup.py).
"""
