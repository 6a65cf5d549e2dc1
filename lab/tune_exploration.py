"""Choose the exploration's local-map length and change penalty on the tuning cases of
``swarmtopo bench exploration`` (never the reported ones).

For each tuning case (``--per-cell`` per hole count) the hall is simulated once, and
mapped once per local-map length (``--travel``: the leader's travel per window, as a
share of the leash R); each map's local counts are then stitched with every penalty
(``--penalties``).  Prints, per (travel, penalty): exact global beta_1 and the position
errors' median and 90th percentile.  The rule, stated before looking: the most exact
maps; ties to the smaller position error median.

    python lab/tune_exploration.py --per-cell 3 --workers 2
"""

from __future__ import annotations

import argparse
import itertools
import pickle
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from swarmtopo.beacon import long_axis_track
from swarmtopo.experiments.exploration import CELLS, jobs
from swarmtopo.experiments.grid import job_simulation_args
from swarmtopo.experiments.sweep import build_arena, stripped_log
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.pipeline import exploration
from swarmtopo.pipeline.exploration import stitch
from swarmtopo.sim import simulate


def local_maps(job, travels):
    """(true hole centroids, [(travel, windows, track, leash, length, step)]) of one tuning case."""
    config, seeds = job.config, job.stream_seeds()
    arena = build_arena(config["arena"], seeds["arena"])
    swarm = config["swarm"]
    track = long_axis_track(arena.bounds, swarm["leash"], swarm["leader_speed"])
    sim = simulate(arena, **job_simulation_args(swarm), beacon=track, leash=swarm["leash"], rng=seeds["simulation"])
    log = stripped_log(sim.log)
    out = []
    for travel in travels:  # the shipped map, its local maps' travel set to each value in turn
        exploration.EXPLORATION_TRAVEL = travel
        tmap = map_encounters(log, MapConfig(embed_dim=0, cycles=False, seed=seeds["map"] % 2**32))
        found = tmap.exploration
        span = (float(log.t[0]), float(log.t[-1]))
        out.append((travel, found.windows, log.beacon, found.leash, found.length, found.step, span))
    return arena.hole_centroids().tolist(), out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-cell", type=int, default=3)
    parser.add_argument("--travel", type=float, nargs="+", default=[exploration.EXPLORATION_TRAVEL])
    parser.add_argument("--penalties", type=float, nargs="+", default=[exploration.EXPLORATION_PENALTY])
    parser.add_argument("--handovers", type=float, nargs="+", default=[exploration.HANDOVER_TRAVEL])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--verbose", action="store_true", help="each case's local counts")
    parser.add_argument("--save", help="pickle the local maps here (to study them again without mapping)")
    parser.add_argument("--load", help="a pickle --save wrote, instead of mapping")
    args = parser.parse_args()
    if args.load:
        with open(args.load, "rb") as f:
            args.travel, cases = pickle.load(f)
    else:
        todo = jobs("tuning", args.per_cell, CELLS)
        with ProcessPoolExecutor(args.workers) as pool:
            cases = list(pool.map(local_maps, todo, [args.travel] * len(todo)))
    if args.save:
        with open(args.save, "wb") as f:
            pickle.dump((args.travel, cases), f)
    print("| travel / R | penalty | handover / R | exact | position error median | 90th pct |")
    print("|---|---|---|---|---|---|")
    for (t_index, travel), penalty, handover in itertools.product(enumerate(args.travel), args.penalties,
                                                                   args.handovers):
        exact, errors = 0, []
        for true, maps in cases:
            _, windows, track, leash, length, step, span = maps[t_index]
            found = stitch(windows, track, leash, length, step, 1, {}, span, penalty=penalty, handover=handover)
            exact += found.betti[1] == len(true)
            if args.verbose:
                print(f"  travel {travel:g} penalty {penalty:g}: {len(true)} holes, found {found.betti[1]}: "
                      + " ".join(str(w.betti[1]) for w in windows))
            xy = np.asarray(true)
            errors += [float(np.hypot(*(xy - (h.x, h.y)).T).min()) for h in found.holes]
        print(f"| {travel:g} | {penalty:g} | {handover:g} | {exact}/{len(cases)} | {np.median(errors):.0f} mm | "
              f"{np.percentile(errors, 90):.0f} mm |")


if __name__ == "__main__":
    main()
