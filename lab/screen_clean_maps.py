"""Clean logs the fault screen acts on, and their maps with and without it: the check
that the screen leaves the accuracy of fault-free logs as it was.

    python lab/screen_clean_maps.py --per-cell 20 --workers 2

Simulates the first PER_CELL reporting cases of every cell of the accuracy benchmark
(no fault), reads each log as ``swarmtopo map`` does (the default pipeline on the log
folder stripped of ground truth) and, where the screen drops or merges events (a sparse
swarm's far share above CLEAN_FAR_SHARE), maps it with the screen and without
(``uncorroborated = "keep"``).  Prints per cell how many logs the screen acts on and
how many of those maps are exact either way; every other log maps exactly as without
the screen (the screen returns it untouched).
"""

from __future__ import annotations

import argparse
import dataclasses
from concurrent.futures import ProcessPoolExecutor

from swarmtopo.experiments.accuracy import CELLS, PIPELINES, built_case
from swarmtopo.experiments.grid import job_simulation_args
from swarmtopo.experiments.sweep import cached_classifier, job_map_config, stripped_log
from swarmtopo.pipeline import map_encounters
from swarmtopo.pipeline.faults import screen_faults
from swarmtopo.sim import simulate


def one(args) -> tuple[str, bool, bool | None, bool | None]:
    """(cell, screen acts, exact with the screen, exact without) of one reporting case."""
    cell_name, index = args
    cell = next(c for c in CELLS if c.name == cell_name)
    _, seed, arena, stream = built_case(cell, "reporting", index)
    swarm = {"agents": cell.agents, "duration": cell.duration, "static_fraction": 0.0}
    log = stripped_log(simulate(arena, **job_simulation_args(swarm), rng=stream).log)
    screen, _ = screen_faults(log)
    if not (screen.dropped or screen.merged):
        return cell_name, False, None, None
    config = job_map_config(PIPELINES["default"], index)
    exact = []
    for mode in ("auto", "keep"):
        tmap = map_encounters(log, dataclasses.replace(config, uncorroborated=mode),
                              reader=cached_classifier("default", None))
        exact.append(tmap.betti[0] == arena.betti[0] and tmap.betti[1] == arena.betti[1])
    return cell_name, True, exact[0], exact[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-cell", type=int, default=20)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    cases = [(c.name, i) for c in CELLS for i in range(args.per_cell)]
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(pool.map(one, cases, chunksize=2))
    print("| cell | logs | screen acts | exact with the screen | exact without |\n|---|---|---|---|---|")
    for name in [c.name for c in CELLS] + ["all"]:
        mine = [r for r in rows if name in (r[0], "all")]
        acted = [r for r in mine if r[1]]
        print(f"| {name} | {len(mine)} | {len(acted)} | {sum(r[2] for r in acted)} | {sum(r[3] for r in acted)} |")


if __name__ == "__main__":
    main()
