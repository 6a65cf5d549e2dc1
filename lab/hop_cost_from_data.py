"""The per-hop cost a real trace gets: h from the data against r_d / v_c.

For a trace without r_d and v_c in meta.json, ``swarmtopo map`` sets
h = HOP_GAP_FACTOR x the mean time between an agent's consecutive encounters.  This
script simulates the accuracy suite's three budgets (random arenas with 0-3 holes of
every family, scale 0.75-1.25; seeds 0..N-1 of its own, not the benchmark's) and
prints that data-derived h beside r_d / v_c = 2 s, with their ratio (median and range).

    python lab/hop_cost_from_data.py [--seeds 10]
"""

import argparse

import numpy as np

from swarmtopo.arena import HOLE_SHAPES, OUTER_SHAPES, random_arena
from swarmtopo.experiments.accuracy import BUDGETS, SCALE_RANGE
from swarmtopo.log import EncounterLog
from swarmtopo.pipeline.settings import hop_cost
from swarmtopo.sim import simulate


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10)
    args = parser.parse_args()
    print("| agents x seconds | r_d / v_c (s) | h from data (s): median [min, max] | ratio |")
    print("|---|---|---|---|")
    for agents, duration in BUDGETS:
        reference, from_data = [], []
        for seed in range(args.seeds):
            rng = np.random.default_rng([agents, seed])
            arena = random_arena(int(rng.integers(0, 4)), scale=rng.uniform(*SCALE_RANGE), shapes=HOLE_SHAPES,
                                 outer=OUTER_SHAPES[int(rng.integers(3))], rng=rng)
            log = simulate(arena, agents, duration, rng=rng).log
            reference.append(hop_cost(log, None)[0])
            bare = EncounterLog.from_records(log.t, log.a, log.b)  # a trace: no meta.json
            from_data.append(hop_cost(bare, None)[0])
        h = np.array(from_data)
        ratio = np.median(h / np.array(reference))
        print(f"| {agents} x {duration:g} | {np.median(reference):.2f} | {np.median(h):.2f} [{h.min():.2f}, {h.max():.2f}] "
              f"| {ratio:.2f} |")


if __name__ == "__main__":
    main()
