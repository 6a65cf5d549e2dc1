"""Encounter-graph construction: time and memory at 10^6 events, and sparse vs literal.

Part 1 (10^6 events, ``--quick``: 10^5): ``build_graph`` on a simulated two-hole log
(``_data.simulated_log``: 2,000 agents, 10 % static) for the plain, contracted and
hybrid metrics: median build time of 3 runs, the tracemalloc peak of one more run
(Python and numpy allocations) and the peak RSS above the level before the call
(everything, numba and scipy included).  The graph's nodes and undirected edges stand
next to the number of edges the literal graph would have (every pair of events
sharing an agent, sum over agents of m_k (m_k - 1) / 2), counted, not built.

Part 2 (N = 1,000, 2,000, 4,000 simulated events, ``--quick``: 1,000 and 2,000): the
all-pairs event distances from the sparse chain graph (build + Dijkstra from every
node + expansion to events) against ``graph.literal_distances`` (the paper's dense
definition), medians of 3, the two matrices asserted equal.

    python benchmarks/bench_graph.py [--quick]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
import tracemalloc

import numpy as np

from _data import simulated_log
from _measure import machine, revision, run_measured
from swarmtopo.metric.graph import METRICS, build_graph, literal_distances

REPEATS = 3


def median_seconds(run, repeats=REPEATS):
    """(median wall seconds, last result)."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        result = run()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


def traced_peak(run) -> int:
    """Peak bytes traced by tracemalloc during ``run()``."""
    tracemalloc.start()
    try:
        run()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def literal_edge_count(log) -> int:
    """Edges of the literal graph: pairs of events that share an agent (pairs sharing both counted once)."""
    per_agent = np.bincount(np.concatenate([log.a, log.b]), minlength=log.n_agents).astype(np.int64)
    pair = log.a * log.n_agents + log.b
    _, per_pair = np.unique(pair, return_counts=True)
    return int((per_agent * (per_agent - 1) // 2).sum() - (per_pair * (per_pair - 1) // 2).sum())


def large_scale(n_events):
    start = time.perf_counter()
    log = simulated_log(n_events)
    print(f"\n## build_graph at {log.n_events:,} events ({log.n_agents} agents, {log.duration:.0f} s, "
          f"{len(log.static_agent)} static; log ready in {time.perf_counter() - start:.1f} s); "
          f"literal graph: {literal_edge_count(log):,} edges\n")
    print("| metric | nodes | edges | median build s | tracemalloc peak MB | RSS peak above baseline MB |")
    print("|---|---|---|---|---|---|")
    for metric in METRICS:
        seconds, graph = median_seconds(lambda: build_graph(log, metric))
        del graph
        traced = traced_peak(lambda: build_graph(log, metric))
        graph, _, rss, _ = run_measured(lambda: build_graph(log, metric))
        print(f"| {metric} | {graph.n_nodes:,} | {graph.adjacency.nnz // 2:,} | {seconds:.2f} | "
              f"{traced / 2**20:.0f} | {rss / 2**20:.0f} |", flush=True)
        del graph


def chain_all_pairs(log, metric):
    graph = build_graph(log, metric)
    nodes = graph.distances_from(np.arange(graph.n_nodes))
    return nodes[np.ix_(graph.node_of_event, graph.node_of_event)]


def against_literal(sizes):
    print(f"\n## all-pairs event distances: sparse chain graph vs literal definition (median of {REPEATS})\n")
    print("| events | agents | metric | literal s | sparse s | ratio | equal |")
    print("|---|---|---|---|---|---|---|")
    for n_events in sizes:
        log = simulated_log(n_events)
        for metric in METRICS:
            literal_s, literal = median_seconds(lambda: literal_distances(log, metric))
            sparse_s, sparse = median_seconds(lambda: chain_all_pairs(log, metric))
            np.testing.assert_allclose(sparse, literal, rtol=1e-12, atol=1e-9)
            del literal, sparse
            print(f"| {log.n_events:,} | {log.n_agents} | {metric} | {literal_s:.2f} | {sparse_s:.3f} | "
                  f"{literal_s / sparse_s:.0f}x | yes |", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="10^5 events; N = 1,000 and 2,000")
    args = parser.parse_args()
    print(f"machine: {machine()}; swarmtopo {revision()}")
    for metric in METRICS:  # load the numba kernels (compiled or cached) before timing
        build_graph(simulated_log(1000), metric)
    large_scale(10**5 if args.quick else 10**6)
    against_literal((1000, 2000) if args.quick else (1000, 2000, 4000))
    print(f"\nload average after: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
