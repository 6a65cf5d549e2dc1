"""simulate(): log contract, determinism, pure-Python agreement, commands, validation."""

import math
import re

import numpy as np
import pytest
from shapely.geometry import Polygon, box

import swarmtopo
from swarmtopo import Arena, InputError
from swarmtopo.log import LOG_FORMAT, RW, S, WF
from swarmtopo.sim import Command, MotionParams, SensingParams, interpreted_kernels, simulate

DT = 0.1


def arena_with_holes():
    return Arena(Polygon(box(0, 0, 300, 300).exterior.coords,
                         [box(120, 120, 180, 180).exterior.coords, [(40, 200), (90, 210), (50, 260)]]))


def log_arrays(log):
    return [log.t, log.a, log.b, log.status_t, log.status_agent, log.status_state, log.static_agent,
            log.static_time]


def positions(sim, n):
    return sim.trajectories["x"].reshape(-1, n), sim.trajectories["y"].reshape(-1, n)


def rows_of(log, agent):
    mine = log.status_agent == agent
    return log.status_t[mine], log.status_state[mine]


ALL_COMMANDS = (Command(2.0, "RW", fraction=0.3), Command(3.0, "WF", agents=(0, 1, 2, 3)),
                Command(4.0, "S", fraction=0.2), Command(5.05, "static", agents=(4, 5)),
                Command(6.0, "free", fraction=1.0))


def test_same_seed_gives_identical_bytes_and_other_seeds_differ():
    runs = [simulate(arena_with_holes(), 50, 10.0, rng=seed, commands=ALL_COMMANDS).log for seed in (7, 7, 8)]
    for x, y in zip(log_arrays(runs[0]), log_arrays(runs[1])):
        assert x.dtype == y.dtype and x.tobytes() == y.tobytes()
    assert runs[0].meta == runs[1].meta
    assert runs[0].n_events != runs[2].n_events or not np.array_equal(runs[0].t, runs[2].t)


def test_compiled_kernels_match_their_pure_python_functions():
    kwargs = dict(n_agents=25, duration=8.0, rng=np.random.SeedSequence(5), commands=ALL_COMMANDS,
                  truth=True, trajectory_every=0.1)
    compiled = simulate(arena_with_holes(), **kwargs)
    with interpreted_kernels():
        python = simulate(arena_with_holes(), **kwargs)
    for x, y in zip(log_arrays(compiled.log), log_arrays(python.log)):
        np.testing.assert_array_equal(x, y)
    for key in compiled.trajectories:
        np.testing.assert_array_equal(compiled.trajectories[key], python.trajectories[key])
    assert compiled.log.n_events > 10 and len(compiled.log.status_t) > 50


def test_log_contract_times_status_and_meta():
    arena = arena_with_holes()
    n = 30
    sim = simulate(arena, n, 12.3, dt=DT, rng=4, trajectory_every=0.25)
    log = sim.log
    k = np.rint(log.t / DT)
    np.testing.assert_array_equal(log.t, np.round(k * DT, 9))
    np.testing.assert_array_equal(log.agent_ids, np.arange(n))
    # one row at t = 0 per agent, then only changes
    first = np.r_[True, log.status_agent[1:] != log.status_agent[:-1]]
    np.testing.assert_array_equal(log.status_agent[first], np.arange(n))
    assert np.all(log.status_t[first] == 0)
    same_agent = ~first[1:]
    assert np.all(log.status_state[1:][same_agent] != log.status_state[:-1][same_agent])
    assert log.meta["units"] == {"time": "s", "length": "mm"}
    assert (log.meta["r_d"], log.meta["v_c"], log.meta["v_p"], log.meta["dt"]) == (30.0, 15.0, 10.0, DT)
    assert log.meta["duration"] == 12.3 and log.meta["agent_count"] == n and log.meta["seed"] == 4
    assert log.meta["version"] == swarmtopo.__version__ and log.meta["format"] == LOG_FORMAT
    assert log.meta["simulation"]["motion"]["tau_exit"] == MotionParams().tau_exit
    assert log.meta["simulation"]["n_agents"] == n
    # trajectory samples every round(0.25 / dt) = 2 steps (0.2 s) from t = 0
    t = np.unique(sim.trajectories["t"])
    np.testing.assert_allclose(t, np.arange(len(t)) * 0.2, atol=1e-9)
    assert t[-1] == pytest.approx(12.2)
    # trajectory states agree with the status log
    x, _ = positions(sim, n)
    state = sim.trajectories["state"].reshape(-1, n)
    for agent in range(n):
        st_t, st_state = rows_of(log, agent)
        current = st_state[np.searchsorted(st_t, t + 1e-9, side="right") - 1]
        np.testing.assert_array_equal(state[:, agent], current)


def test_seed_is_null_for_a_generator_and_inf_is_json_safe():
    log = simulate(Arena(box(0, 0, 100, 100)), 5, 1.0, rng=np.random.default_rng(1),
                   motion=MotionParams(tau_stop=math.inf)).log
    assert log.meta["seed"] is None
    assert log.meta["simulation"]["motion"]["tau_stop"] == "inf"


def test_static_nodes_are_listed_stopped_and_never_move_again():
    n = 60
    sim = simulate(arena_with_holes(), n, 20.0, static_fraction=0.25, static_time=5.03, rng=2,
                   trajectory_every=DT)
    log = sim.log
    assert len(log.static_agent) == 15
    assert np.all(log.static_time == 5.1)  # first step at or after the command time
    x, y = positions(sim, n)
    after = slice(51, None)
    for agent in log.static_agent:
        assert np.all(x[after, agent] == x[51, agent]) and np.all(y[after, agent] == y[51, agent])
        st_t, st_state = rows_of(log, agent)
        assert st_state[-1] == S and st_t[-1] <= 5.1
    moving = np.setdiff1d(np.arange(n), log.static_agent)
    assert np.any(x[-1, moving] != x[51, moving])
    _, start, end = log.stop_intervals()
    assert np.sum(np.isinf(end)) >= 15


def test_later_commands_do_not_wake_static_agents():
    commands = [Command(1.0, "static", agents=(3,)), Command(2.0, "free", agents=(3,)),
                Command(2.0, "static", agents=(3, 4))]
    log = simulate(arena_with_holes(), 10, 4.0, commands=commands, rng=1).log
    np.testing.assert_array_equal(log.static_agent, [3, 4])
    np.testing.assert_array_equal(log.static_time, [1.0, 2.0])
    st_t, st_state = rows_of(log, 3)
    assert st_state[-1] == S and st_t[-1] <= 1.0


def test_hold_then_free_resumes_motion():
    n = 40
    commands = [Command(3.0, "S", fraction=0.5), Command(7.0, "free", fraction=1.0)]
    sim = simulate(arena_with_holes(), n, 10.0, commands=commands, rng=6, trajectory_every=DT,
                   motion=MotionParams(tau_stop=math.inf))
    x, y = positions(sim, n)
    state = sim.trajectories["state"].reshape(-1, n)
    held = np.flatnonzero(state[30] == S)
    assert len(held) == 20  # round(0.5 * 40), and no natural stops
    assert np.all(x[30:71, held] == x[30, held]) and np.all(y[30:71, held] == y[30, held])
    assert np.all(state[71:, held] != S)
    assert np.all(np.hypot(x[71:, held] - x[70, held], y[71:, held] - y[70, held]).max(axis=0) > 0)
    for agent in held:
        st_t, st_state = rows_of(sim.log, agent)
        assert 3.0 in st_t[st_state == S].tolist() and 7.0 in st_t[st_state != S].tolist()


def test_rw_command_stops_wall_following_and_wf_command_never_exits():
    n = 80
    commands = [Command(5.0, "RW", agents=tuple(range(40))), Command(5.0, "WF", agents=tuple(range(40, 80)))]
    sim = simulate(Arena(box(0, 0, 300, 300)), n, 60.0, commands=commands, rng=3, trajectory_every=DT)
    state = sim.trajectories["state"].reshape(-1, n)
    assert np.all(state[50:, :40] != WF)
    assert np.any(state[:50, :40] == WF)  # they did wall-follow before the command
    found_wall = 0
    for agent in range(40, 80):
        on_wall = np.flatnonzero(state[50:, agent] == WF)
        if len(on_wall):
            found_wall += 1
            assert not np.any(state[50 + on_wall[0]:, agent] == RW)  # once on a wall, never RW again
    assert found_wall >= 35


def test_fraction_command_targets_a_random_rounded_fraction():
    n = 50
    sim = simulate(arena_with_holes(), n, 2.0, commands=[Command(1.0, "S", fraction=0.33)], rng=12,
                   motion=MotionParams(tau_stop=math.inf), trajectory_every=DT)
    state = sim.trajectories["state"].reshape(-1, n)
    held = np.flatnonzero(state[10] == S)
    assert len(held) == round(0.33 * n)
    assert not np.array_equal(held, np.arange(len(held)))


def test_progress_is_reported_about_a_hundred_times():
    seen = []
    simulate(Arena(box(0, 0, 100, 100)), 3, 50.0, rng=0, progress=seen.append)
    assert 95 <= len(seen) <= 105
    assert seen[-1] == 1.0 and seen == sorted(seen)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(dt=0.6), "r_d / 4"),
        (dict(dt=0.0), "dt must be a positive finite number"),
        (dict(duration=math.nan), "duration must be a positive finite number"),
        (dict(static_time=-1.0), "static_time must be a finite number >= 0"),
        (dict(n_agents=2.0), "n_agents must be a positive integer"),
        (dict(n_agents=0), "n_agents"),
        (dict(duration=-1.0), "duration must be a positive finite number"),
        (dict(duration=0.0), "duration must be a positive finite number"),
        (dict(static_fraction=1.5), "static_fraction"),
        (dict(commands=[Command(1.0, "S", agents=(99,))]), "agents are 0..9"),
        (dict(trajectory_every=0.0), "trajectory_every"),
        (dict(progress=3), "callable"),
        (dict(arena="square"), "Arena"),
        (dict(rng="seed"), "rng must be"),
    ],
)
def test_invalid_parameters_raise_clear_errors(kwargs, message):
    args = dict(arena=Arena(box(0, 0, 100, 100)), n_agents=10, duration=1.0)
    args.update(kwargs)
    with pytest.raises(InputError, match=re.escape(message)):
        simulate(**args)


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: Command(1.0, "dance", fraction=0.5), "unknown command behaviour"),
        (lambda: Command(1.0, "S"), "exactly one"),
        (lambda: Command(1.0, "S", fraction=0.5, agents=(1,)), "exactly one"),
        (lambda: Command(1.0, "S", fraction=1.2), r"\[0, 1\]"),
        (lambda: Command(-1.0, "S", fraction=0.5), "time"),
        (lambda: Command(1.0, "S", agents=(1.5,)), "integer"),
        (lambda: MotionParams(v_c=-1), "v_c"),
        (lambda: MotionParams(p_sh=2), "p_sh"),
        (lambda: MotionParams(tau_s=math.inf), "tau_s"),
        (lambda: SensingParams(r_d=0), "r_d"),
        (lambda: SensingParams(walls_block="yes"), "walls_block"),
    ],
)
def test_invalid_parameter_objects_raise(make, message):
    with pytest.raises(InputError, match=message):
        make()


@pytest.mark.parametrize("kwargs, message", [
    # duration 1 s at dt 0.1 s: K = 10 steps, the last at t = 1.0 s
    (dict(static_fraction=0.5, static_time=1.04), "static_time is after the run ends at t = 1 s"),
    (dict(commands=[Command(1.0, "S", agents=(0,)), Command(2.5, "free", fraction=1.0)]),
     "command 'free' at t = 2.5 s comes after the run ends at t = 1 s"),
])
def test_commands_after_the_end_are_refused(kwargs, message):
    with pytest.raises(InputError, match=re.escape(message)):
        simulate(Arena(box(0, 0, 100, 100)), 4, 1.0, rng=0, **kwargs)


def test_commands_at_the_last_step_are_applied():
    log = simulate(Arena(box(0, 0, 100, 100)), 4, 1.0, rng=0, static_fraction=0.5, static_time=1.0).log
    assert log.static_time.tolist() == [1.0, 1.0]
    # a static_time after the end is harmless when nobody is made static
    assert simulate(Arena(box(0, 0, 100, 100)), 4, 1.0, rng=0, static_time=5.0).log.n_agents == 4


def test_resolution_rule_message_names_the_largest_valid_dt():
    with pytest.raises(InputError) as err:
        simulate(Arena(box(0, 0, 100, 100)), 5, 1.0, dt=1.0)
    assert "use dt <= 0.5 s" in str(err.value)


@pytest.mark.parametrize("duration, dt, nearest", [
    (0.1, 0.5, "use 0.5 s"),  # would be K = 0 steps: a log of t = 0 only
    (1.0, 0.3, "use 0.9 s or 1.2 s"),  # would be 0.9 s without a word
    (20.05, 0.1, "use 20 s or 20.1 s"),
])
def test_a_duration_must_be_a_whole_number_of_time_steps(duration, dt, nearest):
    with pytest.raises(InputError) as info:
        simulate(Arena(box(0, 0, 100, 100)), 4, duration, dt=dt)
    assert str(info.value) == (f"duration {duration:g} s is not a whole number of time steps dt = {dt:g} s "
                               f"({duration / dt:.6g} steps); {nearest}")


def test_a_duration_within_a_relative_1e_9_of_whole_steps_is_that_many_steps():
    # 0.9 / 0.3 = 3.0000000000000004 and 30 / 0.1 = 299.99999999999994 steps
    for duration, dt in ((0.9, 0.3), (30.0, 0.1), (1.0 + 1e-10, 0.1)):
        assert simulate(Arena(box(0, 0, 100, 100)), 4, duration, dt=dt).log.meta["duration"] == round(duration, 9)
