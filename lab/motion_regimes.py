"""The re-contact share rho (swarmtopo.pipeline.motion) of the accuracy benchmark's
cockroach logs: the motion regime's threshold FLICKER_SHARE must leave every one of
them ``persistent``, so that they map exactly as before the regime existed.

    python lab/motion_regimes.py --per-cell 20 --workers 2

Simulates (no map) the first PER_CELL tuning and reporting cases of every cell and
prints, per cell, the least, median and largest rho and how many logs exceed
FLICKER_SHARE.
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from swarmtopo.experiments.accuracy import CELLS, built_case, tuning_session
from swarmtopo.experiments.grid import job_simulation_args
from swarmtopo.pipeline.motion import FLICKER_SHARE, estimate_motion
from swarmtopo.sim import simulate


def share(args) -> tuple[str, str, float]:
    cell_name, split, index = args
    cell = next(c for c in CELLS if c.name == cell_name)
    if split == "tuning":
        with tuning_session():
            _, _, arena, stream = built_case(cell, split, index)
    else:
        _, _, arena, stream = built_case(cell, split, index)
    swarm = {"agents": cell.agents, "duration": cell.duration, "static_fraction": 0.0}
    log = simulate(arena, **job_simulation_args(swarm), rng=stream).log
    return cell_name, split, estimate_motion(log)[0].recontact_share


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-cell", type=int, default=20)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    jobs = [(c.name, split, i) for c in CELLS for split in ("tuning", "reporting") for i in range(args.per_cell)]
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(pool.map(share, jobs, chunksize=4))
    print(f"FLICKER_SHARE = {FLICKER_SHARE}")
    print("| cell | logs | rho min | rho median | rho max | above the threshold |")
    print("|---|---|---|---|---|---|")
    for name in [c.name for c in CELLS] + ["all"]:
        rho = np.array([r[2] for r in rows if name in (r[0], "all")])
        print(f"| {name} | {len(rho)} | {rho.min():.3f} | {np.median(rho):.3f} | {rho.max():.3f} | "
              f"{int((rho > FLICKER_SHARE).sum())} |")


if __name__ == "__main__":
    main()
