"""What the swarm does when its arena changes (:class:`~swarmtopo.changing.ChangingArena`).

At a change time the simulator rebuilds the walls, then :func:`arena_changed`:

1. moves every agent that is not in the new free space with a clearance above
   ``WALL_EPS`` (it stood where an obstacle appeared) to the nearest free point:
   the nearest point q of the free space, then ``STEP_IN`` mm past it along the
   direction from the agent to q, or as far as fits (a tenth at a time); an agent for
   which no such point is free is put at the free point nearest it among a fixed
   grid of candidates (never seen in practice; no random draw, so runs stay
   reproducible);
2. makes every wall follower (moving or stopped) whose wall is gone -- no wall within
   its offset plus ``2 v_p dt`` -- a random walker, disarmed as after leaving a wall,
   its heading kept.

Agents keep every other state and timer.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.ops import nearest_points

from ..arena import Arena
from ..log import RW, S, WF
from .walls import WALL_EPS, nearest_wall

STEP_IN = 1.0
"""How far (mm) past the nearest free point an agent moved out of an obstacle is put."""


def arena_changed(agents: np.ndarray, free: Arena, walls, model) -> int:
    """Apply a change of the free space to the swarm (module docstring); returns how
    many agents were moved out of obstacles."""
    x, y = agents["x"], agents["y"]
    moved = np.flatnonzero(~clear_of_walls(free, x, y))
    for i in moved:
        agents["x"][i], agents["y"][i] = _nearest_free(free, float(x[i]), float(y[i]))
    for i in range(len(agents)):
        following = agents["state"][i] == WF or (agents["state"][i] == S and agents["resume_state"][i] == WF)
        if not following:
            continue
        dist = nearest_wall(walls, float(agents["x"][i]), float(agents["y"][i]))[0]
        if dist > agents["wf_offset"][i] + 2 * model.v_p * model.dt:
            if agents["state"][i] == S:
                agents["resume_state"][i] = RW
            else:
                agents["state"][i] = RW
            agents["armed"][i] = 0
            agents["seg_left"][i] = model.l_star
    return int(len(moved))


def _nearest_free(free: Arena, x: float, y: float) -> tuple[float, float]:
    """The free point nearest (x, y), ``STEP_IN`` (or less) inside the free space."""
    point = shapely.Point(x, y)
    q = nearest_points(free.geometry, point)[0]
    dx, dy = q.x - x, q.y - y
    norm = float(np.hypot(dx, dy))
    if norm > 0:
        step = STEP_IN
        while step > 100 * WALL_EPS:
            cx, cy = q.x + step * dx / norm, q.y + step * dy / norm
            if clear_of_walls(free, np.array([cx]), np.array([cy]))[0]:
                return cx, cy
            step /= 10
    xmin, ymin, xmax, ymax = free.bounds
    gx, gy = np.meshgrid(np.linspace(xmin, xmax, 101), np.linspace(ymin, ymax, 101))
    gx, gy = gx.ravel(), gy.ravel()
    k = int(np.argmin(np.where(clear_of_walls(free, gx, gy), np.hypot(gx - x, gy - y), np.inf)))
    return float(gx[k]), float(gy[k])


def clear_of_walls(free: Arena, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Whether each point is inside the free space, more than 2 ``WALL_EPS`` from every wall."""
    ok = free.contains(x, y)
    ok[ok] = free.distance_to_boundary(x[ok], y[ok]) > 2 * WALL_EPS
    return ok
