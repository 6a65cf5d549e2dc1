"""Wall geometry for the simulator: a bucketed list of boundary segments and its queries.

Every boundary edge of the arena (outer walls and obstacle walls alike) is a segment
``[x0, y0, x1, y1]``.  A :class:`WallGrid` lays a uniform grid of square cells (side
about r_d) over the arena's bounding box and lists, per cell, every segment within
``reach`` of the cell *rectangle* (an exact shapely ``dwithin`` query, so no cell
diagonal needs adding).  For any point inside a cell, every segment closer than
``reach`` is therefore listed, and a query costs O(segments nearby), not O(all).
The simulator picks ``reach`` = r_d + 3 max(v_c, v_p) dt, which covers every query it
makes: wall detection (r_d), the wall-follow re-projection (<= offset + 2 steps),
moves (<= one step) and lines of sight between agents in contact (<= r_d).

No orientation of the rings is used: the side of the free space is always the side of
the querying agent, which is never on a wall (every accepted position keeps a
clearance > ``WALL_EPS`` from all segments).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import shapely
from numba import njit

from ..errors import SwarmtopoError

agent_kernel = njit(cache=True, _nrt=False)
"""Decorator of the per-agent helpers (geometry here, the state machine in motion).

They are compiled without numba's reference-counting runtime (``_nrt=False``, the
option numba uses for its own allocation-free helpers): they neither allocate nor
return arrays, and with the runtime every call would update the reference counts of
each array argument and of the Generator -- atomic operations that cost more than
the helpers' own work (measured: 8x on an empty call).  Their ``.py_func`` is plain
Python, as for any njit function."""

WALL_EPS = 1e-6
"""Minimum clearance (mm) of an agent from any wall; moves ending closer are rejected."""


class WallGrid(NamedTuple):
    """Boundary segments bucketed by grid cell (CSR: ``index[start[c]:start[c+1]]``)."""

    segs: np.ndarray   # (M, 4) float64 [x0, y0, x1, y1]
    start: np.ndarray  # (ncx * ncy + 1,) int64, cell c = cy * ncx + cx
    index: np.ndarray  # int64 segment ids
    x0: float
    y0: float
    cell: float
    ncx: int
    ncy: int


MAX_WALL_CELLS = 50_000_000
"""Most cells a wall grid may have (its CSR offsets take 8 bytes each: 400 MB)."""


def build_wall_grid(segments: np.ndarray, bounds, cell: float, reach: float) -> WallGrid:
    """Bucket ``segments`` over ``bounds`` = (xmin, ymin, xmax, ymax) in cells of side ``cell``.

    A segment is listed in a cell when its distance to the cell rectangle is <= ``reach``.
    Only cells near a wall are ever built (candidates along each segment, then the exact
    test), so time and memory follow the walls' length, not the arena's area; an arena
    of more than MAX_WALL_CELLS cells is refused.
    """
    segs = np.array(segments, dtype=np.float64, order="C").reshape(-1, 4)  # writable: one kernel type
    xmin, ymin, xmax, ymax = (float(v) for v in bounds)
    # a reach beyond the bounds' diagonal lists every segment in every cell, as the diagonal
    # does; capping both keeps the exact test's coordinates finite (a reach of 1e300 overflowed)
    diagonal = max(math.hypot(xmax - xmin, ymax - ymin), WALL_EPS)
    reach, cell = min(reach, diagonal), min(cell, diagonal)
    ncx = max(1, math.ceil((xmax - xmin) / cell))
    ncy = max(1, math.ceil((ymax - ymin) / cell))
    if ncx * ncy > MAX_WALL_CELLS:
        raise SwarmtopoError(f"the arena is {xmax - xmin:.6g} x {ymax - ymin:.6g} mm, {ncx} x {ncy} cells of the "
                             f"detection radius ({cell:g} mm), more than {MAX_WALL_CELLS:,}: are its coordinates in mm?")
    if len(segs):
        cell_id, seg_id = _cells_near(segs, xmin, ymin, cell, reach, ncx, ncy)
        order = np.lexsort((seg_id, cell_id))
        cell_id, seg_id = cell_id[order], seg_id[order]
    else:
        cell_id = seg_id = np.empty(0, np.int64)
    start = np.zeros(ncx * ncy + 1, np.int64)
    np.cumsum(np.bincount(cell_id, minlength=ncx * ncy), out=start[1:])
    return WallGrid(segs, start, seg_id.astype(np.int64), xmin, ymin, float(cell), ncx, ncy)


def _cells_near(segs: np.ndarray, xmin: float, ymin: float, cell: float, reach: float, ncx: int, ncy: int):
    """(cell, segment) pairs with the segment within ``reach`` of the cell rectangle.

    Candidates: the cells within ceil(reach / cell) + 1 of points spaced at most half a
    cell along each segment (every cell within reach of the segment is among them);
    then shapely's exact ``dwithin`` of each candidate box and its segment.
    """
    lengths = np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1])
    samples = np.ceil(2 * lengths / cell).astype(np.int64) + 1
    seg_of = np.repeat(np.arange(len(segs)), samples)
    offset = np.arange(len(seg_of)) - np.repeat(np.cumsum(samples) - samples, samples)
    f = offset / np.maximum(samples - 1, 1)[seg_of]
    x = segs[seg_of, 0] + f * (segs[seg_of, 2] - segs[seg_of, 0])
    y = segs[seg_of, 1] + f * (segs[seg_of, 3] - segs[seg_of, 1])
    pad = math.ceil(reach / cell) + 1
    dx, dy = (d.ravel() for d in np.meshgrid(np.arange(-pad, pad + 1), np.arange(-pad, pad + 1)))
    cx = (np.floor((x - xmin) / cell).astype(np.int64)[:, None] + dx).ravel()
    cy = (np.floor((y - ymin) / cell).astype(np.int64)[:, None] + dy).ravel()
    inside = (cx >= 0) & (cx < ncx) & (cy >= 0) & (cy < ncy)
    n_cells = ncx * ncy
    pairs = np.unique(np.repeat(seg_of, len(dx))[inside] * n_cells + (cy * ncx + cx)[inside])
    seg_id, cell_id = np.divmod(pairs, n_cells)
    cy, cx = np.divmod(cell_id, ncx)
    boxes = shapely.box(xmin + cx * cell, ymin + cy * cell, xmin + (cx + 1) * cell, ymin + (cy + 1) * cell)
    lines = shapely.linestrings(segs.reshape(-1, 2, 2))
    near = shapely.dwithin(lines[seg_id], boxes, reach)
    return cell_id[near], seg_id[near]


def empty_wall_grid() -> WallGrid:
    """A grid without walls (for sensing without an arena)."""
    return WallGrid(np.empty((0, 4)), np.zeros(2, np.int64), np.empty(0, np.int64), 0.0, 0.0, 1.0, 1, 1)


@agent_kernel
def cell_of(walls, x, y):
    """Grid cell holding (x, y); points outside the grid go to the nearest edge cell."""
    cx = min(max(int((x - walls.x0) / walls.cell), 0), walls.ncx - 1)
    cy = min(max(int((y - walls.y0) / walls.cell), 0), walls.ncy - 1)
    return cy * walls.ncx + cx


@agent_kernel
def nearest_wall(walls, x, y):
    """Nearest boundary point to (x, y) among listed segments.

    Returns (distance, qx, qy, segment id); (inf, nan, nan, -1) if no wall is within reach.
    """
    c = cell_of(walls, x, y)
    best, bx, by, bk = np.inf, np.nan, np.nan, -1
    for j in range(walls.start[c], walls.start[c + 1]):
        k = walls.index[j]
        x0, y0, x1, y1 = walls.segs[k, 0], walls.segs[k, 1], walls.segs[k, 2], walls.segs[k, 3]
        dx, dy = x1 - x0, y1 - y0
        u = ((x - x0) * dx + (y - y0) * dy) / (dx * dx + dy * dy)
        u = min(max(u, 0.0), 1.0)
        qx, qy = x0 + u * dx, y0 + u * dy
        d = math.sqrt((x - qx) * (x - qx) + (y - qy) * (y - qy))
        if d < best:
            best, bx, by, bk = d, qx, qy, k
    return best, bx, by, bk


@agent_kernel
def _orient(ax, ay, bx, by, cx, cy):
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


@agent_kernel
def _within_box(ax, ay, bx, by, px, py):
    return min(ax, bx) <= px <= max(ax, bx) and min(ay, by) <= py <= max(ay, by)


@agent_kernel
def segments_intersect(ax, ay, bx, by, cx, cy, dx, dy):
    """True if the closed segments a-b and c-d share a point (touching counts)."""
    d1 = _orient(cx, cy, dx, dy, ax, ay)
    d2 = _orient(cx, cy, dx, dy, bx, by)
    d3 = _orient(ax, ay, bx, by, cx, cy)
    d4 = _orient(ax, ay, bx, by, dx, dy)
    if ((d1 > 0 and d2 < 0) or (d1 < 0 and d2 > 0)) and ((d3 > 0 and d4 < 0) or (d3 < 0 and d4 > 0)):
        return True
    return ((d1 == 0 and _within_box(cx, cy, dx, dy, ax, ay))
            or (d2 == 0 and _within_box(cx, cy, dx, dy, bx, by))
            or (d3 == 0 and _within_box(ax, ay, bx, by, cx, cy))
            or (d4 == 0 and _within_box(ax, ay, bx, by, dx, dy)))


@agent_kernel
def line_of_sight(walls, ax, ay, bx, by):
    """True if the segment a-b crosses no wall listed near a (|a - b| <= reach)."""
    c = cell_of(walls, ax, ay)
    for j in range(walls.start[c], walls.start[c + 1]):
        k = walls.index[j]
        if segments_intersect(ax, ay, bx, by, walls.segs[k, 0], walls.segs[k, 1],
                              walls.segs[k, 2], walls.segs[k, 3]):
            return False
    return True


@agent_kernel
def path_is_clear(walls, px, py, ex, ey):
    """A move p -> e is allowed: it crosses no wall and ends farther than WALL_EPS from all."""
    if not line_of_sight(walls, px, py, ex, ey):
        return False
    return nearest_wall(walls, ex, ey)[0] > WALL_EPS


@agent_kernel
def first_hit(walls, px, py, ex, ey):
    """First wall met on the move p -> e: (u, segment id), u in [0, 1] along the move.

    Returns (inf, -1) if the move meets no wall.  Collinear contact counts as u = 0.
    """
    c = cell_of(walls, px, py)
    best_u, best_k = np.inf, -1
    rx, ry = ex - px, ey - py
    for j in range(walls.start[c], walls.start[c + 1]):
        k = walls.index[j]
        x0, y0, x1, y1 = walls.segs[k, 0], walls.segs[k, 1], walls.segs[k, 2], walls.segs[k, 3]
        if not segments_intersect(px, py, ex, ey, x0, y0, x1, y1):
            continue
        sx, sy = x1 - x0, y1 - y0
        denom = rx * sy - ry * sx
        u = ((x0 - px) * sy - (y0 - py) * sx) / denom if denom != 0 else 0.0
        u = min(max(u, 0.0), 1.0)
        if u < best_u:
            best_u, best_k = u, k
    return best_u, best_k
