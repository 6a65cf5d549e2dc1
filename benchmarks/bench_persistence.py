"""Time the Rips persistence backends on landmark-like distance matrices.

For each L, every installed backend runs through the adapter
(``swarmtopo.persistence.rips_persistence``, maxdim 1) on the same matrix; the table
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
from scipy.sparse.csgraph import dijkstra
from sklearn.neighbors import kneighbors_graph

from swarmtopo.persistence import available_backends, rips_persistence

SIZES = (150, 300, 500, 1000, 2000)
QUICK_SIZES = (150, 300, 500)
HOLES = ((0.2, 0.3, 0.4, 0.7), (0.6, 0.3, 0.8, 0.7))  # x0, y0, x1, y1 in the unit square


def landmark_matrices(sizes, rng) -> dict[int, np.ndarray]:
    """Stand-in for the pipeline's landmark matrices: maxmin landmarks of a 2-hole domain.

    Points are uniform in the unit square minus two 0.2 x 0.4 squares; distances are
    geodesic (shortest paths in the symmetric 8-NN graph, Euclidean edge lengths, which
    never cross a hole at this density).  Landmarks are chosen by maxmin on those
    distances; the first L landmarks are again a maxmin set, so each size is a prefix
    of the largest.  Swap this function for real encounter-metric landmark matrices.
    """
    rng = np.random.default_rng(rng)
    n_points = max(3000, 3 * max(sizes))
    points = np.empty((0, 2))
    while len(points) < n_points:
        candidates = rng.random((n_points, 2))
        inside_hole = np.zeros(len(candidates), bool)
        for x0, y0, x1, y1 in HOLES:
            inside_hole |= (candidates[:, 0] > x0) & (candidates[:, 0] < x1) & \
                           (candidates[:, 1] > y0) & (candidates[:, 1] < y1)
        points = np.vstack([points, candidates[~inside_hole]])
    points = points[:n_points]
    graph = kneighbors_graph(points, 8, mode="distance")
    graph = graph.maximum(graph.T)
    landmarks = [int(rng.integers(n_points))]
    rows = [dijkstra(graph, indices=landmarks[0])]
    if not np.isfinite(rows[0]).all():
        raise RuntimeError("the kNN graph is disconnected; raise k")
    cover = rows[0].copy()
    for _ in range(max(sizes) - 1):
        landmarks.append(int(np.argmax(cover)))
        rows.append(dijkstra(graph, indices=landmarks[-1]))
        np.minimum(cover, rows[-1], out=cover)
    full = np.array(rows)[:, landmarks]
    full = 0.5 * (full + full.T)
    return {size: full[:size, :size].copy() for size in sizes}


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

    start = time.perf_counter()
    matrices = landmark_matrices(sizes, rng=20240611)
    print(f"landmark matrices of a 2-hole domain built in {time.perf_counter() - start:.1f} s")
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
