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

import math
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


def _positive_fields(params, *names: str, allow_inf: bool = False) -> None:
    """Check (and store as float) each named field of a frozen parameter dataclass: a
    positive number, named ``Class.field`` in the error."""
    for name in names:
        value = positive(f"{type(params).__name__}.{name}", getattr(params, name), allow_inf=allow_inf)
        object.__setattr__(params, name, value)


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
        _positive_fields(self, "v_c", "l_star", "v_p", "tau_s", "tau_l")
        _positive_fields(self, "tau_stop", "tau_exit", allow_inf=True)
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


@dataclass(frozen=True)
class Billiard:
    """Billiard motion: straight lines at a constant speed, specular reflection off walls.

    The only randomness is each agent's first heading.  Cheap robots that drive until
    they bump move like this.

    Attributes
    ----------
    speed : float
        v, mm/s.
    """

    speed: float = 15.0
    name = "billiard"

    def __post_init__(self):
        _positive_fields(self, "speed")


@dataclass(frozen=True)
class RunAndTumble:
    """Run-and-tumble motion (E. coli, Kilobots): straight runs at speed v ended by
    instantaneous tumbles at rate lambda to a uniform new heading; walls reflect.

    Runs last Exp(1 / lambda) (mean run length v / lambda), and in open space the mean
    squared displacement is MSD(t) = 2 v^2 / lambda^2 (lambda t - 1 + exp(-lambda t)).

    Attributes
    ----------
    speed : float
        v, mm/s.
    tumble_rate : float
        lambda, tumbles per second.
    """

    speed: float = 15.0
    tumble_rate: float = 0.5
    name = "run-and-tumble"

    def __post_init__(self):
        _positive_fields(self, "speed", "tumble_rate")


@dataclass(frozen=True)
class Brownian:
    """Brownian (diffusive) motion: independent Gaussian increments, MSD(t) = 4 D t in
    open space; walls reflect.

    Each time step dt is walked in ``BROWNIAN_SUBSTEPS`` Gaussian sub-steps of variance
    2 D dt / n per axis, each cut into straight pieces of at most r_d / 4 reflected off
    the walls, so a wall is never crossed whatever the increment.

    Attributes
    ----------
    diffusion : float
        D, mm^2/s.
    """

    diffusion: float = 225.0
    name = "brownian"

    def __post_init__(self):
        _positive_fields(self, "diffusion")


@dataclass(frozen=True)
class LevyWalk:
    """Lévy walk: straight steps at speed v with heavy-tailed lengths, P(L > l) =
    (l / l_0)^(1 - mu) for l >= l_0, then a uniform new heading; walls reflect (a
    step goes on after a reflection until its length is walked).

    1 < mu <= 3: mu < 2 has steps of infinite mean (ballistic-like), mu -> 3 tends to
    diffusion; in between the MSD grows like t^(4 - mu) (superdiffusive).

    Attributes
    ----------
    speed : float
        v, mm/s.
    exponent : float
        mu, the step-length exponent (density ~ l^-mu).
    min_step : float
        l_0, the shortest step, mm.
    """

    speed: float = 15.0
    exponent: float = 2.0
    min_step: float = 10.0
    name = "levy"

    def __post_init__(self):
        _positive_fields(self, "speed", "min_step", "exponent")
        if not 1.0 < self.exponent <= 3.0:
            raise InputError("LevyWalk.exponent must be in (1, 3]", value=self.exponent)


@dataclass(frozen=True)
class Flocking:
    """Vicsek flocking: constant speed v; at every time step each moving agent takes the
    mean heading of the moving agents within the alignment radius (itself included)
    plus noise U[-eta/2, eta/2]; walls reflect.  Walls do not hide neighbours.

    The alignment happens once per time step dt (Vicsek et al. 1995, with their Delta t
    = dt).  Low noise orders the swarm (order parameter phi = |mean unit velocity| -> 1),
    eta = 2 pi leaves it disordered (phi ~ 1 / sqrt(N)).

    Attributes
    ----------
    speed : float
        v, mm/s.
    radius : float
        Alignment radius, mm.
    noise : float
        eta in [0, 2 pi], rad.
    """

    speed: float = 15.0
    radius: float = 30.0
    noise: float = 1.0
    name = "flocking"

    def __post_init__(self):
        _positive_fields(self, "speed", "radius")
        eta = non_negative("Flocking.noise", self.noise)
        if eta > 2 * math.pi:
            raise InputError("Flocking.noise must be in [0, 2 pi] rad", value=self.noise)
        object.__setattr__(self, "noise", eta)


BROWNIAN_SUBSTEPS = 4
"""Gaussian sub-steps per time step of :class:`Brownian` motion."""

WALKERS = (Billiard, RunAndTumble, Brownian, LevyWalk, Flocking)
"""Motion models beside the paper's cockroach (:class:`MotionParams`)."""
MOTION_MODELS: dict[str, type] = {"cockroach": MotionParams, **{m.name: m for m in WALKERS}}
"""Every motion model by the name the CLI, sweeps and meta.json use."""


def motion_name(motion) -> str:
    """The name of a motion model instance (``"cockroach"`` for :class:`MotionParams`)."""
    return "cockroach" if isinstance(motion, MotionParams) else motion.name


def top_speed(motion, dt: float) -> float:
    """The farthest an agent moves in one time step at the model's speed, mm (for a
    Brownian agent its root-mean-square displacement sqrt(4 D dt))."""
    if isinstance(motion, MotionParams):
        return max(motion.v_c, motion.v_p) * dt
    if isinstance(motion, Brownian):
        return math.sqrt(4.0 * motion.diffusion * dt)
    return motion.speed * dt


MOTION_OPTIONS: dict[str, str] = {"speed": "speed", "tumble_rate": "tumble_rate", "diffusion": "diffusion",
                                  "levy_exponent": "exponent", "levy_min_step": "min_step",
                                  "align_radius": "radius", "noise": "noise"}
"""Option name (``simulate --levy-exponent``, a sweep's ``[swarm] levy_exponent``) -> the
walker field it sets."""


def make_motion(name: str, options: dict[str, float | None] | None = None):
    """The motion model ``name`` (a key of :data:`MOTION_MODELS`) with the given options
    (keys of :data:`MOTION_OPTIONS`; None leaves a default).

    Raises
    ------
    InputError
        For an unknown model, or an option the model does not have.
    """
    if name not in MOTION_MODELS:
        raise InputError(f"unknown motion model; expected one of {', '.join(MOTION_MODELS)}", value=name)
    model = MOTION_MODELS[name]
    given = {k: v for k, v in (options or {}).items() if v is not None}
    fields = {f for f in getattr(model, "__dataclass_fields__", {})}
    kwargs = {}
    for option, value in given.items():
        field = MOTION_OPTIONS.get(option)
        if field is None or field not in fields or model is MotionParams:
            has = [o for o, f in MOTION_OPTIONS.items() if f in fields and model is not MotionParams]
            raise InputError(f"{option.replace('_', '-')} is not an option of {name} motion"
                             + (f" (it has {', '.join(o.replace('_', '-') for o in has)})" if has else
                                " (the cockroach's parameters are the paper's defaults)"), value=value)
        kwargs[field] = value
    return model(**kwargs)
