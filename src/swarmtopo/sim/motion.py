"""The per-agent motion state machine (paper, "Bio-Inspired Mobility Model").

States RW (random walk), WF (wall following), S (stopped); numba kernels that loop
over agents and draw from a ``np.random.Generator`` (bit-identical to numpy, so a
kernel's ``.py_func`` gives the same run).  Time is discrete, t_k = k dt.  At each
step the simulator senses at p_k, applies commands, then :func:`step_swarm` decides
each agent's transitions at t_k (:func:`decide`) and moves it to p_{k+1}
(:func:`advance`).  A stop decided at t_stop and ended at t_resume therefore holds
the agent at one point on the closed interval [t_stop, t_resume].

The model and the project's choices (each with its reason):

* RW: speed v_c along straight segments of length Exp(l*), new heading U(0, 2 pi).
  A segment renews exactly where it ends, even mid-step (the step is split), so the
  free path is exactly Exp(l*), without a per-step overshoot bias.
* Wall detection: an *armed* RW agent within r_d of any wall (outer or obstacle)
  switches to WF, with a random direction (+1: wall on its right, -1: on its left)
  and an offset = its distance at detection, clipped below at a small minimum (see
  params).  An armed agent is > r_d from all walls when it moves, so its RW step
  (<= r_d / 4) needs no wall test.
* WF: speed v_p.  Each sub-step (<= offset / 2) moves along the tangent of the
  nearest wall point *of the trial position* (this turns at concave corners and
  rounds convex ones), then re-projects to the offset from the new nearest wall
  point.  Works for any polygon; in corridors narrower than twice the offset the
  agent dithers between the two walls until it leaves (a documented limitation).
* WF exit: after Exp(tau_exit) wall-following time (counted in WF steps, paused
  during stops) the agent leaves at theta ~ U[0, pi] from its direction of travel,
  turning into free space, and starts a fresh RW segment.
* Re-entry rule: an agent that left a wall is *disarmed*: it cannot start wall
  following until it has been farther than r_d from every wall (otherwise it would
  re-attach at once).  Disarmed and commanded pure-RW agents reflect specularly off
  walls instead (up to ``MAX_REFLECTIONS`` per move; a move that would end closer
  than WALL_EPS to a wall stops just short of it and the rest of the step is lost).
* Stops: moving time (RW or WF) to the next stop ~ Exp(tau_stop); a stop is short
  (prob. p_sh, Exp(tau_s)) or long (Exp(tau_l)); then the agent resumes exactly what
  it was doing (heading and remaining segment, or wall, direction, offset, exit
  timer).  All timers are counted in steps, n = max(1, ceil(D / dt)) for a duration
  D drawn from the exponential, so an observed duration is n dt and its survival
  function at grid points x = j dt equals the exponential one exactly.
* Order of decisions at t_k: a stop that ends resumes motion; then wall logic
  (WF exit, or detection / arming); then a stop may start (the timers stay exact).
  The status log gets one row per agent and step at most: its state after all of it.
* Invariant: every accepted position is inside the free space, farther than
  WALL_EPS from every wall; every move is checked against the listed walls unless
  the geometry above makes a crossing impossible.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ..log import RW, S, WF
from .params import HOLD, MIN_WALL_OFFSET_FRACTION, NATURAL, STATIC, MotionParams
from .walls import agent_kernel, first_hit, nearest_wall, path_is_clear

NEVER = 2**62
"""Timer value (steps) for an infinite mean time."""
MAX_REFLECTIONS = 3
"""Wall reflections tried within one move before the rest of the move is dropped."""
BACKOFF = 1e-4
"""Distance (mm) a reflecting agent stops short of the wall it hits."""


class Model(NamedTuple):
    """Scalar model parameters as the kernels see them (mm, s)."""

    v_c: float
    v_p: float
    l_star: float
    tau_stop: float
    p_sh: float
    tau_s: float
    tau_l: float
    tau_exit: float
    r_d: float
    dt: float
    min_offset: float


def make_model(motion: MotionParams, r_d: float, dt: float) -> Model:
    """Kernel parameters from the public dataclasses."""
    return Model(motion.v_c, motion.v_p, motion.l_star, motion.tau_stop, motion.p_sh, motion.tau_s,
                 motion.tau_l, motion.tau_exit, float(r_d), float(dt), MIN_WALL_OFFSET_FRACTION * r_d)


AGENT_DTYPE = np.dtype([
    ("x", np.float64), ("y", np.float64),   # position, mm
    ("heading", np.float64),                # RW heading, rad
    ("seg_left", np.float64),               # length left on the current RW segment, mm
    ("wf_offset", np.float64),              # wall-follow distance, mm
    ("move_left", np.int64),                # moving steps before the next natural stop
    ("stop_left", np.int64),                # steps left in the current natural stop
    ("wf_left", np.int64),                  # WF steps before leaving the wall
    ("state", np.int8),                     # RW / WF / S, as reported
    ("resume_state", np.int8),              # moving state to resume after a stop
    ("mode", np.int8),                      # command mode (params.BEHAVIOURS index)
    ("armed", np.int8),                     # 1: may start wall following
    ("wf_dir", np.int8),                    # +1 wall on the right, -1 wall on the left
    ("reported", np.int8),                  # last state written to the status log (-1 none)
], align=True)
"""Per-agent state, one record per agent.  A record (not a tuple of arrays) is what the
kernels pass around: passing it costs a pointer, where a tuple of 14 arrays costs 28
reference-count updates per call.  ``agents[i]`` is a view in numba and in numpy alike."""


def new_swarm(xy: np.ndarray, model: Model, rng: np.random.Generator) -> np.ndarray:
    """Agents at ``xy`` (N, 2), state RW, armed, random heading, fresh timers."""
    agents = blank_swarm(xy)
    init_swarm(agents, model, rng)
    return agents


def blank_swarm(xy: np.ndarray) -> np.ndarray:
    """Agent records at ``xy`` (N, 2): state RW, mode free, armed, nothing drawn yet."""
    agents = np.zeros(len(xy), AGENT_DTYPE)
    agents["x"], agents["y"] = xy[:, 0], xy[:, 1]
    agents["state"] = agents["resume_state"] = RW
    agents["mode"] = NATURAL
    agents["armed"] = 1
    agents["wf_dir"] = 1
    agents["reported"] = -1
    return agents


@njit(cache=True)
def init_swarm(agents, m, rng):
    """Draw each agent's heading, first segment and time to its first stop."""
    for i in range(len(agents)):
        ag = agents[i]
        ag['heading'] = rng.uniform(0.0, 2.0 * math.pi)
        ag['seg_left'] = rng.exponential(m.l_star)
        ag['move_left'] = draw_steps(rng, m.tau_stop, m.dt)


@agent_kernel
def draw_steps(rng, mean, dt):
    """Steps of an Exp(mean) duration D: max(1, ceil(D / dt)); NEVER if mean is inf."""
    if mean == np.inf:
        return NEVER
    return max(1, int(math.ceil(rng.exponential(mean) / dt)))


@agent_kernel
def draw_stop_steps(rng, m):
    """Steps of a stop: short (prob. p_sh, mean tau_s) or long (mean tau_l)."""
    if rng.random() < m.p_sh:
        return draw_steps(rng, m.tau_s, m.dt)
    return draw_steps(rng, m.tau_l, m.dt)


@njit(cache=True)
def step_swarm(agents, m, walls, rng, move, changed):
    """Decide every agent's transitions at t_k, then (if ``move``) move it to p_{k+1}.

    Agents whose state differs from the last reported one are written to ``changed``
    (and marked reported); returns how many.
    """
    n_changed = 0
    for i in range(len(agents)):
        ag = agents[i]
        decide(ag, m, walls, rng)
        if ag['state'] != ag['reported']:
            ag['reported'] = ag['state']
            changed[n_changed] = i
            n_changed += 1
        if move:
            advance(ag, m, walls, rng)
    return n_changed


@agent_kernel
def decide(ag, m, walls, rng):
    """State transitions of the agent at the current step (see module docstring)."""
    mode = ag['mode']
    if mode == HOLD or mode == STATIC:
        return
    if ag['state'] == S:
        ag['stop_left'] -= 1
        if ag['stop_left'] > 0:
            return
        ag['state'] = ag['resume_state']
        ag['move_left'] = draw_steps(rng, m.tau_stop, m.dt)
    if ag['state'] == WF:
        if mode == NATURAL and ag['wf_left'] <= 0:
            leave_wall(ag, m, walls, rng)
    elif ag['armed']:
        dist = nearest_wall(walls, ag['x'], ag['y'])[0]
        if dist <= m.r_d:
            start_wall_following(ag, m, dist, rng)
    elif mode == NATURAL and nearest_wall(walls, ag['x'], ag['y'])[0] > m.r_d:
        ag['armed'] = 1
    if ag['move_left'] <= 0:
        ag['resume_state'] = ag['state']
        ag['state'] = S
        ag['stop_left'] = draw_stop_steps(rng, m)


@agent_kernel
def start_wall_following(ag, m, dist, rng):
    """The agent detected a wall at distance ``dist``: WF, random direction, exit timer."""
    ag['state'] = WF
    ag['wf_dir'] = 1 if rng.random() < 0.5 else -1
    ag['wf_offset'] = max(dist, m.min_offset)
    ag['wf_left'] = draw_steps(rng, m.tau_exit, m.dt)


@agent_kernel
def wall_frame(walls, x, y, direction):
    """Unit normal (wall -> point) and unit tangent of travel at the nearest wall point."""
    dist, qx, qy, _ = nearest_wall(walls, x, y)
    nx, ny = (x - qx) / dist, (y - qy) / dist
    return nx, ny, direction * ny, -direction * nx


@agent_kernel
def leave_wall(ag, m, walls, rng):
    """The agent leaves its wall at theta ~ U[0, pi] from its travel direction: disarmed RW.

    A WF agent is always within the grid's reach of its wall (its distance stays
    <= offset + one step), so the nearest wall point exists.
    """
    nx, ny, tx, ty = wall_frame(walls, ag['x'], ag['y'], ag['wf_dir'])
    theta = rng.uniform(0.0, math.pi)
    ag['heading'] = math.atan2(math.cos(theta) * ty + math.sin(theta) * ny,
                               math.cos(theta) * tx + math.sin(theta) * nx)
    ag['seg_left'] = rng.exponential(m.l_star)
    ag['armed'] = 0
    if ag['state'] == S:
        ag['resume_state'] = RW
    else:
        ag['state'] = RW


@agent_kernel
def advance(ag, m, walls, rng):
    """Move the agent by one step in its current state; count the moving time."""
    if ag['state'] == S:
        return
    if ag['state'] == RW:
        random_walk(ag, m, walls, rng)
    else:
        follow_wall(ag, m, walls)
        ag['wf_left'] -= 1
    ag['move_left'] -= 1


@agent_kernel
def random_walk(ag, m, walls, rng):
    """One RW step of length v_c dt; segments renew exactly where they end."""
    remaining = m.v_c * m.dt
    while remaining > 0.0:
        d = min(remaining, ag['seg_left'])
        if ag['armed']:
            ag['x'] += d * math.cos(ag['heading'])
            ag['y'] += d * math.sin(ag['heading'])
        else:
            reflecting_move(ag, walls, d)
        ag['seg_left'] -= d
        remaining -= d
        if ag['seg_left'] <= 0.0:
            ag['heading'] = rng.uniform(0.0, 2.0 * math.pi)
            ag['seg_left'] = rng.exponential(m.l_star)


@agent_kernel
def reflecting_move(ag, walls, length):
    """Move the agent by ``length`` along its heading, reflecting specularly off walls."""
    x, y, h = ag['x'], ag['y'], ag['heading']
    left = length
    for _ in range(MAX_REFLECTIONS):
        cx, cy = math.cos(h), math.sin(h)
        ex, ey = x + left * cx, y + left * cy
        if path_is_clear(walls, x, y, ex, ey):
            x, y = ex, ey
            break
        u, k = first_hit(walls, x, y, ex, ey)
        if k < 0:  # no crossing: the move would end within WALL_EPS of wall k
            u = 1.0
            k = nearest_wall(walls, ex, ey)[3]
        go = u * left - BACKOFF
        if go > 0.0 and path_is_clear(walls, x, y, x + go * cx, y + go * cy):
            x, y = x + go * cx, y + go * cy
            left -= go
        wx, wy = walls.segs[k, 2] - walls.segs[k, 0], walls.segs[k, 3] - walls.segs[k, 1]
        norm = math.sqrt(wx * wx + wy * wy)
        wx, wy = wx / norm, wy / norm
        along = cx * wx + cy * wy
        h = math.atan2(2.0 * along * wy - cy, 2.0 * along * wx - cx)
    ag['x'], ag['y'], ag['heading'] = x, y, h


@agent_kernel
def follow_wall(ag, m, walls):
    """One WF step of length v_p dt at the agent's offset, in sub-steps <= offset / 2."""
    offset = ag['wf_offset']
    total = m.v_p * m.dt
    n_sub = max(1, int(math.ceil(total / (0.5 * offset))))
    s = total / n_sub
    x, y, direction = ag['x'], ag['y'], ag['wf_dir']
    for _ in range(n_sub):
        _, _, tx, ty = wall_frame(walls, x, y, direction)
        _, _, tx, ty = wall_frame(walls, x + s * tx, y + s * ty, direction)
        bx, by = x + s * tx, y + s * ty
        if not path_is_clear(walls, x, y, bx, by):
            break
        dist, qx, qy, _ = nearest_wall(walls, bx, by)
        gx, gy = qx + offset * (bx - qx) / dist, qy + offset * (by - qy) / dist
        if path_is_clear(walls, bx, by, gx, gy):
            x, y = gx, gy
        else:
            x, y = bx, by
    ag['x'], ag['y'] = x, y
