"""The re-contact share rho (swarmtopo.pipeline.motion) of cockroach logs and the regime
the map reads: no cockroach log may read as flickering, so that every one maps
exactly as before the regime existed.

    python lab/motion_regimes.py --per-cell 20 --small 10 --workers 2

Simulates (no map) the first PER_CELL tuning and reporting cases of every cell of the
accuracy benchmark, and SMALL seeds each of small swarms and long logs (20, 40, 60 and
100 agents for 120 to 600 s in random arenas with 0-2 holes: few agents meet the same
ones again and again, whatever their motion), and prints per group the least, median
and largest rho and how many logs read as flickering.
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from swarmtopo.arena import random_arena
from swarmtopo.experiments.accuracy import CELLS, built_case, tuning_session
from swarmtopo.experiments.grid import job_simulation_args
from swarmtopo.pipeline.motion import FLICKER_SHARE, MIN_AGENTS, estimate_motion
from swarmtopo.sim import simulate

SMALL = [(20, 120.0), (20, 600.0), (40, 120.0), (40, 600.0), (60, 240.0), (100, 300.0), (100, 600.0)]


def suite_case(args) -> tuple[str, float, float]:
    cell_name, split, index = args
    cell = next(c for c in CELLS if c.name == cell_name)
    if split == "tuning":
        with tuning_session():
            _, _, arena, stream = built_case(cell, split, index)
    else:
        _, _, arena, stream = built_case(cell, split, index)
    swarm = {"agents": cell.agents, "duration": cell.duration, "static_fraction": 0.0}
    estimate = estimate_motion(simulate(arena, **job_simulation_args(swarm), rng=stream).log)[0]
    return cell_name, estimate.recontact_share, estimate.regime


def small_swarm(args) -> tuple[str, float, float]:
    n, duration, seed = args
    arena = random_arena(seed % 3, rng=np.random.SeedSequence([n, int(duration), seed]))
    estimate = estimate_motion(simulate(arena, n, duration, rng=seed).log)[0]
    return f"{n} agents x {duration:g} s", estimate.recontact_share, estimate.regime


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-cell", type=int, default=20)
    parser.add_argument("--small", type=int, default=10, help="seeds per small-swarm group")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    suite = [(c.name, split, i) for c in CELLS for split in ("tuning", "reporting") for i in range(args.per_cell)]
    small = [(n, t, seed) for n, t in SMALL for seed in range(args.small)]
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(pool.map(suite_case, suite, chunksize=4)) + list(pool.map(small_swarm, small))
    print(f"FLICKER_SHARE = {FLICKER_SHARE}, MIN_AGENTS = {MIN_AGENTS}")
    print("| group | logs | rho min / median / max | read as | flickering |")
    print("|---|---|---|---|---|")
    groups = list(dict.fromkeys(r[0] for r in rows))
    for name in groups + ["all"]:
        rho = np.array([r[1] for r in rows if name in (r[0], "all")])
        regimes = sorted({r[2] for r in rows if name in (r[0], "all")})
        print(f"| {name} | {len(rho)} | {rho.min():.3f} / {np.median(rho):.3f} / {rho.max():.3f} | "
              f"{', '.join(regimes)} | {sum(r[2] == 'flickering' for r in rows if name in (r[0], 'all'))} |")

if __name__ == "__main__":
    main()
