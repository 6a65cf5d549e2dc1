"""Tuning of the map's settings for flickering logs on the motion benchmark's tuning
cases (``swarmtopo.experiments.motion_models``; never its reporting cases).

    python lab/tune_motion.py --models brownian flocking --per-cell 4 --workers 2

Simulates the tuning cases once (the logs are kept in ``--cache``), then maps each one
under every candidate: re-contacts merged within M median gaps, per-hop cost h = F_h x
the merged log's mean agent gap, diffusion time tau = F_tau x it, windows of K
encounters per agent; prints the exact (beta_0, beta_1) maps per model and candidate.
The shipped rule is M = 7, F_h = 2, F_tau = 0.5, K = 20 (``pipeline.motion``,
``pipeline.settings``).
"""

from __future__ import annotations

import argparse
import itertools
import pickle
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace
from pathlib import Path


from swarmtopo.experiments.accuracy import tuning_session
from swarmtopo.experiments.grid import job_simulation_args
from swarmtopo.experiments.motion_models import CELLS, MODELS, jobs
from swarmtopo.experiments.sweep import build_arena, contact_trace, stripped_log
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.pipeline.motion import median_agent_gap, recontact_gaps
from swarmtopo.pipeline.settings import mean_agent_gap
from swarmtopo.sim import simulate


def simulate_case(job):
    seeds = job.stream_seeds()
    config = job.config
    arena = build_arena(config["arena"], seeds["arena"])
    sim = simulate(arena, **job_simulation_args(config["swarm"]), rng=seeds["simulation"])
    return (config["swarm"].get("motion", "cockroach"), tuple(arena.betti), contact_trace(stripped_log(sim.log)),
            int(seeds["map"]))


def map_case(args):
    (model, truth, log, seed), (merge_gaps, hop, tau, encounters) = args
    gap = median_agent_gap(log)
    drop = recontact_gaps(log) < merge_gaps * gap
    merged = replace(log, t=log.t[~drop], a=log.a[~drop], b=log.b[~drop])
    mean = mean_agent_gap(merged)
    config = MapConfig(recontacts="keep", hop_cost=hop * mean, diffusion_time=tau * mean,
                       window_encounters=encounters, embed_dim=0, seed=seed)
    tmap = map_encounters(merged, config)
    return model, (tmap.betti[0], tmap.betti[1]) == truth, tmap.betti[1] - truth[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--models", nargs="+", default=["brownian", "flocking"], choices=MODELS)
    parser.add_argument("--per-cell", type=int, default=4)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--merge", type=float, nargs="+", default=[7.0])
    parser.add_argument("--hop", type=float, nargs="+", default=[2.0])
    parser.add_argument("--tau", type=float, nargs="+", default=[0.5])
    parser.add_argument("--encounters", type=float, nargs="+", default=[20.0])
    parser.add_argument("--cache", type=Path, default=Path("motion-tuning-logs.pkl"))
    args = parser.parse_args()
    with tuning_session():
        todo = jobs("tuning", args.per_cell, [c for c in CELLS if c.model in args.models])
    key = (tuple(args.models), args.per_cell)
    cases = None
    if args.cache.exists():
        cached_key, cases = pickle.loads(args.cache.read_bytes())
        cases = cases if cached_key == key else None
    with ProcessPoolExecutor(args.workers) as pool:
        if cases is None:
            cases = list(pool.map(simulate_case, todo))
            args.cache.write_bytes(pickle.dumps((key, cases)))
        candidates = list(itertools.product(args.merge, args.hop, args.tau, args.encounters))
        results = list(pool.map(map_case, [(c, k) for k in candidates for c in cases], chunksize=2))
    print("| merge gaps M | F_h | F_tau | K | " + " | ".join(args.models) + " | all | too many / too few holes |")
    print("|---" * (len(args.models) + 6) + "|")
    n = len(cases)
    for i, k in enumerate(candidates):
        chunk = results[i * n:(i + 1) * n]
        per = [f"{sum(ok for m, ok, _ in chunk if m == model)}/{sum(m == model for m, _, _ in chunk)}"
               for model in args.models]
        over = sum(d > 0 for _, _, d in chunk)
        under = sum(d < 0 for _, _, d in chunk)
        print(f"| {k[0]:g} | {k[1]:g} | {k[2]:g} | {k[3]:g} | " + " | ".join(per)
              + f" | {sum(ok for _, ok, _ in chunk)}/{n} | {over} / {under} |")


if __name__ == "__main__":
    main()
