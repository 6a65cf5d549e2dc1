"""Where the holes are: representative cycles of significant H1 bars, as loops of landmarks.

A bar [b, d) of dgm_1 comes from ripser.py with a representative *cocycle* phi: a set
of landmark edges (Z/2 coefficients) that is a cocycle of the Rips complex X(eps) and
non-trivial there for every eps in [b, d).  A loop gamma of edges of X(eps) is a
1-cycle, and the pairing <phi, gamma> (the number of edges of gamma in phi, mod 2)
depends only on gamma's homology class.  So any loop that crosses phi an odd number
of times is a non-trivial cycle of X(eps) that "goes round" the feature of this bar.
We return the shortest such loop (edge weights = the landmark distances, seconds of
the encounter metric), found as a shortest path in the Z/2 double cover of the Rips
graph: nodes (v, parity), an edge of phi flips the parity, and the shortest loop
through landmark s crossing phi oddly is the shortest path from (s, 0) to (s, 1).
The minimum over s is a simple loop: a closed walk that repeats a vertex splits into
two shorter closed walks, one of which still crosses phi oddly.

Scale: eps = b + position (d - b), by default the midpoint of the bar.  Just above b
the graph has only the shortest edges, so the loop hugs whatever thin ring of
landmarks closed the cycle first (and a cocycle edge may be absent);
just below d the graph has edges as long as the hole itself, so the loop cuts
corners through regions the encounter metric barely resolves.  The midpoint is as far
from both ends as the bar allows (see docs/cycles.md for both ends measured).

Ground truth (simulations): the true position of an event is the midpoint of its two
agents (``Simulation.truth``); :func:`encircled_obstacles` reads a loop of true
positions as a closed polygon and says which obstacles it goes round.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp
import shapely
from scipy.sparse.csgraph import dijkstra

from ..errors import InputError
from .persistence import PersistenceResult, check_distance_matrix, rips_persistence

DEFAULT_POSITION = 0.5
"""Where in the bar [b, d) the Rips graph is taken: eps = b + position (d - b)."""

OBSTACLE_SAMPLES = 15
"""Grid points per side sampled inside an obstacle to measure how much of it a loop encloses."""


@dataclass(frozen=True, eq=False)
class Cycle:
    """A representative loop of one H1 bar.

    Attributes
    ----------
    landmarks
        (k,) int64 landmark indices in loop order (the loop closes from the last
        back to the first); k >= 3.
    bar
        The bar (b, d) it represents (d may be inf).
    bar_index
        Index of the bar in ``diagram[1]``.
    scale
        eps: the loop uses only edges of the Rips graph X(eps), d(l_i, l_j) <= eps.
    length
        Sum of the landmark distances along the loop (seconds).
    events
        (k,) original log event index of each landmark, or None when unknown.
    """

    landmarks: np.ndarray
    bar: tuple[float, float]
    bar_index: int
    scale: float
    length: float
    events: np.ndarray | None = None

    def to_json(self) -> dict:
        """``{"bar": [b, d|null], "scale", "length", "landmarks": [...], "events": [...]|null}``."""
        b, d = self.bar
        return {
            "bar": [float(b), float(d) if np.isfinite(d) else None],
            "scale": float(self.scale),
            "length": float(self.length),
            "landmarks": [int(i) for i in self.landmarks],
            "events": None if self.events is None else [int(e) for e in self.events],
        }


def shortest_odd_loop(distances: np.ndarray, cocycle_edges: np.ndarray, scale: float) -> np.ndarray | None:
    """Shortest loop of the Rips graph X(scale) crossing the given edges an odd number of times.

    Parameters
    ----------
    distances
        (L, L) landmark distances (validated, symmetric).
    cocycle_edges
        (m, 2) landmark index pairs with coefficient 1 mod 2 (the cocycle phi).
    scale
        eps: edges with d_ij <= eps are in the graph.

    Returns
    -------
    ndarray or None
        Landmark indices in loop order, or None if no such loop exists in X(eps).
    """
    n = len(distances)
    upper = np.triu(distances <= scale, k=1)
    i, j = np.nonzero(upper)
    if len(i) == 0 or len(cocycle_edges) == 0:
        return None
    flip = np.zeros((n, n), dtype=bool)
    u, v = np.asarray(cocycle_edges, dtype=np.int64).T
    flip[u, v] = flip[v, u] = True
    odd = flip[i, j]
    w = distances[i, j]
    # Double cover: node v -> (v, 0) = v, (v, 1) = v + n.  Even edges stay on a sheet,
    # odd edges (in phi) switch sheets.
    src = np.concatenate([i, i + n])
    dst = np.concatenate([np.where(odd, j + n, j), np.where(odd, j, j + n)])
    weights = np.concatenate([w, w])
    cover = sp.coo_matrix((weights, (src, dst)), shape=(2 * n, 2 * n)).tocsr()
    # Every odd loop uses an edge of phi, so it passes through one of its endpoints.
    sources = np.unique(np.concatenate([u, v]))
    sources = sources[np.isin(sources, np.concatenate([i, j]))]
    if len(sources) == 0:
        return None
    dist, pred = dijkstra(cover, directed=False, indices=sources, return_predecessors=True)
    loop_lengths = dist[np.arange(len(sources)), sources + n]
    best = int(np.argmin(loop_lengths))
    if not np.isfinite(loop_lengths[best]):
        return None
    s = int(sources[best])
    path = [s + n]
    while path[-1] != s:
        path.append(int(pred[best, path[-1]]))
    return np.array(path[:0:-1], dtype=np.int64) % n


def representative_cycles(distances, result: PersistenceResult, bars=None, *, threshold: float | None = None,
                          position: float = DEFAULT_POSITION) -> list[Cycle]:
    """Representative loops of H1 bars, from ripser.py's cocycles.

    Parameters
    ----------
    distances
        (L, L) landmark distances the persistence was computed on.
    result
        ``rips_persistence(distances, cocycles=True)``.
    bars
        Indices into ``result.diagram[1]``; or None to select by ``threshold``.
    threshold
        Bars longer than this (the classifier's tau_1 (l_q + Delta_1)); with
        ``bars=None`` and no threshold, every H1 bar.
    position
        eps = b + position (d - b), in [0, 1); an infinite bar uses eps = max distance.

    Returns
    -------
    list of Cycle
        One per selected bar that has a loop in X(eps), in bar order.
    """
    matrix = check_distance_matrix(distances)
    if result.cocycles is None:
        raise InputError("representative cycles need cocycles: rips_persistence(..., cocycles=True)")
    if not 0.0 <= position < 1.0:
        raise InputError("position must be in [0, 1)", value=position)
    dgm = result.diagram[1]
    if bars is None:
        lengths = dgm[:, 1] - dgm[:, 0]
        bars = np.flatnonzero(lengths > threshold) if threshold is not None else np.arange(len(dgm))
    cycles = []
    for index in np.asarray(bars, dtype=np.int64):
        if not 0 <= index < len(dgm):
            raise InputError(f"bar index out of range 0..{len(dgm) - 1}", value=int(index))
        b, d = (float(x) for x in dgm[index])
        scale = b + position * (d - b) if np.isfinite(d) else float(matrix.max())
        cocycle = np.asarray(result.cocycles[1][index]).reshape(-1, 3)
        edges = cocycle[cocycle[:, 2] % 2 == 1, :2]
        loop = shortest_odd_loop(matrix, edges, scale)
        if loop is None:
            continue
        length = float(matrix[loop, np.roll(loop, -1)].sum())
        cycles.append(Cycle(landmarks=loop, bar=(b, d), bar_index=int(index), scale=scale, length=length))
    return cycles


def region_cycles(region, result: PersistenceResult | None = None, *,
                  position: float = DEFAULT_POSITION) -> list[Cycle]:
    """Cycles of the significant H1 bars of one mapped region (one call for map.json).

    ``region`` is a :class:`swarmtopo.pipeline.map.RegionMap`; ``result`` its persistence
    with cocycles (``rips_persistence(region.landmarks.distances, cocycles=True)``),
    computed here when not given (the adapter makes its diagram identical to the
    region's).  The bars in ``region.counted[1]`` are the ones the classifier counts,
    and each loop carries its landmarks' log event indices.
    """
    if 1 not in region.counted:
        return []
    distances = region.landmarks.distances
    if result is None:
        result = rips_persistence(distances, maxdim=1, cocycles=True)
    cycles = representative_cycles(distances, result, region.counted[1], position=position)
    events = np.asarray(region.landmark_events)
    return [replace(c, events=events[c.landmarks]) for c in cycles]


# -- ground truth ------------------------------------------------------------------------
def event_positions(truth: dict, events) -> np.ndarray:
    """(k, 2) true positions of log events: the midpoint of the two agents (mm)."""
    events = np.asarray(events, dtype=np.int64)
    x = 0.5 * (truth["xa"][events] + truth["xb"][events])
    y = 0.5 * (truth["ya"][events] + truth["yb"][events])
    return np.column_stack([x, y])


def odd_winding(loop_xy: np.ndarray, points: np.ndarray) -> np.ndarray:
    """True where the closed polygon ``loop_xy`` winds an odd number of times round a point.

    Even-odd (ray crossing) rule: a horizontal ray from the point crosses the loop's
    edges an odd number of times.  For a self-intersecting loop this is the Z/2
    winding number, the same coefficients the persistence uses.
    """
    x0, y0 = loop_xy[:, 0], loop_xy[:, 1]
    x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
    px, py = points[:, 0:1], points[:, 1:2]
    straddles = (y0 > py) != (y1 > py)
    with np.errstate(divide="ignore", invalid="ignore"):
        x_cross = x0 + (py - y0) * (x1 - x0) / (y1 - y0)
    crossings = straddles & (px < x_cross)
    return crossings.sum(axis=1) % 2 == 1


def encircled_obstacles(loop_xy, arena, *, samples: int = OBSTACLE_SAMPLES) -> list[int]:
    """Indices (into ``arena.obstacles``) of the obstacles a loop of true positions encircles.

    An obstacle is encircled when more than half of it (a ``samples`` x ``samples``
    grid of its bounding box, points inside the obstacle) has odd winding number: a
    straight segment between two consecutive events can cut across an obstacle
    corner, which a single test point would turn into a coin flip.
    """
    loop_xy = np.asarray(loop_xy, dtype=np.float64)
    if len(loop_xy) < 3:
        return []
    found = []
    for k, obstacle in enumerate(arena.obstacles):
        xmin, ymin, xmax, ymax = obstacle.bounds
        gx, gy = np.meshgrid(np.linspace(xmin, xmax, samples + 2)[1:-1],
                             np.linspace(ymin, ymax, samples + 2)[1:-1])
        grid = np.column_stack([gx.ravel(), gy.ravel()])
        inside = grid[shapely.contains_xy(obstacle, grid[:, 0], grid[:, 1])]
        if len(inside) == 0:
            inside = np.array(obstacle.representative_point().coords)
        if odd_winding(loop_xy, inside).mean() > 0.5:
            found.append(k)
    return found


@dataclass(frozen=True)
class LocalizationScores:
    """Precision and recall of cycle localization over many maps.

    precision = correct / detected: detected cycles whose true-position loop encircles
    exactly one obstacle; recall = found / obstacles: true obstacles encircled by some
    detected cycle of their map.
    """

    detected: int
    correct: int
    obstacles: int
    found: int

    @property
    def precision(self) -> float:
        return self.correct / self.detected if self.detected else float("nan")

    @property
    def recall(self) -> float:
        return self.found / self.obstacles if self.obstacles else float("nan")


def localization_scores(maps) -> LocalizationScores:
    """Pool ``maps``: an iterable of (list of encircled-obstacle lists, one per cycle; number of obstacles)."""
    detected = correct = obstacles = found = 0
    for per_cycle, n_obstacles in maps:
        detected += len(per_cycle)
        correct += sum(len(e) == 1 for e in per_cycle)
        obstacles += n_obstacles
        found += len({k for e in per_cycle for k in e})
    return LocalizationScores(detected, correct, obstacles, found)


def wilson_interval(successes: int, trials: int, z: float = 1.959964) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion (95 % by default)."""
    if trials == 0:
        return (float("nan"), float("nan"))
    p = successes / trials
    centre = (p + z * z / (2 * trials)) / (1 + z * z / trials)
    half = z * np.sqrt(p * (1 - p) / trials + z * z / (4 * trials * trials)) / (1 + z * z / trials)
    return (float(centre - half), float(centre + half))
