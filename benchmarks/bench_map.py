"""One map, end to end: the default pipeline from 10^5 to 10^7 events, on threads and on Dask.

Every ratio is against a baseline measured in the same run, on the same input:

Part 1, the exact part (one window of the 10^6-event simulated log, 400 maxmin
landmarks): the landmark-to-landmark distances by the previous route (one heap search
per landmark, parallel over landmarks) and by the bucket-queue searches; same
distances asserted bit for bit; medians of 5.

Part 2, the whole map (``map_encounters(log)``, every option at its default) on
simulated two-hole logs (``_data.simulated_log``: the paper's density, 10 % static) of
10^5 and 10^6 events, and on a random-pair log of 10^6 events (2,000 agents, 1,000 s,
no spatial structure: the worst case):

- ``previous route``: the windows one after the other in this process, each kernel
  parallel over landmarks with heap searches -- the route before the window tasks;
- ``threads``: the default engine, window tasks on one thread per core;
- ``1 thread``: the same on one thread (numba.set_num_threads(1));
- ``dask 2 workers``: an embedded Dask LocalCluster of 2 processes (``--workers 2``),
  cluster start-up included.

Each map's map.json (timings aside) is asserted identical to the previous route's.
Wall and CPU seconds of this process (Dask workers' CPU is not in it) and peak memory:
this process's peak RSS above its RSS before the call (``_measure.run_measured``; the
log itself not counted, Dask workers not counted).  Targets (issue 41, 2 cores): the
simulated 10^6-event log < 15 s (must: < 30 s) and < 1 GB; the random-pair one < 60 s.

Part 3 (``--huge``): growth from 10^5 to 10^7 events (10^7: 20,000 agents), the default
engine only, as a table and a log-log plot (``--plot``, default
``docs/figures/map_scaling.png``); target: 10^7 events under 12 GB.  Simulating the
10^7-event log takes several minutes the first time (cached after).

    python benchmarks/bench_map.py [--quick] [--huge] [--plot PATH]

``--quick``: part 2 at 10^5 events only.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from contextlib import contextmanager
from functools import partial
from pathlib import Path

import numba
import numpy as np

from _data import random_pair_log, simulated_log
from _measure import machine, revision, run_measured
from swarmtopo.metric import _kernels
from swarmtopo.metric.graph import weighted_chains
from swarmtopo.metric.landmarks import _GraphArrays, maxmin
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.pipeline import map as pipeline_map
from swarmtopo.pipeline.settings import resolve
from swarmtopo.readers.registry import load_classifier, shipped_reader_for
from swarmtopo.viz.summary import map_json

TIME_TARGET, TIME_MUST, MEMORY_TARGET = 15.0, 30.0, 2**30
RANDOM_PAIR_TARGET = 60.0
HUGE_MEMORY_TARGET = 12 * 2**30
HUGE_AGENTS = 20_000
DEFAULT_PLOT = Path(__file__).resolve().parent.parent / "docs" / "figures" / "map_scaling.png"


class InlineEngine:
    """The previous route: each task run at once in the calling thread, whose kernels
    keep all of numba's threads (parallel over landmarks)."""

    def share(self, value):
        return value

    def submit(self, function, *args):
        return function(*args)

    def gather(self, futures):
        return list(futures)


@contextmanager
def previous_route():
    """Windows one after the other, kernels parallel over landmarks, heap searches."""
    engine_for, layout = pipeline_map.engine_for, _kernels.bucket_layout

    @contextmanager
    def inline(workers=None, scheduler=None):
        yield InlineEngine()

    pipeline_map.engine_for = inline
    _kernels.bucket_layout = lambda weights: (0.0, 0)
    try:
        yield
    finally:
        pipeline_map.engine_for, _kernels.bucket_layout = engine_for, layout


@contextmanager
def numba_threads(n: int):
    before = numba.get_num_threads()
    numba.set_num_threads(n)
    try:
        yield
    finally:
        numba.set_num_threads(before)


def doc_of(tmap) -> str:
    doc = map_json(tmap)
    doc.pop("timings")
    return json.dumps(doc, sort_keys=True, default=str)


def exact_part(repeats: int = 5) -> None:
    """Part 1: landmark-to-landmark rows, heap searches vs bucket-queue searches."""
    log = simulated_log(10**6)
    config = MapConfig().validate()
    settings = resolve(log, config, load_classifier(shipped_reader_for(log)))
    chains = weighted_chains(log, config.metric, hop_cost=settings.hop_cost[0],
                             diffusion_time=settings.diffusion_time[0], wall_follow_weight=config.wall_follow_weight)
    graph = chains.graph(settings.spans[len(settings.spans) // 2])
    labels = graph.components()[1]
    graph = graph.subgraph(np.flatnonzero(labels == np.argmax(np.bincount(labels))))
    arrays = _GraphArrays.of(graph)
    nodes = maxmin(graph, 400, rng=0).nodes
    args = (arrays.indptr, arrays.indices, arrays.weights, nodes, nodes)
    heap = _kernels.rows_to_targets(*args, buckets=False)
    buckets = _kernels.rows_to_targets(*args)
    assert np.array_equal(heap, buckets), "bucket searches changed a distance"
    times = {}
    for name, flag in (("heap (previous)", False), ("buckets", True)):
        runs = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            _kernels.rows_to_targets(*args, buckets=flag)
            runs.append(time.perf_counter() - t0)
        times[name] = statistics.median(runs)
    width, n_buckets = _kernels.bucket_layout(arrays.weights)
    print(f"\n## Part 1: landmark-to-landmark distances on one window ({graph.n_nodes:,} nodes, "
          f"{len(arrays.weights):,} arcs, 400 landmarks, {n_buckets} buckets of {width:.3g} s), "
          f"{numba.get_num_threads()} numba threads, median of {repeats}\n")
    print("| searches | ms | speed-up |\n|---|---|---|")
    for name, seconds in times.items():
        print(f"| {name} | {1e3 * seconds:.0f} | {times['heap (previous)'] / seconds:.2f}x |")
    print("\nsame distances, bit for bit: yes")


def measured_map(log, route: str):
    if route == "previous route":
        with previous_route():
            return run_measured(lambda: map_encounters(log))
    if route == "1 thread":
        with numba_threads(1):
            return run_measured(lambda: map_encounters(log))
    if route == "dask 2 workers":
        return run_measured(lambda: map_encounters(log, workers=2))
    return run_measured(lambda: map_encounters(log))


ROUTES = ("previous route", "threads", "1 thread", "dask 2 workers")


def whole_maps(cases) -> None:
    """Part 2: the default map by each route, ratios against the previous route."""
    print("\n## Part 2: the default map, every route on the same log\n")
    print("| log | events | agents | windows x bands | route | wall s | speed-up | CPU s (this process) | "
          "peak MB above baseline | beta_0, beta_1 | same map.json |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name, log, target in cases:
        base_wall, base_doc = None, None
        for route in ROUTES:
            tmap, wall, peak, cpu = measured_map(log, route)
            doc = doc_of(tmap)
            base_wall, base_doc = (wall, doc) if base_wall is None else (base_wall, base_doc)
            windows = sum(len(r.windows) for r in tmap.regions)
            print(f"| {name} | {tmap.n_events:,} | {log.n_agents:,} | {windows} | {route} | {wall:.1f} | "
                  f"{base_wall / wall:.2f}x | {cpu:.1f} | {peak / 2**20:.0f} | {tmap.betti[0]}, {tmap.betti[1]} | "
                  f"{'yes' if doc == base_doc else 'NO'} |", flush=True)
            del tmap
        if target:
            print(f"\n{name}: target {target}\n")


def growth(plot: Path) -> None:
    """Part 3: the default engine from 10^5 to 10^7 events; table and log-log plot."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sizes = [(10**5, None), (10**6, None), (10**7, HUGE_AGENTS)]
    rows = []
    print("\n## Part 3: growth, the default engine\n")
    print("| events | agents | windows x bands | graph s | wall s | peak MB above baseline | beta_0, beta_1 |")
    print("|---|---|---|---|---|---|---|")
    for n_events, agents in sizes:
        log = simulated_log(n_events, agents=agents)
        tmap, wall, peak, _ = run_measured(partial(map_encounters, log))
        windows = sum(len(r.windows) for r in tmap.regions)
        rows.append((tmap.n_events, wall, peak))
        print(f"| {tmap.n_events:,} | {log.n_agents:,} | {windows} | {tmap.timings['graph']:.1f} | {wall:.1f} | "
              f"{peak / 2**20:.0f} | {tmap.betti[0]}, {tmap.betti[1]} |", flush=True)
        del tmap, log
    events, walls, peaks = (np.array(column, float) for column in zip(*rows))
    slope_time = np.polyfit(np.log10(events), np.log10(walls), 1)[0]
    slope_memory = np.polyfit(np.log10(events), np.log10(peaks), 1)[0]
    print(f"\nlog-log slopes from 10^5 to 10^7: time {slope_time:.2f}, peak memory {slope_memory:.2f}; "
          f"10^7 events: {'under' if peaks[-1] < HUGE_MEMORY_TARGET else 'OVER'} 12 GB")
    fig, ax = plt.subplots(figsize=(5, 3.6))
    ax.loglog(events, walls, "o-", label="wall time, s")
    ax.loglog(events, peaks / 2**20, "s-", label="peak memory, MB")
    ax.set_xlabel("encounter events")
    ax.set_title("swarmtopo map, default pipeline, 2 cores", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    plot.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(plot, dpi=120)
    print(f"plot: {plot}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="part 2 at 10^5 events only")
    parser.add_argument("--huge", action="store_true", help="also part 3: growth up to 10^7 events")
    parser.add_argument("--plot", type=Path, default=DEFAULT_PLOT, help="where part 3 writes its log-log plot")
    args = parser.parse_args()
    print(f"machine: {machine()}; {numba.get_num_threads()} numba threads; swarmtopo {revision()}")
    map_encounters(simulated_log(10**4))  # load every numba kernel: no timed run pays for it
    exact_part()
    cases = [("simulated", simulated_log(10**5), None)]
    if not args.quick:
        cases += [("simulated", simulated_log(10**6),
                   f"< {TIME_TARGET:.0f} s (must: < {TIME_MUST:.0f} s) and < 1 GB on the default engine (threads)"),
                  ("random pairs", random_pair_log(10**6), f"< {RANDOM_PAIR_TARGET:.0f} s on the default engine")]
    whole_maps(cases)
    if args.huge:
        growth(args.plot)
    print(f"\nload average after: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
