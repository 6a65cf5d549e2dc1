"""Encounter tracking (paper, "Sensing and Communication", "Encounter Tracking").

Agents a and b are *in contact* at t_k when ||p_a - p_b|| <= r_d and, if walls block
sensing, the segment a-b crosses no wall.  An event [t_k, a, b] is recorded only at
the first step of each contact period: approach, stay, leave and return give exactly
two events.  Pairs already in contact at the first update are logged then (at t = 0
in a simulation) when ``log_initial_contacts`` is set: the paper's condition "not in
contact at the previous step" holds vacuously at t = 0, and a real radio reports
contacts already in progress at start-up.

Neighbour search uses cell lists (cell side >= r_d, so the 3 x 3 block around an
agent's cell holds all its candidates), never all pairs.  The cell grid spans the
agents' bounding box; its side grows past r_d only when the box is sparse enough that
there would be more than about 6 N cells.  Contacts are kept as sorted keys a N + b
(a < b); new contacts are the set difference with the previous step, by a linear merge.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..arena import Arena
from .walls import WallGrid, build_wall_grid, empty_wall_grid, line_of_sight


class EncounterTracker:
    """Turns positions at successive times into encounter events.

    Parameters
    ----------
    n_agents : int
        N; agents are 0 .. N-1.
    r_d : float
        Detection radius, mm.
    walls : Arena, WallGrid or None
        Walls that block sensing (None: nothing blocks).  A WallGrid must list the
        segments within r_d of each cell (the simulator shares its own).
    log_initial_contacts : bool
        Report the contacts found at the first update.
    """

    def __init__(self, n_agents: int, r_d: float, walls: Arena | WallGrid | None = None, *,
                 log_initial_contacts: bool = True):
        self.n_agents = int(n_agents)
        self.r_d = float(r_d)
        if isinstance(walls, Arena):
            walls = build_wall_grid(walls.boundary_segments, walls.bounds, cell=self.r_d, reach=self.r_d)
        self.walls = walls if walls is not None else empty_wall_grid()
        self.walls_block = walls is not None
        self.log_initial_contacts = bool(log_initial_contacts)
        self._current = np.empty(0, np.int64)
        self._buffer = np.empty(max(16, 2 * self.n_agents), np.int64)
        self._new = np.empty(0, np.int64)
        self.time: float | None = None  # time of the last update

    @property
    def contacts(self) -> tuple[np.ndarray, np.ndarray]:
        """Pairs (a, b), a < b, in contact at the last update, sorted."""
        return np.divmod(self._current, self.n_agents)

    def update(self, t: float, x, y) -> tuple[np.ndarray, np.ndarray]:
        """Positions at the next time step ``t`` -> the pairs (a, b) whose contact starts at t.

        Times must increase from one update to the next.  Returns int64 arrays sorted
        by (a, b), a < b: the events [t, a, b].
        """
        x = np.ascontiguousarray(x, dtype=np.float64)
        y = np.ascontiguousarray(y, dtype=np.float64)
        if x.shape != (self.n_agents,) or y.shape != (self.n_agents,):
            raise ValueError(f"expected {self.n_agents} x and y positions, got {x.shape} and {y.shape}")
        first = self.time is None
        if not first and not t > self.time:
            raise ValueError(f"update times must increase: got t={t} after t={self.time}")
        self.time = t
        while True:
            n = contact_keys(x, y, self.r_d, self.walls, self.walls_block, self._buffer)
            if n <= len(self._buffer):
                break
            self._buffer = np.empty(2 * n, np.int64)
        current = self._buffer[:n].copy()
        if not first or self.log_initial_contacts:
            if len(self._new) < n:
                self._new = np.empty(max(n, 2 * len(self._new)), np.int64)
            m = new_keys(self._current, current, self._new)
            new = self._new[:m]
        else:
            new = current[:0]
        self._current = current
        return np.divmod(new, self.n_agents)


@njit(cache=True)
def contact_keys(x, y, r_d, walls, walls_block, out):
    """Sorted keys a N + b (a < b) of all pairs in contact; returns their count.

    Writes at most ``len(out)`` keys; a count larger than that means "call again
    with a bigger buffer".
    """
    n = len(x)
    xmin, xmax, ymin, ymax = x.min(), x.max(), y.min(), y.max()
    width, height = xmax - xmin, ymax - ymin
    cell = max(r_d, math.sqrt(width * height / (2.0 * n)), (width + height) / (4.0 * n))
    ncx, ncy = int(width / cell) + 1, int(height / cell) + 1
    cx = np.empty(n, np.int64)
    cy = np.empty(n, np.int64)
    start = np.zeros(ncx * ncy + 1, np.int64)
    for i in range(n):
        cx[i] = min(int((x[i] - xmin) / cell), ncx - 1)
        cy[i] = min(int((y[i] - ymin) / cell), ncy - 1)
        start[cy[i] * ncx + cx[i] + 1] += 1
    for c in range(ncx * ncy):
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    member_id = np.empty(n, np.int64)  # agents in cell order, with contiguous coordinates
    member_x = np.empty(n)
    member_y = np.empty(n)
    for i in range(n):
        c = cy[i] * ncx + cx[i]
        member_id[fill[c]], member_x[fill[c]], member_y[fill[c]] = i, x[i], y[i]
        fill[c] += 1
    r2 = r_d * r_d
    partners = np.empty(n, np.int64)
    count = 0
    for a in range(n):
        k = 0
        xa, ya = x[a], y[a]
        for gy in range(max(cy[a] - 1, 0), min(cy[a] + 2, ncy)):
            for gx in range(max(cx[a] - 1, 0), min(cx[a] + 2, ncx)):
                c = gy * ncx + gx
                for j in range(start[c], start[c + 1]):
                    b = member_id[j]
                    if b <= a:
                        continue
                    dx, dy = member_x[j] - xa, member_y[j] - ya
                    if dx * dx + dy * dy > r2:
                        continue
                    if walls_block and not line_of_sight(walls, xa, ya, member_x[j], member_y[j]):
                        continue
                    pos = k  # insertion keeps the few partners of a sorted
                    while pos > 0 and partners[pos - 1] > b:
                        partners[pos] = partners[pos - 1]
                        pos -= 1
                    partners[pos] = b
                    k += 1
        for j in range(k):
            if count < len(out):
                out[count] = a * n + partners[j]
            count += 1
    return count


@njit(cache=True)
def new_keys(previous, current, out):
    """Keys of ``current`` not in ``previous`` (both sorted) into ``out``; returns the count."""
    i = m = 0
    for key in current:
        while i < len(previous) and previous[i] < key:
            i += 1
        if i == len(previous) or previous[i] != key:
            out[m] = key
            m += 1
    return m
