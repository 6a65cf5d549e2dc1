"""The fault screen's cost beside the graph it protects.

On simulated two-hole logs (``_data.simulated_log``: 10^4, 10^5 and 10^6 events,
``--quick``: 10^4 and 10^5), clean and with 3 % false encounters: the median wall time
of 3 runs of ``screen_faults`` (a bounded detour search from every event) and of the
weighted chain graph the map builds (``weighted_chains(...).graph()``, the map's
"graph" stage), and their ratio, measured in the same run.

    python benchmarks/bench_fault_screen.py [--quick]
"""

from __future__ import annotations

import argparse
import statistics
import time

from _data import simulated_log
from _measure import machine, revision
from swarmtopo.metric.graph import weighted_chains
from swarmtopo.pipeline.faults import screen_faults
from swarmtopo.sim.faults import Faults, perturb

REPEATS = 3


def median_seconds(run) -> float:
    times = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    sizes = (10_000, 100_000) if args.quick else (10_000, 100_000, 1_000_000)
    print(f"{machine()}; {revision()}")
    print("| events | log | screen (s) | graph (s) | screen / graph | dropped |\n|---|---|---|---|---|---|")
    for n in sizes:
        clean = simulated_log(n, static_fraction=0.0)
        for name, log in (("clean", clean), ("3 % false", perturb(clean, Faults(false_encounters=0.03), 1)[0])):
            screen_faults(log)  # compile
            screen = median_seconds(lambda: screen_faults(log))
            graph = median_seconds(lambda: weighted_chains(log, "hybrid", hop_cost=2.0, diffusion_time=1.0).graph())
            dropped = screen_faults(log)[0].dropped
            print(f"| {log.n_events:,} | {name} | {screen:.3f} | {graph:.3f} | {screen / graph:.1f} | {dropped:,} |",
                  flush=True)


if __name__ == "__main__":
    main()
