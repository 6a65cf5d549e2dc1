"""Where beacon-led exploration stops working (docs/exploration.md, "Limits").

The demo's hall (2.4 m x 0.6 m, a 140 mm square and a 140 mm disc on its middle line)
explored behind a leader, with the leader's speed and the leash varied one at a time
from the demo's (2 mm/s, R = 300 mm, 300 agents); a shorter leash keeps the demo's
density (N = 300 (R / 300 mm)^2 agents).  ``--seeds`` runs each.  Prints per setting:
the global beta_1 found (truth 2), the position errors, the warnings.

    python lab/exploration_limits.py --seeds 2 --workers 2
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from swarmtopo.arena import hall_demo_arena
from swarmtopo.beacon import long_axis_track
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.sim import simulate

TRUE_X = (700.0, 1700.0)
SETTINGS = [(2.0, 300.0), (4.0, 300.0), (8.0, 300.0), (2.0, 150.0), (2.0, 100.0)]
"""(leader speed mm/s, leash R mm): the demo's, faster leaders, shorter leashes (100 mm: shorter
than the 140 mm holes are wide)."""


def run(setting_seed):
    (speed, leash), seed = setting_seed
    arena = hall_demo_arena()
    track = long_axis_track(arena.bounds, leash, speed)
    agents = max(2, round(300 * (leash / 300.0) ** 2))
    sim = simulate(arena, agents, float(np.ceil(track.t[-1] + 20.0)), rng=seed, beacon=track, leash=leash)
    tmap = map_encounters(sim.log, MapConfig(embed_dim=0, cycles=False))
    found = tmap.exploration
    errors = [min(float(np.hypot(h.x - x, h.y - 300.0)) for x in TRUE_X) for h in found.holes]
    return speed, leash, agents, seed, tmap.betti[1], errors, tmap.log_warnings


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=2)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    todo = [(setting, seed) for setting in SETTINGS for seed in range(args.seeds)]
    with ProcessPoolExecutor(args.workers) as pool:
        results = list(pool.map(run, todo))
    print("| leader speed | leash R | agents | seed | beta_1 (truth 2) | position errors | warnings |")
    print("|---|---|---|---|---|---|---|")
    for speed, leash, agents, seed, count, errors, warnings in results:
        shown = ", ".join(f"{e:.0f}" for e in errors) or "-"
        print(f"| {speed:g} mm/s | {leash:g} mm | {agents} | {seed} | {count} | {shown} mm | "
              f"{'; '.join(warnings) or '-'} |")


if __name__ == "__main__":
    main()
