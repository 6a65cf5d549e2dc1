"""Tuning maps of the fault benchmark: ``bench faults``' tuning cases mapped with the
default pipeline, stored for ``lab/calibrate_faults.py``.

    python lab/tune_faults.py --store faults-tuning.duckdb --per-cell 2 --workers 2

Prints the benchmark's table of the tuning cases (no reporting case is run).
"""

from __future__ import annotations

import argparse

from swarmtopo.experiments.faults import markdown, run_benchmark


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--store", default="faults-tuning.duckdb")
    parser.add_argument("--per-cell", type=int, default=2, help="tuning cases per hole count and fault level")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    summary = run_benchmark(args.store, split="tuning", per_cell=args.per_cell, workers=args.workers)
    print(markdown(summary, f"python lab/tune_faults.py --per-cell {args.per_cell}"))


if __name__ == "__main__":
    main()
