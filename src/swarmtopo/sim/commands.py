"""Base-station commands: switch the behaviour of chosen agents (the hybrid network).

As in the paper's hybrid network and the authors' earlier switching controller, the
base station can order agents to random-walk only, to wall-follow, to stop, to stop
for good (static nodes) or to go back to the natural model.  Semantics (project
choices, with reasons):

* ``"RW"``: random walk only -- walls reflect, no wall following; a wall-following
  agent leaves its wall at once by the natural exit rule (it must leave somehow; the
  exit rule is the model's own way).  Natural stops still happen.
* ``"WF"``: wall following that never exits; an RW agent walks until it finds a wall
  (it is armed at once, whatever the re-entry rule said).  Natural stops still happen.
* ``"S"``: held stopped until the next command, which resumes what the agent was doing
  (a natural stop in progress is dropped; the time to the next stop is drawn afresh).
* ``"static"``: stopped for good; the agent is listed in ``log.static_agent`` with the
  time step the command was applied at, and ignores every later command.
* ``"free"``: back to the natural model; a wall follower gets a fresh exit timer
  (exponential, so this is the natural law), a pure-RW agent re-arms once it is
  farther than r_d from every wall.

A status row is written only when an agent's reported state (RW / WF / S) changes.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..errors import InputError
from ..log import S, WF
from .motion import draw_steps, leave_wall
from .params import HOLD, NATURAL, PURE_RW, PURE_WF, STATIC, Command


def resolve_agents(command: Command, n_agents: int, rng: np.random.Generator) -> np.ndarray:
    """Sorted unique agent IDs a command targets (a random fraction draws from ``rng``)."""
    if command.fraction is not None:
        k = int(round(command.fraction * n_agents))
        return np.sort(rng.choice(n_agents, size=k, replace=False)).astype(np.int64)
    return np.unique(np.asarray(command.agents, dtype=np.int64))


def check_command_agents(commands, n_agents: int) -> None:
    """Raise InputError if a command names an agent outside 0 .. n_agents-1."""
    for c in commands:
        for i in c.agents or ():
            if not 0 <= i < n_agents:
                raise InputError(f"command at t={c.time:g} s names agent {i}, but agents are 0..{n_agents - 1}",
                                 value=i)


@njit(cache=True)
def apply_command(agents, m, walls, rng, targets, mode):
    """Switch agents ``targets`` to command ``mode`` (see module docstring)."""
    for i in targets:
        ag = agents[i]
        old = ag['mode']
        if old == STATIC:
            continue
        if old == HOLD and mode != HOLD and mode != STATIC:
            ag['state'] = ag['resume_state']
            ag['move_left'] = draw_steps(rng, m.tau_stop, m.dt)
        ag['mode'] = mode
        on_wall = ag['state'] == WF or (ag['state'] == S and ag['resume_state'] == WF)
        if mode == HOLD or mode == STATIC:
            if ag['state'] != S:
                ag['resume_state'] = ag['state']
                ag['state'] = S
        elif mode == PURE_RW:
            ag['armed'] = 0
            if on_wall:
                leave_wall(ag, m, walls, rng)
        elif mode == PURE_WF:
            ag['armed'] = 1
        elif mode == NATURAL and on_wall:
            ag['wf_left'] = draw_steps(rng, m.tau_exit, m.dt)
