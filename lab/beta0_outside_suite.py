"""beta_0's confidence on arenas the benchmark does not hold (docs/accuracy.md, "beta_0").

Two cases a review of the model found: a small second room beside a large one, whose
few agents' encounters are a small share of the log (beta_0 = 1 is then wrong, and
``fragments`` is too small to lower the confidence); and two rooms of a sparse swarm,
whose groups form slowly (beta_0 = 2 is right, and ``settled`` is small).  Prints each
simulated log's count, evidence and confidence beside the truth.

Usage::

    python lab/beta0_outside_suite.py [--seeds 4]
"""

from __future__ import annotations

import argparse

import shapely
from shapely.geometry import MultiPolygon

from swarmtopo.arena import Arena, two_rooms_arena
from swarmtopo.readers.beta0 import shipped_beta0_model
from swarmtopo.pipeline import MapConfig
from swarmtopo.pipeline.regions import split_regions
from swarmtopo.sim import simulate

CASES = {
    "small second room (500 x 500 and 100 x 100 mm), 300 agents, 20 s":
        (Arena(MultiPolygon([shapely.box(0, 0, 500, 500), shapely.box(600, 0, 700, 100)])), 300, 20.0),
    "two rooms (500 x 500 mm each), 100 agents, 40 s": (two_rooms_arena(), 100, 40.0),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=4)
    args = parser.parse_args()
    model = shipped_beta0_model()
    for name, (arena, agents, duration) in CASES.items():
        rows = []
        for seed in range(args.seeds):
            evidence = split_regions(simulate(arena, agents, duration, rng=seed).log, MapConfig()).beta0
            rows.append(f"beta_0 {evidence.regions} at {model.confidence(evidence):.4f} (settled "
                        f"{evidence.settled:.2f}, fragments {evidence.fragments:.3f})")
        print(f"{name}, true beta_0 = {arena.betti[0]}:\n  " + "\n  ".join(rows))


if __name__ == "__main__":
    main()
