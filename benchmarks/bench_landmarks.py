"""Time and memory of the landmark subsamplers on a large synthetic encounter graph.

Part 1 (10^6 events, ``--quick``: 10^5): maxmin, knn and probabilistic maxmin with 500
landmarks on the plain encounter metric, split into graph build / k-NN / landmark
picks / L x L distances, with peak memory above the baseline (Linux VmHWM, reset
through /proc/self/clear_refs after malloc_trim, so numba's allocations count too).  Targets: maxmin
< 60 s including the graph, knn / probabilistic < 120 s, < 4 GB.

Part 2: the L x L step, numba search (ours) vs scipy ``dijkstra`` from the landmarks
(keeping landmark columns), per source, measured on a sample of sources; and the
k-NN of every node, ours vs scipy ``dijkstra`` bounded at the k-th distance.

Part 3 (10^4 events): maxmin vs the dense approach (scipy all-pairs shortest paths,
then maxmin on the full matrix) from the same start, medians of repeats, the same
landmarks asserted.  Targets: >= 20x faster, >= 50x less peak memory.

The encounter log comes from a cheap synthetic mobility (not the simulator): agents
do correlated random walks on a torus, and every new pair within r_d is an event.

    python benchmarks/bench_landmarks.py [--quick]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numba
import numpy as np
from scipy.sparse.csgraph import dijkstra, shortest_path
from scipy.spatial import cKDTree

from _measure import run_measured
from swarmtopo.metric.graph import build_graph
from swarmtopo.metric.landmarks import SUBSAMPLERS, knn_distances, maxmin
from swarmtopo.log import EncounterLog

N_LANDMARKS = 500
STAGES = ("knn", "picks", "distances")


def synthetic_log(n_events, *, n_agents=300, side=500.0, r_d=30.0, speed=40.0, dt=0.1, rng=0):
    """Correlated random walks on a side x side torus (mm, s); events = new contacts."""
    rng = np.random.default_rng(rng)
    position = rng.uniform(0, side, (n_agents, 2))
    heading = rng.uniform(0, 2 * np.pi, n_agents)
    previous = np.empty(0, np.int64)
    t, a, b = [], [], []
    count, step = 0, 0
    while count < n_events:
        step += 1
        heading += rng.normal(0, 0.5, n_agents)
        position = (position + speed * dt * np.c_[np.cos(heading), np.sin(heading)]) % side
        pairs = cKDTree(position, boxsize=side).query_pairs(r_d, output_type="ndarray")
        keys = np.sort(pairs[:, 0].astype(np.int64) * n_agents + pairs[:, 1])
        new = keys[~np.isin(keys, previous, assume_unique=True)]
        previous = keys
        t.append(np.full(len(new), step * dt))
        a.append(new // n_agents)
        b.append(new % n_agents)
        count += len(new)
    t, a, b = (np.concatenate(x)[:n_events] for x in (t, a, b))
    return EncounterLog.from_records(t, a, b, meta={"agent_count": n_agents, "r_d": r_d})


class StageClock:
    """Progress callback that records when each stage starts."""

    def __init__(self):
        self.marks = [("start", time.perf_counter())]

    def __call__(self, stage):
        self.marks.append((stage, time.perf_counter()))

    def durations(self) -> dict[str, float]:
        return {name: nxt - at for (name, at), (_, nxt) in zip(self.marks[:-1], self.marks[1:])}


def warm_up():
    """Load every numba kernel (compiled or cached) so no run pays for it."""
    graph = build_graph(synthetic_log(2000, rng=1), "plain")
    for method in SUBSAMPLERS.values():
        method(graph, 20, rng=0)


def large_scale(n_events):
    log, log_s = run_measured(lambda: synthetic_log(n_events))[:2]
    graph, graph_s, graph_mem, _ = run_measured(lambda: build_graph(log, "plain"))
    print(f"\n## {n_events:.0e} events, {log.n_agents} agents, {log.duration:.0f} s of synthetic log "
          f"(made in {log_s:.1f} s): graph {graph.n_nodes} nodes, {graph.adjacency.nnz // 2} edges, "
          f"built in {graph_s:.2f} s, {graph_mem / 2**20:.0f} MB\n")
    print("| method | graph s | k-NN s | picks s | L x L s | total s (incl. graph) | peak MB | target |")
    print("|---|---|---|---|---|---|---|---|")
    results = {}
    for name, method in SUBSAMPLERS.items():
        clock = StageClock()
        result, seconds, peak, _ = run_measured(lambda: method(graph, N_LANDMARKS, rng=0, progress=clock))
        stage = clock.durations()
        total = graph_s + seconds
        limit = 60.0 if name == "maxmin" else 120.0
        ok = total < limit and peak < 4 * 2**30
        print(f"| {name} | {graph_s:.2f} | {stage.get('knn', 0.0):.2f} | {stage['picks']:.2f} | "
              f"{stage['distances']:.2f} | {total:.1f} | {peak / 2**20:.0f} | "
              f"< {limit:.0f} s, < 4 GB: {'yes' if ok else 'NO'} |")
        results[name] = (result, stage)
    return graph, results


def lxl_engines(graph, result, stage, n_sample):
    """Per-source cost of the L x L rows: our numba search vs scipy dijkstra."""
    sample = result.nodes[:n_sample]
    times = []
    for _ in range(3):
        start = time.perf_counter()
        rows = dijkstra(graph.adjacency, directed=True, indices=sample)[:, result.nodes]
        times.append(time.perf_counter() - start)
    scipy_per_source = statistics.median(times) / n_sample
    ours_per_source = stage["distances"] / len(result.nodes)
    np.testing.assert_allclose(rows, result.distances[:n_sample], rtol=1e-12)
    print(f"\n## L x L rows at {graph.n_nodes} nodes (scipy: median of 3 on {n_sample} sources)\n")
    print("| engine | ms per source | L = 500 rows, s | ratio |")
    print("|---|---|---|---|")
    print(f"| scipy dijkstra (C, 1 thread, dense rows) | {1e3 * scipy_per_source:.1f} | "
          f"{N_LANDMARKS * scipy_per_source:.1f} (extrapolated) | 1.0 |")
    print(f"| numba settle, prange over sources (ours) | {1e3 * ours_per_source:.1f} | "
          f"{N_LANDMARKS * ours_per_source:.1f} | {scipy_per_source / ours_per_source:.1f}x |")


def knn_engines(graph, k=10, n_sample=50, repeats=3):
    """k-NN of every node: our stopping search vs scipy dijkstra bounded at the k-th distance."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        ours = knn_distances(graph, k)
        times.append(time.perf_counter() - start)
    ours_s = statistics.median(times)
    sample = np.random.default_rng(0).choice(graph.n_nodes, n_sample, replace=False)
    start = time.perf_counter()
    for x in sample:
        # the most favourable bound for scipy: the k-th distance, known in advance
        row = dijkstra(graph.adjacency, directed=True, indices=x, limit=ours[x, -1] * (1 + 1e-12))
        reached = np.flatnonzero(np.isfinite(row))
        neighbours = np.sort(np.repeat(row[reached], graph.multiplicity[reached]))[1:k + 1]
        assert np.allclose(neighbours, ours[x][: len(neighbours)])
    scipy_s = (time.perf_counter() - start) / n_sample * graph.n_nodes
    print(f"\n## k-NN (k = {k}) of all {graph.n_nodes} nodes (ours: median of {repeats}; "
          f"scipy: {n_sample} sources, extrapolated)\n")
    print("| engine | s for all nodes | ratio |")
    print("|---|---|---|")
    print(f"| scipy dijkstra, limit = k-th NN distance | {scipy_s:.0f} (extrapolated) | 1.0 |")
    print(f"| numba settle, stops after k points (ours) | {ours_s:.2f} | {scipy_s / ours_s:.0f}x |")


def dense_maxmin(graph, n_landmarks, start):
    """The approach we replace: all-pairs matrix, then textbook maxmin on it."""
    d = shortest_path(graph.adjacency, method="D", directed=True)
    chosen, u = [start], d[start].copy()
    for _ in range(n_landmarks - 1):
        chosen.append(int(np.argmax(u)))
        np.minimum(u, d[chosen[-1]], out=u)
    return np.array(chosen), d[np.ix_(chosen, chosen)]


def compare_with_dense(graph, heading: str, repeats: int = 3) -> None:
    """maxmin (bounded searches + L x L) against dense_maxmin on ``graph``, side by side:
    checks they pick the same landmarks and distances, prints wall, CPU and memory."""
    ours = [run_measured(lambda: maxmin(graph, N_LANDMARKS, rng=0)) for _ in range(repeats)]
    start = int(ours[0][0].nodes[0])
    dense = [run_measured(lambda: dense_maxmin(graph, N_LANDMARKS, start)) for _ in range(repeats)]
    nodes, distances = dense[0][0]
    np.testing.assert_array_equal(ours[0][0].nodes, nodes)
    np.testing.assert_allclose(ours[0][0].distances, distances, rtol=1e-12)
    wall, cpu, peak = ([statistics.median(run[i] for run in runs) for runs in (ours, dense)] for i in (1, 3, 2))
    print(f"\n## {heading}, L = {N_LANDMARKS}, median of {repeats}; same landmarks and distances: yes\n")
    print("| approach | wall s | CPU s (all threads) | peak MB above baseline |")
    print("|---|---|---|---|")
    print(f"| dense: all-pairs shortest_path + maxmin | {wall[1]:.2f} | {cpu[1]:.2f} | {peak[1] / 2**20:.1f} |")
    print(f"| ours: bounded searches + L x L | {wall[0]:.3f} | {cpu[0]:.3f} | {peak[0] / 2**20:.1f} |")
    time_ratio, memory_ratio = wall[1] / wall[0], peak[1] / max(peak[0], 1)
    print(f"| ratio | {time_ratio:.0f}x | {cpu[1] / cpu[0]:.0f}x | {memory_ratio:.0f}x |")
    print(f"\ntarget >= 20x faster: {'met' if time_ratio >= 20 else 'NOT met'}; "
          f">= 50x less memory: {'met' if memory_ratio >= 50 else 'NOT met'}")


def against_dense(n_events, repeats=3):
    graph = build_graph(synthetic_log(n_events, rng=2), "plain")
    compare_with_dense(graph, f"maxmin vs dense at {n_events:.0e} events ({graph.n_nodes} nodes)", repeats)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="10^5 events instead of 10^6")
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores, "
          f"{numba.get_num_threads()} numba threads")
    warm_up()
    graph, results = large_scale(10**5 if args.quick else 10**6)
    result, stage = results["maxmin"]
    lxl_engines(graph, result, stage, n_sample=10 if args.quick else 20)
    knn_engines(graph)
    against_dense(10**4)
    print(f"\nload average after: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
