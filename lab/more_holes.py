"""Arenas with more holes than the benchmark's three: how the default pipeline maps 4
and 5 holes of mixed shapes.

    python lab/more_holes.py --per-cell 5 --workers 2

For each of 4 and 5 holes and 400 and 600 agents x 60 s, PER_CELL random arenas (a
square, rectangular or polygonal outer wall, a scale in [0.75, 1.25], every hole
drawing its family from the four tuning families; seeds of their own, not the accuracy
benchmark's), simulated and mapped with the default pipeline from the log folder
stripped of ground truth.  Prints per cell the exact maps, the counts found and the
mean beta_1 confidence.  A measurement outside the frozen suite: no default is chosen
on it.
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from swarmtopo.arena import HOLE_SHAPES, OUTER_SHAPES, random_arena
from swarmtopo.experiments.accuracy import HELD_OUT_FAMILY, PIPELINES, SCALE_RANGE
from swarmtopo.experiments.sweep import cached_classifier, job_map_config, stripped_log
from swarmtopo.pipeline import map_encounters
from swarmtopo.sim import simulate

CELLS = [(holes, agents, 60.0) for holes in (4, 5) for agents in (400, 600)]


def one(args) -> tuple[tuple, int, float]:
    (holes, agents, duration), index = args
    rng = np.random.default_rng([holes, agents, index])
    families = tuple(s for s in HOLE_SHAPES if s != HELD_OUT_FAMILY)
    arena = random_arena(holes, scale=float(rng.uniform(*SCALE_RANGE)), shapes=families,
                         outer=OUTER_SHAPES[int(rng.integers(len(OUTER_SHAPES)))], rng=rng)
    log = stripped_log(simulate(arena, agents, duration, rng=rng).log)
    tmap = map_encounters(log, job_map_config(PIPELINES["default"], index), reader=cached_classifier("default", None))
    return (holes, agents, duration), tmap.betti[1] if tmap.betti[0] == arena.betti[0] else -1, tmap.confidence[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-cell", type=int, default=5)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(pool.map(one, [(cell, i) for cell in CELLS for i in range(args.per_cell)]))
    print("| holes | agents x s | exact | beta_1 found (-1: wrong beta_0) | mean beta_1 confidence |\n|---|---|---|---|---|")
    for cell in CELLS:
        mine = [r for r in rows if r[0] == cell]
        print(f"| {cell[0]} | {cell[1]} x {cell[2]:g} | {sum(r[1] == cell[0] for r in mine)}/{len(mine)} | "
              f"{', '.join(str(r[1]) for r in mine)} | {np.mean([r[2] for r in mine]):.2f} |")


if __name__ == "__main__":
    main()
