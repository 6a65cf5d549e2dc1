"""Motion models beside the cockroach's: billiard, run-and-tumble, Brownian, Lévy walk,
flocking (:mod:`.params` documents each model and its parameters).

Every model walks in the agent records of :mod:`.motion` (``heading``, ``seg_left``)
and reflects specularly off every wall with :func:`.motion.reflecting_move`, in
straight pieces of at most ``max_piece`` (the simulator's wall grid lists every wall
within that reach).  None of them wall-follows or stops on its own, so an agent
reports RW while it moves and S while a command holds it (``"S"`` or ``"static"``);
``"free"`` and ``"RW"`` both mean the model's own motion.  Draws come from the run's
one ``np.random.Generator``, so a kernel's ``.py_func`` gives the same run.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ..log import RW, S
from .motion import reflecting_move
from .params import (BROWNIAN_SUBSTEPS, HOLD, STATIC, Billiard, Brownian, Flocking, LevyWalk, MotionParams,
                     RunAndTumble)
from .walls import agent_kernel

BILLIARD, RUN_AND_TUMBLE, BROWNIAN, LEVY, FLOCKING = range(1, 6)
_KINDS = {Billiard: BILLIARD, RunAndTumble: RUN_AND_TUMBLE, Brownian: BROWNIAN, LevyWalk: LEVY, Flocking: FLOCKING}


class Walker(NamedTuple):
    """A walker model's parameters as the kernels see them (mm, s)."""

    kind: int
    speed: float
    mean_run: float     # run-and-tumble: v / lambda
    exponent: float     # Lévy: mu
    min_step: float     # Lévy: l_0
    diffusion: float    # Brownian: D
    radius: float       # flocking: alignment radius
    noise: float        # flocking: eta
    dt: float
    max_piece: float


def make_walker(motion, dt: float, max_piece: float) -> Walker:
    """Kernel parameters of a walker model (one of :data:`.params.WALKERS`)."""
    speed = getattr(motion, "speed", 0.0)
    return Walker(_KINDS[type(motion)], float(speed),
                  speed / motion.tumble_rate if isinstance(motion, RunAndTumble) else 0.0,
                  getattr(motion, "exponent", 0.0), getattr(motion, "min_step", 0.0),
                  getattr(motion, "diffusion", 0.0), getattr(motion, "radius", 0.0),
                  getattr(motion, "noise", 0.0), float(dt), float(max_piece))


def command_model(motion, r_d: float, dt: float) -> MotionParams:
    """The cockroach parameters the commands (:mod:`.commands`) and arena changes see for a
    walker: no natural stops, no wall exits, so they draw nothing."""
    speed = getattr(motion, "speed", r_d / (4 * dt))
    return MotionParams(v_c=speed, v_p=speed, tau_stop=np.inf, tau_exit=np.inf)


@njit(cache=True)
def init_walkers(agents, w, rng):
    """Each agent's first heading (uniform) and first run or step length."""
    for i in range(len(agents)):
        ag = agents[i]
        ag['heading'] = rng.uniform(0.0, 2.0 * math.pi)
        ag['seg_left'] = draw_run(rng, w)


@agent_kernel
def draw_run(rng, w):
    """Length of a fresh straight run, mm: Exp(v / lambda) (run-and-tumble), Pareto
    l_0 U^(-1 / (mu - 1)) (Lévy), inf (billiard, flocking, Brownian: never renewed)."""
    if w.kind == RUN_AND_TUMBLE:
        return rng.exponential(w.mean_run)
    if w.kind == LEVY:
        return w.min_step * (1.0 - rng.random()) ** (-1.0 / (w.exponent - 1.0))
    return np.inf


@njit(cache=True)
def step_walkers(agents, w, walls, rng, move, changed):
    """Report state changes at t_k, then (if ``move``) move every agent to p_{k+1}.

    A held agent (mode S or static) reports S and stays; any other reports RW.  Agents
    whose reported state changed are written to ``changed``; returns how many.
    """
    n_changed = 0
    for i in range(len(agents)):
        ag = agents[i]
        ag['state'] = S if ag['mode'] == HOLD or ag['mode'] == STATIC else RW
        if ag['state'] != ag['reported']:
            ag['reported'] = ag['state']
            changed[n_changed] = i
            n_changed += 1
    if not move:
        return n_changed
    if w.kind == FLOCKING:
        align(agents, w, rng)
    for i in range(len(agents)):
        ag = agents[i]
        if ag['state'] == S:
            continue
        if w.kind == BROWNIAN:
            diffuse(ag, w, walls, rng)
        else:
            run(ag, w, walls, rng)
    return n_changed


@agent_kernel
def reflect_along(ag, walls, length, max_piece):
    """Move ``length`` mm along the heading in pieces of at most ``max_piece``, reflecting."""
    while length > 0.0:
        piece = min(length, max_piece)
        reflecting_move(ag, walls, piece)
        length -= piece


@agent_kernel
def run(ag, w, walls, rng):
    """One step of length v dt along straight runs; a run that ends mid-step renews there."""
    remaining = w.speed * w.dt
    while remaining > 0.0:
        d = min(remaining, ag['seg_left'])
        reflect_along(ag, walls, d, w.max_piece)
        ag['seg_left'] -= d
        remaining -= d
        if ag['seg_left'] <= 0.0:
            ag['heading'] = rng.uniform(0.0, 2.0 * math.pi)
            ag['seg_left'] = draw_run(rng, w)


@agent_kernel
def diffuse(ag, w, walls, rng):
    """One time step of Brownian motion: BROWNIAN_SUBSTEPS Gaussian increments of variance
    2 D dt / n per axis, each walked straight and reflected off walls."""
    sigma = math.sqrt(2.0 * w.diffusion * w.dt / BROWNIAN_SUBSTEPS)
    for _ in range(BROWNIAN_SUBSTEPS):
        dx, dy = rng.normal(0.0, sigma), rng.normal(0.0, sigma)
        length = math.sqrt(dx * dx + dy * dy)
        if length > 0.0:
            ag['heading'] = math.atan2(dy, dx)
            reflect_along(ag, walls, length, w.max_piece)


@njit(cache=True)
def align(agents, w, rng):
    """Vicsek update of every moving agent's heading: the mean heading of the moving
    agents within ``w.radius`` (itself included) plus U[-eta/2, eta/2].

    Neighbours are found on a grid of cells of side ``radius`` (agents sorted by cell
    key, a binary search per neighbouring cell), so a step costs O(N log N) for a
    swarm of bounded density."""
    n = len(agents)
    moving = np.empty(n, np.int64)
    m = 0
    for i in range(n):
        if agents[i]['state'] != S:
            moving[m] = i
            m += 1
    if m == 0:
        return
    moving = moving[:m]
    x = np.empty(m)
    y = np.empty(m)
    for j in range(m):
        x[j] = agents[moving[j]]['x']
        y[j] = agents[moving[j]]['y']
    x0, y0, cell = x.min(), y.min(), w.radius
    cx = np.empty(m, np.int64)
    cy = np.empty(m, np.int64)
    for j in range(m):
        cx[j] = int((x[j] - x0) / cell)
        cy[j] = int((y[j] - y0) / cell)
    width = cx.max() + 3
    key = (cy + 1) * width + (cx + 1)
    order = np.argsort(key, kind="mergesort")
    sorted_key = key[order]
    r2 = w.radius * w.radius
    headings = np.empty(m)
    for j in range(m):
        headings[j] = agents[moving[j]]['heading']
    new = np.empty(m)
    for j in range(m):
        sx, sy = 0.0, 0.0
        for oy in range(-1, 2):
            for ox in range(-1, 2):
                k = key[j] + oy * width + ox
                lo = np.searchsorted(sorted_key, k)
                hi = np.searchsorted(sorted_key, k, side="right")
                for q in range(lo, hi):
                    o = order[q]
                    ddx, ddy = x[o] - x[j], y[o] - y[j]
                    if ddx * ddx + ddy * ddy <= r2:
                        sx += math.cos(headings[o])
                        sy += math.sin(headings[o])
        new[j] = math.atan2(sy, sx) + w.noise * (rng.random() - 0.5)
    for j in range(m):
        agents[moving[j]]['heading'] = new[j]
