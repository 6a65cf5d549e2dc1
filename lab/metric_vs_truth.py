"""The encounter metric against the truth: what limits the maps of sparse swarms.

For tuning cases of one cell of the accuracy suite (inside ``tuning_session``), each log is
mapped with the default pipeline and the landmarks of its first window are compared
with the simulation's truth: their encounter-metric distance d (seconds) against the
true geodesic distance g between the events' positions (mm, the midpoint of the two
agents; shortest paths in the free space on an 8-connected grid of ``GRID_MM``) and
against their time separation dt.  Printed: the median d per (g, dt) bin, pooled over
the cases, and a least-squares fit d ~ a + b g + c dt.

    python lab/metric_vs_truth.py [--cases 5] [--cell "3 holes, 200 x 30 s"]
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy import sparse
from scipy.sparse.csgraph import dijkstra
from scipy.spatial import cKDTree

from swarmtopo.topology.cycles import event_positions
from swarmtopo.experiments.accuracy import CELLS, tuning_arena
from swarmtopo.experiments.sweep import stripped_log
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.sim import simulate

GRID_MM = 5.0
G_BINS = (0, 30, 60, 100, 150, 200, 300, 450)
DT_BINS = (0, 2, 5, 10, 20, 40)


def geodesic_distances(arena, points: np.ndarray, step: float = GRID_MM) -> np.ndarray:
    """Shortest-path distances (mm) between ``points`` inside ``arena`` on an 8-connected grid
    of side ``step`` (each point snapped to its nearest free grid node)."""
    x0, y0, x1, y1 = arena.bounds
    nx, ny = int(np.ceil((x1 - x0) / step)) + 1, int(np.ceil((y1 - y0) / step)) + 1
    gx, gy = np.meshgrid(x0 + step * np.arange(nx), y0 + step * np.arange(ny), indexing="ij")
    free = arena.contains(gx.ravel(), gy.ravel()).reshape(nx, ny)
    node = np.full((nx, ny), -1, np.int64)
    node[free] = np.arange(int(free.sum()))
    rows, cols, weights = [], [], []
    for dx, dy in ((1, 0), (0, 1), (1, 1), (1, -1)):
        source = node[:nx - dx, max(0, -dy):ny - max(0, dy)].ravel()
        target = node[dx:, max(0, dy):ny + min(0, dy)].ravel()
        both = (source >= 0) & (target >= 0)
        rows.append(source[both]), cols.append(target[both])
        weights.append(np.full(int(both.sum()), step * np.hypot(dx, dy)))
    n = int(free.sum())
    graph = sparse.coo_matrix((np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))),
                              shape=(n, n)).tocsr()
    _, nearest = cKDTree(np.column_stack([gx[free], gy[free]])).query(points)
    out = dijkstra(graph, directed=False, indices=nearest)[:, nearest]
    return np.minimum(out, out.T)


def landmark_pairs(cell, index: int):
    """(d, g, dt) of every pair of landmarks of the first window of one tuning case's map."""
    _, seed, arena, stream = tuning_arena(cell, index)
    sim = simulate(arena, cell.agents, cell.duration, rng=stream, truth=True)
    log = stripped_log(sim.log)
    window = map_encounters(log, MapConfig(seed=seed % 2**32, embed_dim=0, cycles=False)).regions[0].windows[0]
    events = window.landmark_events
    true = geodesic_distances(arena, event_positions(sim.truth, events))
    upper = np.triu_indices(len(events), 1)
    times = log.t[events]
    return window.landmarks.distances[upper], true[upper], np.abs(times[:, None] - times[None, :])[upper]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=5)
    parser.add_argument("--cell", default=CELLS[9].name, help=f"a cell name (default {CELLS[9].name!r})")
    args = parser.parse_args()
    cell = next(c for c in CELLS if c.name == args.cell)
    d, g, dt = (np.concatenate(x) for x in zip(*(landmark_pairs(cell, i) for i in range(args.cases))))
    print(f"{cell.name}: first windows of {args.cases} tuning cases, {len(d)} landmark pairs")
    print("median encounter distance d (s) by true distance g (rows) and time separation dt (columns); "
          "'.' under 20 pairs")
    print("g (mm)   " + " ".join(f"dt {a:>2d}-{b:<3d}" for a, b in zip(DT_BINS[:-1], DT_BINS[1:])))
    for g_lo, g_hi in zip(G_BINS[:-1], G_BINS[1:]):
        cells = []
        for t_lo, t_hi in zip(DT_BINS[:-1], DT_BINS[1:]):
            inside = (g >= g_lo) & (g < g_hi) & (dt >= t_lo) & (dt < t_hi)
            cells.append(f"{np.median(d[inside]):9.1f}" if inside.sum() >= 20 else "        .")
        print(f"{g_lo:3d}-{g_hi:<4d} " + " ".join(cells))
    design = np.column_stack([np.ones_like(d), g, dt])
    (a, b, c), *_ = np.linalg.lstsq(design, d, rcond=None)
    print(f"fit d = {a:.2f} s + {b:.4f} s/mm x g + {c:.3f} x dt; residual sd {np.std(d - design @ (a, b, c)):.2f} s "
          f"(sd of d {np.std(d):.2f} s)")


if __name__ == "__main__":
    main()
