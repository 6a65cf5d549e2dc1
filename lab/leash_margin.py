"""How far agents stray beyond the leash, and where the swarm sits round a moving leader
(docs/exploration.md, "The leash model" and "Where each hole is").

Three halls swept once by a leader at 2 mm/s (positions sampled every second): the
margins beyond R (99th, 99.9th percentile, farthest) and, while the leader moves, the
agents' position along the hall relative to the leader (mean, and the 95th percentile:
how far ahead the swarm reaches).

    python lab/leash_margin.py
"""

from __future__ import annotations

import numpy as np

from swarmtopo.arena import hall_arena, hall_demo_arena
from swarmtopo.beacon import LEADER_SETTLE, long_axis_track
from swarmtopo.sim import simulate

HALLS = [("1.5 m x 0.6 m, no hole", hall_arena(0, length=1500.0, width=600.0), 150, 250.0),
         ("1.5 m x 0.6 m, two holes", hall_arena(2, length=1500.0, width=600.0, rng=3), 150, 250.0),
         ("the demo's hall, two holes", hall_demo_arena(), 300, 300.0)]
"""(name, arena, agents, leash R): the first two are tests/test_exploration.py's runs."""


def main() -> None:
    print("| hall | agents, R | 99 % within | 99.9 % within | farthest | swarm's middle | 95 % reach ahead |")
    print("|---|---|---|---|---|---|---|")
    for name, arena, agents, leash in HALLS:
        track = long_axis_track(arena.bounds, leash, 2.0)
        sim = simulate(arena, agents, float(np.ceil(track.t[-1] + 10)), rng=5, trajectory_every=1.0, beacon=track,
                       leash=leash)
        tj = sim.trajectories
        bx, by = track.position(tj["t"])
        beyond = np.hypot(tj["x"] - bx, tj["y"] - by) - leash
        p99, p999 = np.percentile(beyond, [99, 99.9])
        moving = (tj["t"] > LEADER_SETTLE + 10) & (tj["t"] < track.t[-1] - 10)
        ahead = tj["x"][moving] - bx[moving]
        print(f"| {name} | {agents}, {leash:g} mm | R {p99:+.1f} mm | R {p999:+.1f} mm | R {beyond.max():+.1f} mm | "
              f"{ahead.mean():+.0f} mm | {np.percentile(ahead, 95):+.0f} mm |")


if __name__ == "__main__":
    main()
