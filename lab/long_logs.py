"""What the window cap costs on long logs: every window against ``MapConfig.max_windows``.

The accuracy suite's logs are at most 60 s long and no map of it pools more than 44
windows, so the cap (``MAX_WINDOWS`` = 48) leaves it alone.  This maps logs several
times longer: the arenas of the suite's largest-budget tuning cases (400 agents, 0-3
holes; ``experiments.accuracy.case``) simulated for ``--duration`` seconds instead of
60, stripped of ground truth, each mapped by the default pipeline twice, with every
window (``max_windows=None``) and with the cap.  Prints per setting the exact
(beta_0, beta_1) count, the windows pooled and the seconds per map (mean, median), and
on how many maps the two agree.

    python lab/long_logs.py [--per-cell 6] [--duration 240] [--cap 48]
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from swarmtopo.experiments.accuracy import CELLS, tuning_arena
from swarmtopo.experiments.sweep import stripped_log
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.sim import simulate

BUDGET = "400 x 60 s"
"""The cells whose arenas and swarm size are simulated for longer."""


def _run(task):
    cell_index, index, duration, cap = task
    cell = CELLS[cell_index]
    _, seed, arena, stream = tuning_arena(cell, index)
    log = stripped_log(simulate(arena, cell.agents, duration, rng=stream).log)
    out = []
    for max_windows in (None, cap):
        start = time.perf_counter()
        tmap = map_encounters(log, MapConfig(seed=seed % 2**32, embed_dim=0, cycles=False, max_windows=max_windows))
        out.append((tmap.betti[0] == arena.betti[0] and tmap.betti[1] == arena.betti[1],
                    max(len(r.windows) for r in tmap.regions), time.perf_counter() - start,
                    (tmap.betti[0], tmap.betti[1])))
    return cell.name, log.n_events, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-cell", type=int, default=6)
    parser.add_argument("--duration", type=float, default=240.0)
    parser.add_argument("--cap", type=int, default=MapConfig.max_windows)
    parser.add_argument("--processes", type=int, default=2)
    args = parser.parse_args()
    cells = [i for i, c in enumerate(CELLS) if c.name.endswith(BUDGET)]
    tasks = [(c, i, args.duration, args.cap) for i in range(args.per_cell) for c in cells]
    with ProcessPoolExecutor(args.processes) as pool:
        results = list(pool.map(_run, tasks))
    events = [n for _, n, _ in results]
    print(f"{len(results)} tuning arenas of the {BUDGET} cells ({', '.join(CELLS[c].name for c in cells)}), "
          f"simulated for {args.duration:g} s: {int(np.median(events))} events per log (median)")
    for k, label in enumerate(("every window", f"at most {args.cap} windows")):
        right = sum(r[k][0] for _, _, r in results)
        windows = [r[k][1] for _, _, r in results]
        seconds = [r[k][2] for _, _, r in results]
        print(f"{label}: {right}/{len(results)} exact; windows {min(windows)}-{max(windows)} "
              f"(median {int(np.median(windows))}); {np.mean(seconds):.1f} s per map (median {np.median(seconds):.1f})")
    same = sum(r[0][3] == r[1][3] for _, _, r in results)
    print(f"the same (beta_0, beta_1) on {same}/{len(results)} maps")


if __name__ == "__main__":
    main()
