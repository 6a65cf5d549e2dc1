"""The leash: agents kept within R of a moving, localized leader (beacon-led exploration).

Model (docs/model.md, "The leash").  Steered insects and biobots respond to a stimulus
by walking towards it, imprecisely.  At every step t_k, before the agents decide, every
agent farther than the leash R from the beacon is *stimulated*:

* a stop ends at once (the stimulus wakes it; its moving state resumes);
* a random walker turns towards the beacon: heading = bearing + N(0, ``HEADING_ERROR``^2),
  its straight segment lasting at least this step;
* a wall in the way is followed round, as in a bug algorithm: a stimulated random walker
  with a wall within r_d straight towards the beacon starts wall following (the
  paper's WF, its offset the distance to the wall) in the direction it last followed a
  wall (each agent keeps a handedness, so it does not turn back at a corner); a stimulated wall follower leaves its wall (as the paper's
  WF exit) as soon as the way towards the beacon is clear for r_d, and not before (its
  exit timer waits).

Within R an agent moves by the paper's model unchanged.  Agents commanded to hold or
stop for good ignore the stimulus; commanded wall followers and random walkers keep
their behaviour (a pure random walker only turns towards the beacon).
"""

from __future__ import annotations

import math

from numba import njit

from ..log import S, WF
from .params import NATURAL, PURE_RW
from .motion import start_wall_following
from .walls import agent_kernel, line_of_sight, nearest_wall

RETURN_FRACTION = 0.5
"""A stimulated agent walks towards the beacon until it is within this share of the leash."""
HEADING_ERROR = 0.5
"""Standard deviation (rad, about 29 degrees) of a stimulated agent's heading about the bearing to the beacon."""


@njit(cache=True)
def steer(agents, stimulated, bx, by, leash, m, walls, rng):
    """Stimulate every agent farther than ``leash`` from the beacon at (bx, by), and keep
    stimulating it until it is within ``RETURN_FRACTION`` x leash (module docstring);
    ``stimulated`` (bool, one per agent) is that state.  Returns how many were stimulated."""
    n = 0
    for i in range(len(agents)):
        ag = agents[i]
        if ag['mode'] != NATURAL and ag['mode'] != PURE_RW:
            stimulated[i] = False
            continue
        dx, dy = bx - ag['x'], by - ag['y']
        dist = math.sqrt(dx * dx + dy * dy)
        if dist > leash:
            stimulated[i] = True
        elif dist <= RETURN_FRACTION * leash:
            stimulated[i] = False
        if stimulated[i]:
            stimulate(ag, dx / dist, dy / dist, m, walls, rng)
            n += 1
    return n


@agent_kernel
def stimulate(ag, ux, uy, m, walls, rng):
    """One stimulated agent; (ux, uy) is the unit bearing to the beacon."""
    moving = ag['state']
    stopped = moving == S
    if stopped:
        ag['stop_left'] = 1  # decide() resumes the moving state at this step
        moving = ag['resume_state']
    x, y = ag['x'], ag['y']
    facing = line_of_sight(walls, x, y, x + m.r_d * ux, y + m.r_d * uy)  # no wall within r_d towards the beacon
    if moving == WF:
        if ag['mode'] == NATURAL:  # leave at this step (decide()) if facing the beacon, else follow on
            ag['wf_left'] = 0 if facing else max(ag['wf_left'], 2)
        return
    if not facing and ag['mode'] == NATURAL:
        way = ag['wf_dir']
        start_wall_following(ag, m, nearest_wall(walls, x, y)[0], rng)
        ag['wf_dir'] = way  # round the same way as its last wall: no dithering at a corner
        if stopped:  # decide() resumes it, following the wall, with a fresh moving time
            ag['state'], ag['resume_state'] = S, WF
        return
    ag['heading'] = math.atan2(uy, ux) + rng.normal(0.0, HEADING_ERROR)
    ag['seg_left'] = max(ag['seg_left'], m.v_c * m.dt)
