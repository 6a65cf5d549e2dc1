"""Parameters of the swarm simulator: motion (paper defaults), sensing, commands.

The motion defaults are the paper's parameter table (commented out in the LaTeX,
taken from Jeanson et al. 2005 / Dirafzoon et al. 2013): the same stop process in
the central (RW) and peripheral (WF) zones.  Project choices, one line each:

* ``tau_exit = 10 s`` -- the paper names tau_exit but gives no value; 10 s makes one
  wall visit cover v_p * tau_exit = 100 mm (a fifth of a 500 mm wall), so agents
  explore walls yet roam the interior most of the time (measured in the 500 mm
  one-hole arena: 57 % RW, 35 % WF, 8 % S).
* ``r_d = 30 mm`` -- equal to l*, the scale of the paper's arenas (500 mm, holes of a
  few r_d) and of the feasibility study the project's defaults were tuned on.
* ``dt = 0.1 s`` (in :func:`~swarmtopo.sim.simulate`) -- an agent moves v_c dt = 1.5 mm
  = r_d / 20 per step, far inside the resolution rule max(v_c, v_p) dt <= r_d / 4 (two
  agents closing at 2 v_c cannot cross a contact disk of diameter 2 r_d unseen), and
  stop durations are resolved to 0.1 s against tau_s = 0.5 s.
* wall-follow offset -- an agent follows a wall at the distance it had when it
  detected it (<= r_d, the antenna reach), clipped below at ``MIN_WALL_OFFSET_FRACTION
  * r_d`` = 3 mm so the offset stays far above the numerical wall clearance and the
  sub-steps along a wall stay few.

Times are in seconds, lengths in millimetres.  ``inf`` is allowed for ``tau_stop``
and ``tau_exit`` and means "never" (no natural stops, wall following never exits).
"""

from __future__ import annotations

import operator
from dataclasses import dataclass

from .._validate import fraction, non_negative, positive
from ..errors import InputError

BEHAVIOURS: tuple[str, ...] = ("free", "RW", "WF", "S", "static")
"""Command behaviours; the index is the agent *mode* code used by the kernels.

``free`` the natural RW/WF/S model; ``RW`` random walk only (walls reflect);
``WF`` wall following that never exits; ``S`` held stopped until the next command;
``static`` stopped for good (a static node of the hybrid network)."""
NATURAL, PURE_RW, PURE_WF, HOLD, STATIC = range(5)

MIN_WALL_OFFSET_FRACTION = 0.1
"""Wall-follow offset lower bound, as a fraction of r_d (see module docstring)."""


@dataclass(frozen=True)
class MotionParams:
    """Bio-inspired mobility model (paper, "Bio-Inspired Mobility Model").

    Attributes
    ----------
    v_c : float
        Random-walk (RW) speed, mm/s.
    l_star : float
        l*, mean length of the straight RW segments (exponential), mm.
    v_p : float
        Wall-following (WF) speed, mm/s.
    tau_stop : float
        Mean moving time (RW or WF) before a stop, s (exponential; inf = never).
    p_sh : float
        Probability that a stop is short.
    tau_s, tau_l : float
        Mean durations of short and long stops, s (exponential).
    tau_exit : float
        Mean wall-following time before leaving the wall, s (exponential; the timer
        pauses during stops; inf = never).
    """

    v_c: float = 15.0
    l_star: float = 30.0
    v_p: float = 10.0
    tau_stop: float = 20.0
    p_sh: float = 0.93
    tau_s: float = 0.5
    tau_l: float = 20.0
    tau_exit: float = 10.0

    def __post_init__(self):
        for name in ("v_c", "l_star", "v_p", "tau_s", "tau_l"):
            object.__setattr__(self, name, positive(f"MotionParams.{name}", getattr(self, name)))
        for name in ("tau_stop", "tau_exit"):
            object.__setattr__(self, name, positive(f"MotionParams.{name}", getattr(self, name), allow_inf=True))
        object.__setattr__(self, "p_sh", fraction("MotionParams.p_sh", self.p_sh))


@dataclass(frozen=True)
class SensingParams:
    """Sensing model (paper, "Sensing and Communication", "Encounter Tracking").

    Attributes
    ----------
    r_d : float
        Detection radius, mm: agents within r_d of each other are in contact, and an
        agent within r_d of a wall detects it.
    walls_block : bool
        A wall between two agents hides them from each other.
    log_initial_contacts : bool
        Log pairs already in contact at t = 0 as events at t = 0.
    """

    r_d: float = 30.0
    walls_block: bool = True
    log_initial_contacts: bool = True

    def __post_init__(self):
        object.__setattr__(self, "r_d", positive("SensingParams.r_d", self.r_d))
        for name in ("walls_block", "log_initial_contacts"):
            if not isinstance(getattr(self, name), bool):
                raise InputError(f"SensingParams.{name} must be True or False", value=getattr(self, name))


@dataclass(frozen=True)
class Command:
    """A base-station command: at ``time`` the targeted agents switch behaviour.

    Exactly one of ``fraction`` (a random fraction of the whole swarm, drawn with the
    simulation's rng; ``round(fraction * N)`` agents) or ``agents`` (explicit IDs).
    Agents already static ignore later commands.

    Attributes
    ----------
    time : float
        When (s); applied at the first time step t_k >= time.
    behaviour : str
        One of ``"free"``, ``"RW"``, ``"WF"``, ``"S"``, ``"static"`` (see BEHAVIOURS).
    fraction : float or None
        Fraction of the swarm in [0, 1].
    agents : tuple of int or None
        Agent IDs 0 .. N-1 (range checked by :func:`~swarmtopo.sim.simulate`).
    """

    time: float
    behaviour: str
    fraction: float | None = None
    agents: tuple[int, ...] | None = None

    def __post_init__(self):
        object.__setattr__(self, "time", non_negative("Command.time", self.time))
        if self.behaviour not in BEHAVIOURS:
            raise InputError(f"unknown command behaviour; expected one of {', '.join(BEHAVIOURS)}",
                             value=self.behaviour)
        if (self.fraction is None) == (self.agents is None):
            raise InputError("a Command needs exactly one of fraction= or agents=",
                             value=f"fraction={self.fraction}, agents={self.agents}")
        if self.fraction is not None:
            object.__setattr__(self, "fraction", fraction("Command.fraction", self.fraction))
        else:
            ids = []
            for i in self.agents:
                try:
                    if isinstance(i, bool):
                        raise TypeError
                    ids.append(operator.index(i))
                except TypeError:
                    raise InputError("Command.agents must hold integer agent IDs", value=i) from None
            object.__setattr__(self, "agents", tuple(ids))

    @property
    def mode(self) -> int:
        """Kernel mode code of the behaviour."""
        return BEHAVIOURS.index(self.behaviour)
