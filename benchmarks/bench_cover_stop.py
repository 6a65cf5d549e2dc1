"""The automatic landmark count: greedy picks stopped when they cover, against picking
``max_landmarks`` and cutting the run afterwards (the pipeline before 41a1a1e).

``map_encounters`` with every default (automatic landmarks: the first picks whose
covering radius is at most 1.5 k-NN scales, at most ``MapConfig.max_landmarks``;
windows at two landmark bands) on simulated two-hole logs (``_data.simulated_log``), in
two ways in the same process: as shipped (``landmarks.maxmin(..., cover=c)``), and
with the baseline patched in (``max_landmarks`` picks, their L x L distances, then the
prefix the cover keeps).  The maps must be equal (Betti numbers, every window's
landmarks and diagram; asserted); the script prints the median wall time of each over
``--repeats`` runs (alternating, after a warm-up) and their ratio.

    python benchmarks/bench_cover_stop.py [--events 10000 100000] [--repeats 3]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from _data import simulated_log
from _measure import machine, revision
from swarmtopo.pipeline import tasks as pipeline
from swarmtopo.metric.landmarks import covering_prefix
from swarmtopo.pipeline import MapConfig, map_encounters

SHIPPED = pipeline.subsample


def cut_after(graph, config, n_landmarks, start, candidates=None, cover=None):
    """The baseline: every pick up to ``n_landmarks``, then the prefix ``cover`` keeps."""
    land = SHIPPED(graph, config, n_landmarks, start, candidates)
    return land if cover is None else covering_prefix(land, cover)


def timed_map(log, baseline: bool):
    pipeline.subsample = cut_after if baseline else SHIPPED
    try:
        start = time.perf_counter()
        tmap = map_encounters(log, MapConfig(embed_dim=0, cycles=False))
        return tmap, time.perf_counter() - start
    finally:
        pipeline.subsample = SHIPPED


def fingerprint(tmap):
    return (tmap.betti, [(w.landmarks.nodes.tolist(), w.landmarks.distances.tobytes(),
                          [p.tobytes() for p in w.diagram.pairs]) for r in tmap.regions for w in r.windows])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--events", type=int, nargs="+", default=[10**4, 10**5])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    print(machine(), revision())
    print("| events | agents | windows | landmarks per window (median) | stopped when covered s | "
          "picked all, then cut s | ratio | maps equal |")
    print("|---|---|---|---|---|---|---|---|")
    timed_map(simulated_log(10**4, seed=1), baseline=False)  # numba kernels loaded before any timing
    for n_events in args.events:
        log = simulated_log(n_events, seed=1)
        times = {False: [], True: []}
        maps = {}
        for _ in range(args.repeats):
            for baseline in (False, True):
                maps[baseline], seconds = timed_map(log, baseline)
                times[baseline].append(seconds)
        equal = fingerprint(maps[False]) == fingerprint(maps[True])
        assert equal, "the stopped run must give the same maps as the cut one"
        windows = [w for r in maps[False].regions for w in r.windows]
        shipped, base = statistics.median(times[False]), statistics.median(times[True])
        print(f"| {log.n_events:,} | {log.n_agents} | {len(windows)} | "
              f"{int(np.median([len(w.landmarks.nodes) for w in windows]))} | {shipped:.2f} | {base:.2f} | "
              f"{base / shipped:.2f}x | {equal} |")


if __name__ == "__main__":
    main()
