"""Simulate a swarm in an arena and record what a base station would receive.

Time steps t_k = k dt (rounded to 9 decimals), k = 0 .. K, K = round(duration / dt).
At each step:

1. sense at positions p_k: contacts that start now become events [t_k, a, b];
2. apply the commands with time <= t_k not yet applied, then decide each agent's
   state transitions at t_k (status rows get time t_k);
3. move every agent to p_{k+1} (not after the last step).

Agents start uniformly at random in the free space (``arena.sample_uniform``), in
state RW, with a random heading.  The status log has a row at t = 0 for every agent
(its state after the decisions at t = 0, so an agent born within r_d of a wall starts
as WF) and then a row whenever its state changes.  Every random draw comes from the
one ``np.random.Generator`` made from ``rng``: the same seed gives byte-identical
logs, and the pure-Python kernels (:func:`interpreted_kernels`) give the same run.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from numba.core.registry import CPUDispatcher

from .. import __version__
from .._validate import fraction, non_negative, positive, positive_int
from ..arena import Arena
from ..beacon import BeaconTrack
from ..changing import ChangingArena
from ..errors import InputError
from .._json import jsonable
from ..log import LOG_FORMAT, EncounterLog, state_labels
from . import changes as _changes
from . import leash as _leash
from . import commands as _commands
from . import motion as _motion
from . import sensing as _sensing
from . import walkers as _walkers
from . import walls as _walls
from .params import STATIC, WALKERS, Brownian, Command, MotionParams, SensingParams, motion_name, top_speed

TIME_DECIMALS = 9
MAX_AGENTS = 100_000
"""Most agents a run may have: 500 times the demo's swarm."""
MAX_AGENT_STEPS = 1e10
"""Most agent-steps (agents x duration / dt) a run may take: 10,000 times the accuracy
benchmark's largest run (800 agents x 120 s at dt = 0.1 s), hours of computing."""
DT = 0.1
"""Default time step of :func:`simulate`, s."""
DURATION_TOLERANCE = 1e-9
"""Relative distance from a whole number of time steps within which a duration is
that number of steps (30 s / 0.1 s = 299.99999999999994 steps is 300)."""


@dataclass
class Simulation:
    """Result of :func:`simulate`.

    Attributes
    ----------
    log : EncounterLog
        What the base station receives (agent IDs 0 .. N-1).
    truth : dict of str to ndarray or None
        Ground truth per event, same order as ``log.t / log.a / log.b``: keys ``t, a,
        b, xa, ya, xb, yb`` (``xa, ya`` = position of agent ``log.a``, mm).
    trajectories : dict of str to ndarray or None
        Samples every ``trajectory_every`` s (a multiple of dt, from t = 0): keys ``t,
        agent, x, y, state`` (int8 code of STATES), ordered by (t, agent).  ``state`` is
        the state decided at t, which governs the move from t to t + dt.
    arena : Arena
        The arena simulated.
    """

    log: EncounterLog
    truth: dict[str, np.ndarray] | None
    trajectories: dict[str, np.ndarray] | None
    arena: Arena


def simulate(
    arena: Arena,
    n_agents: int = 200,
    duration: float = 20.0,
    *,
    dt: float = DT,
    motion: MotionParams = MotionParams(),
    sensing: SensingParams = SensingParams(),
    commands: Sequence[Command] = (),
    static_fraction: float = 0.0,
    static_time: float = 0.0,
    rng=None,
    truth: bool = False,
    trajectory_every: float | None = None,
    progress: Callable[[float], None] | None = None,
    beacon: BeaconTrack | None = None,
    leash: float | None = None,
) -> Simulation:
    """Run the bio-inspired swarm model in ``arena`` and log encounters and status changes.

    Parameters
    ----------
    arena : Arena or ChangingArena
        Free space (mm).  A changing arena's obstacles appear and go at the first
        step t_k at or after their times, before that step's sensing: the walls are
        rebuilt, every agent inside a present obstacle moves to the nearest free point,
        and a wall follower whose wall is gone walks on (:mod:`.changes`).
    n_agents : int
        Swarm size N >= 1.
    duration : float
        Simulated time, s: a whole number K >= 1 of time steps dt (to a relative 1e-9).
    dt : float
        Time step, s; must satisfy max(v_c, v_p) dt <= r_d / 4.
    motion : MotionParams or one of :data:`.params.WALKERS`
        The motion model: the paper's cockroach (:class:`MotionParams`, its defaults
        v_c, l*, v_p, tau_stop, p_sh, tau_s, tau_l, tau_exit) or :class:`Billiard`,
        :class:`RunAndTumble`, :class:`Brownian`, :class:`LevyWalk`, :class:`Flocking`
        (:mod:`.walkers`; they never wall-follow, so no ``"WF"`` command and no leader).
    sensing : SensingParams
        r_d and what blocks a contact.
    commands : sequence of Command
        Base-station commands, applied in time order (ties: given order); none may
        come after the last step t_K = K dt.
    static_fraction, static_time : float
        Shortcut for ``Command(static_time, "static", fraction=static_fraction)``
        (so static_time <= t_K when static_fraction > 0).
    rng : int, Generator or None
        Randomness; an int seed is recorded in ``log.meta["seed"]``.
    truth : bool
        Also return the true positions of every event.
    trajectory_every : float or None
        Also return positions and states sampled this often (s, rounded to a multiple
        of dt, at least dt).
    progress : callable or None
        Called with the fraction done (about 100 times).
    beacon, leash : BeaconTrack and float, or None
        A leader moving along ``beacon`` with agents kept within ``leash`` R mm of it
        (:mod:`.leash`); both or neither.  The agents start uniformly in the free space
        within R of the leader's first position, and ``log.beacon`` is its track up to t_K.

    Returns
    -------
    Simulation
        ``log.meta`` holds ``format`` (:data:`swarmtopo.log.LOG_FORMAT`), ``version``,
        ``units``, r_d, v_c, v_p (the cockroach's speeds; a walker's speed as both, none
        for Brownian motion), ``duration`` (t_K), dt, ``agent_count``, ``seed`` and
        ``simulation`` (all parameters, the model's name as ``motion_model``;
        infinities written as ``"inf"``).

    Raises
    ------
    InputError
        On a bad parameter, quoting it; on a command (or static_time) after t_K.
    """
    _check_inputs(arena, n_agents, duration, dt, motion, sensing, commands, static_fraction, static_time,
                  trajectory_every, progress)
    if (beacon is None) != (leash is None):
        raise InputError("a leader needs both beacon= (its track) and leash= (R, mm)",
                         value=f"beacon={beacon!r}, leash={leash!r}")
    if beacon is not None:
        if not isinstance(beacon, BeaconTrack):
            raise InputError(f"beacon must be a BeaconTrack, got {type(beacon).__name__}")
        leash = positive("leash", leash)
        if not isinstance(motion, MotionParams):
            raise InputError(f"a leader steers the cockroach model only, not {motion_name(motion)} motion")
    commands = list(commands)
    if static_fraction > 0:
        commands.append(Command(static_time, "static", fraction=static_fraction))
    commands.sort(key=lambda c: c.time)
    seed = int(rng) if isinstance(rng, (int, np.integer)) and not isinstance(rng, bool) else None
    try:
        gen = np.random.default_rng(rng)
    except (TypeError, ValueError) as exc:
        raise InputError(f"rng must be an int seed, a numpy Generator or None ({exc})", value=rng) from None

    n = int(n_agents)
    n_steps = _n_steps(duration, dt)
    r_d = sensing.r_d
    walker, commanded = None, motion
    if isinstance(motion, MotionParams):
        max_step = top_speed(motion, dt)
    else:  # walkers move in straight pieces of at most r_d / 4 (check_time_step bounds the steps)
        max_step = r_d / 4
        walker = _walkers.make_walker(motion, dt, max_step)
        commanded = _walkers.command_model(motion, r_d, dt)
    reach = r_d + 3 * max_step
    free = arena.at(0.0) if isinstance(arena, ChangingArena) else arena
    walls = _walls.build_wall_grid(free.boundary_segments, free.bounds, cell=r_d, reach=reach)
    model = _motion.make_model(commanded, r_d, dt)
    start_area = None
    if beacon is not None:
        bx, by = (float(c[0]) for c in beacon.position([0.0]))
        start_area = shapely.Point(bx, by).buffer(leash, quad_segs=32)
        if start_area.intersection(free.geometry).area <= 0:
            raise InputError(f"the leader's first position ({bx:g}, {by:g}) mm is not within the leash R = {leash:g} mm "
                             "of the arena's free space: the agents start within R of it")
    xy = free.sample_uniform(n, gen, clearance=_walls.WALL_EPS, within=start_area)
    if walker is None:
        agents = _motion.new_swarm(xy, model, gen)
    else:
        agents = _motion.blank_swarm(xy)
        _walkers.init_walkers(agents, walker, gen)
    stimulated, stimulus = 0, np.zeros(n, np.bool_)
    tracker = _sensing.EncounterTracker(n, r_d, walls if sensing.walls_block else None,
                                        log_initial_contacts=sensing.log_initial_contacts)
    sample_every = None if trajectory_every is None else max(1, int(round(trajectory_every / dt)))
    report_every = max(1, (n_steps + 1) // 100)

    events: list[tuple] = []
    status: list[tuple] = []
    static_agents: list[np.ndarray] = []
    static_times: list[np.ndarray] = []
    samples: list[tuple] = []
    changed = np.empty(n, np.int64)
    next_command = 0
    changes = arena.change_times() if isinstance(arena, ChangingArena) else []
    relocated: list[dict] = []
    for k in range(n_steps + 1):
        t = round(k * dt, TIME_DECIMALS)
        if changes and round(changes[0], TIME_DECIMALS) <= t:  # the arena changes before anyone senses
            while changes and round(changes[0], TIME_DECIMALS) <= t:
                latest = changes.pop(0)
            free = arena.at(max(t, latest))  # a change just after t_k (within rounding) is applied at t_k
            walls = _walls.build_wall_grid(free.boundary_segments, free.bounds, cell=r_d, reach=reach)
            if sensing.walls_block:
                tracker.walls = walls
            moved = _changes.arena_changed(agents, free, walls, model)
            relocated.append({"t": t, "agents": moved})
        x, y = np.ascontiguousarray(agents["x"]), np.ascontiguousarray(agents["y"])
        a, b = tracker.update(t, x, y)
        if len(a):
            events.append((t, a, b, x[a], y[a], x[b], y[b]))
        while next_command < len(commands) and round(commands[next_command].time, TIME_DECIMALS) <= t:
            cmd = commands[next_command]
            targets = _commands.resolve_agents(cmd, n, gen)
            if cmd.mode == STATIC:
                newly = targets[agents["mode"][targets] != STATIC]
                static_agents.append(newly)
                static_times.append(np.full(len(newly), t))
            _commands.apply_command(agents, model, walls, gen, targets, np.int8(cmd.mode))
            next_command += 1
        if beacon is not None:
            bx, by = beacon.position(t)
            stimulated += _leash.steer(agents, stimulus, float(bx), float(by), leash, model, walls, gen)
        if walker is None:
            n_changed = _motion.step_swarm(agents, model, walls, gen, k < n_steps, changed)
        else:
            n_changed = _walkers.step_walkers(agents, walker, walls, gen, k < n_steps, changed)
        if n_changed:
            who = changed[:n_changed].copy()
            status.append((t, who, agents["state"][who]))
        if sample_every is not None and k % sample_every == 0:
            samples.append((t, x, y, agents["state"].copy()))
        if progress is not None and (k % report_every == 0 or k == n_steps):
            progress((k + 1) / (n_steps + 1))

    meta = _meta(arena, n, n_steps, dt, motion, sensing, commands, static_fraction, static_time, seed)
    if isinstance(arena, ChangingArena):
        meta["simulation"]["betti_timeline"] = jsonable(arena.betti_timeline(meta["duration"]))
        meta["simulation"]["relocated"] = relocated
    if beacon is not None:
        meta["leash"] = leash  # the operator's setting, not ground truth: the map reads it
        meta["simulation"]["leash"] = {"R": leash, "heading_error": _leash.HEADING_ERROR,
                                       "stimulated_share": stimulated / (n * (n_steps + 1))}
    log, order = _build_log(events, status, static_agents, static_times, meta)
    if beacon is not None:
        log = dataclasses.replace(log, beacon=beacon.between(0.0, meta["duration"]))
    return Simulation(
        log=log,
        truth=_truth(events, order) if truth else None,
        trajectories=_trajectories(samples, n) if sample_every is not None else None,
        arena=arena,
    )


def _check_inputs(arena, n_agents, duration, dt, motion, sensing, commands, static_fraction, static_time,
                  trajectory_every, progress) -> None:
    if not isinstance(arena, (Arena, ChangingArena)):
        raise InputError(f"arena must be a swarmtopo Arena or ChangingArena, got {type(arena).__name__}")
    check_parameters(n_agents, duration, dt=dt, motion=motion, sensing=sensing, commands=commands,
                     static_fraction=static_fraction, static_time=static_time)
    if trajectory_every is not None:
        positive("trajectory_every", trajectory_every)
    if progress is not None and not callable(progress):
        raise InputError("progress must be callable or None", value=progress)


def check_parameters(n_agents: int, duration: float, *, dt: float = DT,
                     motion=MotionParams(), sensing: SensingParams = SensingParams(),
                     commands: Sequence[Command] = (), static_fraction: float = 0.0,
                     static_time: float = 0.0) -> None:
    """:func:`simulate`'s checks of the swarm's parameters (all but the arena, rng and
    outputs), without running it: InputError on a bad one."""
    positive_int("n_agents", n_agents)
    if not isinstance(motion, (MotionParams, *WALKERS)):
        raise InputError("motion must be a MotionParams or one of " + ", ".join(m.__name__ for m in WALKERS)
                         + f", got {type(motion).__name__}")
    if not isinstance(sensing, SensingParams):
        raise InputError(f"sensing must be a SensingParams, got {type(sensing).__name__}")
    check_time_step(dt, motion, sensing)
    positive("duration", duration)
    check_run_size(n_agents, duration, dt)
    check_duration(duration, dt)
    non_negative("static_time", static_time)
    fraction("static_fraction", static_fraction)
    for c in commands:
        if not isinstance(c, Command):
            raise InputError(f"commands must be Command objects, got {type(c).__name__}", value=c)
    _commands.check_command_agents(commands, int(n_agents))
    if not isinstance(motion, MotionParams):
        for c in commands:
            if c.behaviour == "WF":
                raise InputError(f"a 'WF' command needs the cockroach model: {motion_name(motion)} agents do not "
                                 f"follow walls", value=c.time)
    check_static_time(static_fraction, static_time, duration, dt)
    end = _end_time(duration, dt)
    for c in commands:
        if round(c.time, TIME_DECIMALS) > end:
            raise InputError(f"command {c.behaviour!r} at t = {c.time:g} s comes after the run ends at "
                             f"t = {end:g} s", value=c.time)


def check_time_step(dt: float, motion, sensing: SensingParams) -> None:
    """InputError unless dt > 0 and an agent moves at most r_d / 4 per step (else contacts
    and walls could be stepped over): at its top speed, or for Brownian motion by its
    root-mean-square displacement sqrt(4 D dt), which may reach r_d / 2 (its path is
    rough at every scale, and the walls are checked piece by piece)."""
    positive("dt", dt)
    step = top_speed(motion, dt)
    if isinstance(motion, Brownian):
        if step > sensing.r_d / 2:
            raise InputError(
                f"time step too coarse: Brownian agents move sqrt(4 D dt) = {step:g} mm per step (root mean "
                f"square), more than r_d / 2 = {sensing.r_d / 2:g} mm, so contacts could be stepped over; use "
                f"dt <= {sensing.r_d ** 2 / (16 * motion.diffusion):g} s", value=dt)
        return
    if step > sensing.r_d / 4:
        what = "max(v_c, v_p) * dt" if isinstance(motion, MotionParams) else "speed * dt"
        raise InputError(
            f"time step too coarse: agents move {what} = {step:g} mm per step, more than "
            f"r_d / 4 = {sensing.r_d / 4:g} mm, so contacts and walls could be stepped over; "
            f"use dt <= {sensing.r_d * dt / (4 * step):g} s", value=dt)


def check_run_size(n_agents: int, duration: float, dt: float) -> None:
    """InputError unless the run has at most MAX_AGENTS agents and MAX_AGENT_STEPS agent-steps."""
    if n_agents > MAX_AGENTS:
        raise InputError(f"n_agents must be at most {MAX_AGENTS:,}", value=n_agents)
    steps = n_agents * (duration / dt)
    if steps > MAX_AGENT_STEPS:
        raise InputError(f"{n_agents} agents x {duration:.3g} s / dt {dt:.3g} s = {steps:.3g} agent-steps, more than "
                         f"the {MAX_AGENT_STEPS:.0e} a run may take")


def check_duration(duration: float, dt: float) -> None:
    """InputError unless ``duration`` is a whole number K >= 1 of time steps ``dt``
    (within a relative :data:`DURATION_TOLERANCE`): the last step is t_K = duration,
    never a shorter run than asked for.  The message names the nearest valid durations."""
    steps = duration / dt
    whole = round(steps)
    if whole >= 1 and abs(steps - whole) <= DURATION_TOLERANCE * steps:
        return
    nearest = [k * dt for k in (math.floor(steps), math.ceil(steps)) if k >= 1]
    shown = " or ".join(f"{round(x, TIME_DECIMALS):.12g} s" for x in dict.fromkeys(nearest))
    raise InputError(f"duration {duration:.12g} s is not a whole number of time steps dt = {dt:.12g} s "
                     f"({steps:.6g} steps); use {shown}")


def check_static_time(static_fraction: float, static_time: float, duration: float, dt: float) -> None:
    """InputError if agents are to become static after the run's last step t_K."""
    end = _end_time(duration, dt)
    if static_fraction > 0 and round(static_time, TIME_DECIMALS) > end:
        raise InputError(f"static_time is after the run ends at t = {end:g} s, so no agent would become static",
                         value=static_time)


def _n_steps(duration: float, dt: float) -> int:
    return int(round(duration / dt))


def _end_time(duration: float, dt: float) -> float:
    """t_K, the time of the last step: commands after it would never be applied."""
    return round(_n_steps(duration, dt) * dt, TIME_DECIMALS)


def _meta(arena, n, n_steps, dt, motion, sensing, commands, static_fraction, static_time, seed) -> dict:
    provenance = {
        "n_agents": n,
        "motion": dataclasses.asdict(motion),
        "sensing": dataclasses.asdict(sensing),
        "commands": [{"time": c.time, "behaviour": c.behaviour, "fraction": c.fraction,
                      "agents": None if c.agents is None else list(c.agents)} for c in commands],
        "static_fraction": float(static_fraction),
        "static_time": float(static_time),
        "arena_betti": list(arena.betti),
    }
    if isinstance(motion, MotionParams):  # a cockroach log has no model name (as before walkers existed)
        speeds = {"v_c": motion.v_c, "v_p": motion.v_p}
    else:
        provenance["motion_model"] = motion_name(motion)
        speeds = {"v_c": motion.speed, "v_p": motion.speed} if hasattr(motion, "speed") else {}
    return jsonable({
        "format": LOG_FORMAT,
        "version": __version__,
        "units": {"time": "s", "length": "mm"},
        "r_d": sensing.r_d,
        **speeds,
        "duration": round(n_steps * dt, TIME_DECIMALS),
        "dt": float(dt),
        "agent_count": n,
        "seed": seed,
        "simulation": provenance,
    })


def _build_log(events, status, static_agents, static_times, meta):
    if events:
        t = np.concatenate([np.full(len(e[1]), e[0]) for e in events])
        a = np.concatenate([e[1] for e in events])
        b = np.concatenate([e[2] for e in events])
    else:
        t, a, b = np.empty(0), np.empty(0, np.int64), np.empty(0, np.int64)
    st_t = np.concatenate([np.full(len(s[1]), s[0]) for s in status])
    st_agent = np.concatenate([s[1] for s in status])
    st_state = state_labels(np.concatenate([s[2] for s in status]))
    static = None
    if static_agents:
        static = (np.concatenate(static_agents), np.concatenate(static_times))
    log = EncounterLog.from_records(t, a, b, status=(st_t, st_agent, st_state), static=static, meta=meta)
    order = np.lexsort((b, a, t))
    return log, order


def _truth(events, order) -> dict[str, np.ndarray]:
    keys = ("t", "a", "b", "xa", "ya", "xb", "yb")
    if not events:
        return {k: np.empty(0, np.int64 if k in ("a", "b") else np.float64) for k in keys}
    cols = {"t": np.concatenate([np.full(len(e[1]), e[0]) for e in events])}
    for j, k in enumerate(keys[1:], start=1):
        cols[k] = np.concatenate([e[j] for e in events])
    return {k: v[order] for k, v in cols.items()}


def _trajectories(samples, n) -> dict[str, np.ndarray]:
    return {
        "t": np.repeat(np.array([s[0] for s in samples]), n),
        "agent": np.tile(np.arange(n, dtype=np.int64), len(samples)),
        "x": np.concatenate([s[1] for s in samples]),
        "y": np.concatenate([s[2] for s in samples]),
        "state": np.concatenate([s[3] for s in samples]).astype(np.int8),
    }


@contextlib.contextmanager
def interpreted_kernels():
    """Run the simulator on the kernels' pure-Python ``.py_func`` (tests, benchmarks).

    Inside the block every numba kernel of ``swarmtopo.sim`` is replaced by its
    Python source function, so a simulation is a plain per-agent Python loop of the
    same model with the same neighbour search.  Not thread-safe.
    """
    modules = [_walls, _motion, _commands, _sensing, _leash, _walkers]
    saved = []
    for module in modules:
        for name, obj in vars(module).items():
            if isinstance(obj, CPUDispatcher):
                saved.append((module, name, obj))
    try:
        for module, name, obj in saved:
            setattr(module, name, obj.py_func)
        yield
    finally:
        for module, name, obj in saved:
            setattr(module, name, obj)
