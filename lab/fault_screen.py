"""The fault screen (swarmtopo.pipeline.faults) on tuning cases: how many encounters a
clean log leaves uncorroborated, and how well the rule tells false encounters from true
ones under each fault.

    python lab/fault_screen.py --per-cell 6 --faulty 6 --workers 2

Part 1 simulates (no map) the first PER_CELL tuning cases of every cell of the
accuracy benchmark with at least MIN_AGENTS agents and prints, per cell, the share u
of uncorroborated events and the share of far ones: the far share must stay under
CLEAN_FAR_SHARE on every clean log, so that it maps exactly as before the screen
existed.  Part 2 perturbs FAULTY tuning cases per hole count of the fault benchmark
(300 agents x 40 s, 0-3 holes) at each fault level of TRIED and prints u, the share
of true encounters flagged, the share of false encounters kept (for the rule's
constants and a neighbour of each), how many logs the screen reads as faulty and in how
many it merges duplicated reports.
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from swarmtopo.experiments.accuracy import CELLS, built_case, tuning_session
from swarmtopo.experiments.faults import HOLES, LEVELS, Cell, case
from swarmtopo.experiments.grid import case_streams, job_simulation_args
from swarmtopo.experiments.sweep import build_arena
from swarmtopo.pipeline.faults import (CLEAN_DUPLICATE_SHARE, CLEAN_FAR_SHARE, DETOUR_HOPS, FAR_HOPS, HOP_GAPS, POOR_SHARE,
                                      detours, screen_faults)
from swarmtopo.pipeline.motion import MIN_AGENTS, median_agent_gap
from swarmtopo.sim import simulate
from swarmtopo.sim.faults import Faults, perturb

RULES = [(HOP_GAPS, DETOUR_HOPS), (HOP_GAPS / 2, DETOUR_HOPS), (HOP_GAPS * 2, DETOUR_HOPS),
         (HOP_GAPS, DETOUR_HOPS * 0.75), (HOP_GAPS, DETOUR_HOPS * 1.5)]
TRIED = [{}, {"lost": 0.5}, {"jitter": 1.0}, {"clock_offset": 5.0}, {"duplicated": 0.1}, {"false_encounters": 0.005},
         {"false_encounters": 0.01},
          {"false_encounters": 0.03}, {"false_encounters": 0.05},
          {"lost": 0.5, "jitter": 1.0, "false_encounters": 0.03, "dying": 0.2}]


def clean_share(args) -> tuple[str, float, float, float]:
    cell_name, index = args
    cell = next(c for c in CELLS if c.name == cell_name)
    with tuning_session():
        _, _, arena, stream = built_case(cell, "tuning", index)
    swarm = {"agents": cell.agents, "duration": cell.duration, "static_fraction": 0.0}
    screen, _ = screen_faults(simulate(arena, **job_simulation_args(swarm), rng=stream).log)
    return cell_name, screen.uncorroborated_share, screen.far_share, screen.duplicate_share


def case_log(holes: int, index: int):
    """The clean log of the fault benchmark's tuning case ``index`` with ``holes`` holes,
    and the seed of its faults stream."""
    config, seed = case(Cell(LEVELS[0], holes), "tuning", index)
    streams = case_streams(seed)
    arena = build_arena(config["arena"], streams["arena"])
    return simulate(arena, **job_simulation_args(config["swarm"]), rng=streams["simulation"]).log, streams["faults"]


def faulty(args) -> list[tuple]:
    holes, index, level = args
    clean, seed = case_log(holes, index)
    log, _ = perturb(clean, Faults(**level), seed)
    n = log.n_agents
    met = set((clean.a * n + clean.b).tolist())
    false = np.array([pair not in met for pair in (log.a * n + log.b).tolist()])
    gap = median_agent_gap(log)
    screen = screen_faults(log)[0]
    rows = []
    for hop, hops in RULES:
        lone = ~np.isfinite(detours(log, hop * gap, hops * hop * gap))
        rows.append(((hop, hops), lone.mean(), lone[~false].mean(), (~lone[false]).mean() if false.any() else None,
                     screen.suspected, screen.duplicated, screen.far_share, screen.duplicate_share))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-cell", type=int, default=6)
    parser.add_argument("--faulty", type=int, default=6, help="tuning cases per hole count and fault level")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    cells = [c.name for c in CELLS if c.agents >= MIN_AGENTS]
    with ProcessPoolExecutor(args.workers) as pool:
        shares = list(pool.map(clean_share, [(c, i) for c in cells for i in range(args.per_cell)]))
        print(f"HOP_GAPS = {HOP_GAPS}, DETOUR_HOPS = {DETOUR_HOPS}, FAR_HOPS = {FAR_HOPS}, "
              f"CLEAN_FAR_SHARE = {CLEAN_FAR_SHARE}, POOR_SHARE = {POOR_SHARE}, "
              f"CLEAN_DUPLICATE_SHARE = {CLEAN_DUPLICATE_SHARE}")
        print("| clean cell | logs | u min / median / max | far min / median / max | repeats max | far / u / repeats "
              "above their bound |\n|---|---|---|---|---|---|")
        for name in cells + ["all"]:
            u, far, rep = (np.array([s[k] for s in shares if name in (s[0], "all")]) for k in (1, 2, 3))
            print(f"| {name} | {len(u)} | {u.min():.3f} / {np.median(u):.3f} / {u.max():.3f} | "
                  f"{far.min():.4f} / {np.median(far):.4f} / {far.max():.4f} | {rep.max():.3f} | "
                  f"{int((far > CLEAN_FAR_SHARE).sum())} / {int((u > POOR_SHARE).sum())} / "
                  f"{int((rep > CLEAN_DUPLICATE_SHARE).sum())} |")
        print("\n| faults | H/g, K | u | true flagged | false kept | far share min-max | repeats min-max | "
              "read as faulty | duplicates merged |\n|---|---|---|---|---|---|---|---|---|")
        for level in TRIED:
            jobs = [(h, i, level) for h in HOLES for i in range(args.faulty)]
            rows = [r for case in pool.map(faulty, jobs) for r in case]
            for rule in RULES:
                mine = [r for r in rows if r[0] == rule]
                kept = [r[3] for r in mine if r[3] is not None]
                print(f"| {level or 'none'} | {rule[0]:g}, {rule[1]:g} | {np.mean([r[1] for r in mine]):.3f} | "
                      f"{np.mean([r[2] for r in mine]):.3f} | {np.mean(kept) if kept else float('nan'):.3f} | "
                      f"{min(r[6] for r in mine):.4f}-{max(r[6] for r in mine):.4f} | "
                      f"{min(r[7] for r in mine):.3f}-{max(r[7] for r in mine):.3f} | "
                      f"{sum(r[4] for r in mine)}/{len(mine)} | {sum(r[5] for r in mine)}/{len(mine)} |")


if __name__ == "__main__":
    main()
