"""The whole map (issue 3's figure): 10^6 simulated events, 500 landmarks, H0 + H1.

Part 1 (10^6 events, ``--quick``: 10^5): ``swarmtopo.pipeline.map.map_encounters`` on a
simulated two-hole log (``_data.simulated_log``: 2,000 agents at the paper's density,
10 % static) with ``MapConfig(metric, subsample, landmarks=500, maxdim=1,
embed_dim=0)`` for the three subsamplers, on the plain and the hybrid metric (the
pipeline's default); every other option is the default, so the windows mapped are at
most ``MapConfig.max_windows`` (``--max-windows none``: every window).  One run each, after a warm-up that loads the numba kernels.
Wall time split as ``TopologicalMap.timings`` reports it (graph incl. components /
landmarks incl. the Betti rule's k-NN scale / persistence; "other" is the rest:
region bookkeeping, Betti rule), total
wall and CPU time, and peak memory: the process's peak RSS above its RSS before the
call (``_measure.run_measured``), the log itself not counted.  Targets: maxmin < 60 s
and < 4 GB; knn and probabilistic < 120 s (and < 4 GB).

Part 2 (10^4 events): the pipeline's landmark stage against the dense approach on
the same graph (the hybrid graph's largest component, as the pipeline maps it):
``landmarks.maxmin`` (bounded searches + L x L) vs ``bench_landmarks.dense_maxmin``
(scipy all-pairs ``shortest_path``, then maxmin on the full matrix) from the same
start, medians of 3, same landmarks and distances asserted.  The graph and the
persistence stages are the same for both, so they are left out.  Targets: >= 20x
faster, >= 50x less memory (peak RSS above the level before the call).

    python benchmarks/bench_map.py [--quick] [--subsample maxmin ...] [--max-windows 48|none]

``--subsample`` times only the named subsamplers in part 1 (each row costs minutes at
10^6 events).
"""

from __future__ import annotations

import argparse
import os

import numba
import numpy as np

from _data import simulated_log
from _measure import machine, revision, run_measured
from bench_landmarks import compare_with_dense
from swarmtopo.metric.graph import build_graph
from swarmtopo.metric.landmarks import SUBSAMPLERS
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.pipeline.config import config_from_options

N_LANDMARKS = 500
METRICS = ("plain", "hybrid")
TIME_LIMIT = {"maxmin": 60.0, "knn": 120.0, "probabilistic": 120.0}
MEMORY_LIMIT = 4 * 2**30


def config(metric, subsample, max_windows=MapConfig.max_windows) -> MapConfig:
    return MapConfig(metric=metric, subsample=subsample, landmarks=N_LANDMARKS, maxdim=1, embed_dim=0, seed=0,
                     max_windows=max_windows)


def warm_up():
    """Load every numba kernel (compiled or cached) so that no timed run pays for it."""
    log = simulated_log(10**4)
    for metric in METRICS:
        for subsample in SUBSAMPLERS:
            map_encounters(log, config(metric, subsample))


def whole_map(n_events, subsamplers=SUBSAMPLERS, max_windows=MapConfig.max_windows):
    log = simulated_log(n_events)
    print(f"\n## map_encounters at {log.n_events:,} events ({log.n_agents} agents, {log.duration:.0f} s, "
          f"{len(log.static_agent)} static, 2 holes), L = {N_LANDMARKS}, H0 + H1, one run each\n")
    print("| metric | subsample | windows | graph s | landmarks s | persistence s | other s | total s | CPU s | "
          "peak MB above baseline | beta_0, beta_1 | target | met |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for metric in METRICS:
        for subsample in subsamplers:
            result, wall, peak, cpu = run_measured(lambda: map_encounters(log, config(metric, subsample, max_windows)))
            stage = result.timings
            other = wall - stage["graph"] - stage["landmarks"] - stage["persistence"]
            limit = TIME_LIMIT[subsample]
            met = wall < limit and peak < MEMORY_LIMIT
            bands = result.config.landmark_bands
            spans = sum(len(r.windows) for r in result.regions) // len(bands)  # each span mapped once per band
            windows = f"{spans} of {spans + result.windows_left_out}" + (f" x {len(bands)} bands" if len(bands) > 1 else "")
            print(f"| {metric} | {subsample} | {windows} | {stage['graph']:.2f} | {stage['landmarks']:.2f} | "
                  f"{stage['persistence']:.2f} | {other:.2f} | {wall:.1f} | {cpu:.1f} | {peak / 2**20:.0f} | "
                  f"{result.betti[0]}, {result.betti[1]} | < {limit:.0f} s, < 4 GB | {'yes' if met else 'NO'} |",
                  flush=True)
            del result


def largest_component(graph):
    _, labels = graph.components()
    largest = np.argmax(np.bincount(labels, weights=graph.multiplicity))
    return graph.subgraph(np.flatnonzero(labels == largest))


def against_dense(n_events, repeats=3):
    log = simulated_log(n_events)
    graph = largest_component(build_graph(log, "hybrid"))
    compare_with_dense(graph, f"landmark stage vs dense at {log.n_events:,} simulated events (hybrid graph, "
                              f"largest component: {graph.n_nodes:,} nodes)", repeats)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="10^5 events instead of 10^6")
    parser.add_argument("--subsample", nargs="+", choices=SUBSAMPLERS, default=list(SUBSAMPLERS),
                        help="subsamplers to time in part 1 (default: all)")
    parser.add_argument("--max-windows", default=str(MapConfig.max_windows),
                        help=f"cap of the windows mapped in part 1 (default {MapConfig.max_windows}, the pipeline's; "
                             "'none': every window)")
    args = parser.parse_args()
    max_windows = config_from_options({"max_windows": args.max_windows}).max_windows
    print(f"machine: {machine()}; {numba.get_num_threads()} numba threads; swarmtopo {revision()}")
    warm_up()
    whole_map(10**5 if args.quick else 10**6, args.subsample, max_windows)
    against_dense(10**4)
    print(f"\nload average after: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
