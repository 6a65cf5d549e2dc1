"""Time the Rips persistence backends on the pipeline's landmark distance matrices.

The matrices are real: maxmin landmarks (L = 150 ... 2,000, each a prefix of the
largest set) of the hybrid encounter metric of a simulated two-hole log of 10^5
events (``_data.landmark_matrices``; cached after the first run, which takes about a
minute).  For each L, every installed backend runs through the adapter
(``swarmtopo.topology.persistence.rips_persistence``, maxdim 1) on the same matrix; the table
gives medians of repeats, the ratio of the default backend ("auto") to the fastest
(target <= 1.2), the raw library time of the default (adapter overhead), whether all
backends returned identical diagrams, and the three longest H1 bars (two holes).

    python benchmarks/bench_persistence.py [--quick]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from _data import landmark_matrices
from _measure import machine, revision
from swarmtopo.topology.persistence import available_backends, rips_persistence

SIZES = (150, 300, 500, 1000, 2000)
QUICK_SIZES = (150, 300, 500)
SEED = 0


def median_seconds(run, repeats):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def raw_default(matrix):
    from gudhi.sklearn.rips_persistence import RipsPersistence

    RipsPersistence([0, 1], input_type="full distance matrix", homology_coeff_field=2).fit_transform([matrix])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help=f"sizes {QUICK_SIZES}, fewer repeats")
    args = parser.parse_args()
    sizes = QUICK_SIZES if args.quick else SIZES
    backends = available_backends()
    default = rips_persistence(np.zeros((1, 1))).backend

    print(f"machine: {machine()}; swarmtopo {revision()}")
    start = time.perf_counter()
    matrices = landmark_matrices(sizes, seed=SEED)
    print(f"maxmin landmark matrices (hybrid metric, simulated 2-hole log, 10^5 events) "
          f"ready in {time.perf_counter() - start:.1f} s")
    print(f"backends: {backends}; default (auto): {default}; maxdim 1; median seconds")
    header = f"{'L':>5} " + " ".join(f"{name:>9}" for name in backends)
    header += f" {'default/fastest':>15} {'raw ' + default:>10} {'identical':>9}  longest H1 bars"
    print(header)
    for size, matrix in matrices.items():
        repeats = 3 if args.quick or size >= 1000 else 7
        times, diagrams = {}, {}
        for name in backends:
            diagrams[name] = rips_persistence(matrix, 1, backend=name).diagram  # warm-up
            times[name] = median_seconds(lambda: rips_persistence(matrix, 1, backend=name), repeats)
        raw = median_seconds(lambda: raw_default(matrix), repeats)
        reference = diagrams[default]
        identical = all(
            np.array_equal(d[dim], reference[dim]) for d in diagrams.values() for dim in (0, 1)
        )
        ratio = times[default] / min(times.values())
        row = f"{size:>5} " + " ".join(f"{times[name]:>9.3f}" for name in backends)
        longest = ", ".join(f"{length:.3f}" for length in reference.lengths(1)[:3])
        row += f" {ratio:>15.2f} {raw:>10.3f} {str(identical):>9}  {longest}"
        print(row, flush=True)


if __name__ == "__main__":
    main()
