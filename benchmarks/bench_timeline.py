"""What the map's timeline costs: the map with it against the same map without it.

The baseline, measured in the same run, is the same map with ``timeline_length = inf``
(no timeline).  Logs: the cached simulated logs of ``bench_map.py`` (10^5 events,
``--large`` adds 10^6), a static 300-agent x 150 s log, and logs of 300 agents x 150 s
where a hole appears and where a door closes at 70 s (a door splits the map's one
region in every later window: those windows are mapped again).  Medians of
``--repeats`` runs, interleaved; the maps are asserted equal apart from the timeline.

    python benchmarks/bench_timeline.py [--large] [--repeats 3]
"""

from __future__ import annotations

import argparse
import statistics

from _data import simulated_log
from _measure import machine, revision, run_measured
from swarmtopo.changing import changing_arena
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.sim import simulate
from swarmtopo.viz.summary import map_json


def logs(large: bool):
    yield "simulated 10^5 events", simulated_log(100_000)
    if large:
        yield "simulated 10^6 events", simulated_log(1_000_000)
    for kind in ("none", "appear", "door"):
        arena = changing_arena(kind, 1, 70.0, rng=5)
        yield f"{'static' if kind == 'none' else kind}, 300 x 150 s", simulate(arena, 300, 150.0, rng=5).log


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--large", action="store_true")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    print(f"# bench_timeline ({revision()}; {machine()})\n")
    print("| log | events | timeline windows | split windows mapped again | without s | with s | ratio | "
          "changes found |")
    print("|---|---|---|---|---|---|---|---|")
    with_cfg, without_cfg = MapConfig(embed_dim=0, cycles=False), MapConfig(embed_dim=0, cycles=False,
                                                                             timeline_length=float("inf"))
    for name, log in logs(args.large):
        times = {"with": [], "without": []}
        for _ in range(args.repeats):
            without, seconds, _, _ = run_measured(lambda: map_encounters(log, without_cfg))
            times["without"].append(seconds)
            with_, seconds, _, _ = run_measured(lambda: map_encounters(log, with_cfg))
            times["with"].append(seconds)
        a, b = map_json(with_), map_json(without)
        assert all(a[k] == b[k] for k in ("betti", "confidence", "diagrams", "regions")), name
        windows = with_.timeline.windows
        split = sum(w.betti[0] > len([r for r in with_.regions]) for w in windows)
        t_with, t_without = statistics.median(times["with"]), statistics.median(times["without"])
        print(f"| {name} | {log.n_events:,} | {len(windows)} | {split} | {t_without:.1f} | {t_with:.1f} | "
              f"{t_with / t_without:.2f}x | {with_.timeline.summary()} |", flush=True)


if __name__ == "__main__":
    main()
