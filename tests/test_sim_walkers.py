"""Motion models beside the cockroach's (swarmtopo.sim.walkers): each tested by its own
statistics against theory, plus walls, commands, determinism and bad parameters."""

import math

import numpy as np
import pytest
import shapely

import swarmtopo as st
from swarmtopo.errors import InputError
from swarmtopo.log import RW, S
from swarmtopo.sim import Command, interpreted_kernels, simulate
from swarmtopo.sim.params import (Billiard, Brownian, Flocking, LevyWalk, MotionParams, RunAndTumble, make_motion)
from swarmtopo.sim import walkers
from swarmtopo.sim.motion import AGENT_DTYPE

BIG = 3000.0
"""Side (mm) of the open arena of the statistics tests; agents farther than ``CLEAR``
from its walls at t = 0 do not reach one within the runs below (at 15 mm/s, 20 s is
300 mm; a Brownian agent's 5-sigma reach in 20 s is under 500 mm)."""
CLEAR = 500.0


def big_arena():
    return st.Arena(shapely.box(0, 0, BIG, BIG))


def paths(motion, n=4000, duration=20.0, seed=1, dt=0.1):
    """Positions (T, M) of the agents that start ``CLEAR`` from the walls, and the times."""
    sim = simulate(big_arena(), n, duration, motion=motion, rng=seed, dt=dt, trajectory_every=dt)
    tr = sim.trajectories
    times = np.unique(tr["t"])
    x, y = tr["x"].reshape(len(times), n), tr["y"].reshape(len(times), n)
    inner = (np.minimum(x[0], BIG - x[0]) > CLEAR) & (np.minimum(y[0], BIG - y[0]) > CLEAR)
    return times, x[:, inner], y[:, inner]


def msd(x, y, lag):
    return float(np.mean((x[lag] - x[0]) ** 2 + (y[lag] - y[0]) ** 2))


def test_billiard_moves_straight_at_its_speed_and_reflects_without_loss():
    times, x, y = paths(Billiard(speed=12.0), n=400, duration=10.0)
    step = np.hypot(np.diff(x, axis=0), np.diff(y, axis=0))
    np.testing.assert_allclose(step, 1.2, atol=1e-9)  # v dt, every step, no wall within reach
    heading = np.arctan2(np.diff(y, axis=0), np.diff(x, axis=0))
    assert np.ptp(np.unwrap(heading, axis=0), axis=0).max() < 1e-9  # never turns in open space
    # in a small box: every step at most v dt, speed kept along walls, always inside
    box = st.Arena(shapely.box(0, 0, 100, 60))
    sim = simulate(box, 30, 30.0, motion=Billiard(speed=12.0), rng=2, trajectory_every=0.1)
    tr = sim.trajectories
    assert (tr["x"] > 0).all() and (tr["x"] < 100).all() and (tr["y"] > 0).all() and (tr["y"] < 60).all()
    bx, by = tr["x"].reshape(-1, 30), tr["y"].reshape(-1, 30)
    moved = np.hypot(np.diff(bx, axis=0), np.diff(by, axis=0))
    assert moved.max() <= 1.2 + 1e-9
    assert np.median(moved) == pytest.approx(1.2)


def test_billiard_reflection_is_specular():
    """One agent heading into a wall at 30 degrees leaves it at 30 degrees (mirror image)."""
    agents = np.zeros(1, AGENT_DTYPE)
    agents["x"], agents["y"], agents["heading"] = 50.0, 1.0, -math.pi / 6
    from swarmtopo.sim.walls import build_wall_grid
    box = st.Arena(shapely.box(0, 0, 100, 60))
    walls = build_wall_grid(box.boundary_segments, box.bounds, cell=30.0, reach=40.0)
    walkers.reflect_along.py_func(agents[0], walls, 4.0, 7.5)
    assert agents["heading"][0] == pytest.approx(math.pi / 6)
    # the path: 2 mm to the wall (y = 0) along the heading, then 2 mm back up at the mirror angle
    assert agents["x"][0] == pytest.approx(50.0 + 4.0 * math.cos(math.pi / 6), abs=1e-3)
    assert agents["y"][0] == pytest.approx(1.0, abs=1e-3)


def test_run_and_tumble_msd_and_velocity_correlation_match_theory():
    v, lam = 15.0, 0.5
    times, x, y = paths(RunAndTumble(speed=v, tumble_rate=lam))
    for lag in (10, 50, 100, 200):  # 1, 5, 10, 20 s
        t = times[lag]
        theory = 2 * v * v / lam ** 2 * (lam * t - 1 + math.exp(-lam * t))
        assert msd(x, y, lag) == pytest.approx(theory, rel=0.08)  # about 3 standard errors (1,800 agents)
    heading = np.arctan2(np.diff(y, axis=0), np.diff(x, axis=0))
    for lag in (10, 20, 40):  # <cos(theta(t + s) - theta(t))> = exp(-lambda s): runs end at rate lambda
        corr = float(np.mean(np.cos(heading[lag:] - heading[:-lag])))
        assert corr == pytest.approx(math.exp(-lam * lag * 0.1), abs=0.03)


def test_brownian_msd_is_4_d_t_and_increments_are_gaussian():
    d = 225.0
    times, x, y = paths(Brownian(diffusion=d))
    for lag in (1, 10, 50, 200):
        assert msd(x, y, lag) == pytest.approx(4 * d * times[lag], rel=0.06)
    dx = np.diff(x, axis=0).ravel()
    assert dx.var() == pytest.approx(2 * d * 0.1, rel=0.03)
    kurtosis = np.mean((dx - dx.mean()) ** 4) / dx.var() ** 2
    assert kurtosis == pytest.approx(3.0, abs=0.1)


def test_levy_steps_have_the_pareto_tail_and_spread_superdiffusively():
    w = walkers.make_walker(LevyWalk(exponent=2.5, min_step=10.0), 0.1, 7.5)
    rng = np.random.default_rng(0)
    steps = np.array([walkers.draw_run.py_func(rng, w) for _ in range(20000)])
    assert steps.min() >= 10.0
    hill = 1.0 / np.mean(np.log(steps / 10.0))  # MLE of mu - 1 for P(L > l) = (l / l_0)^(1 - mu)
    assert hill == pytest.approx(1.5, rel=0.03)
    # MSD ~ t^(4 - mu): superdiffusive, where a run-and-tumble walk of the same mean run (l_0 (mu - 1) /
    # (mu - 2) = 30 mm) and speed turns diffusive (slope -> 1)
    times, x, y = paths(LevyWalk(exponent=2.5), duration=20.0)
    slope = math.log(msd(x, y, 200) / msd(x, y, 50)) / math.log(4.0)
    times_rt, xr, yr = paths(RunAndTumble(speed=15.0, tumble_rate=15.0 / 30.0), duration=20.0)
    slope_rt = math.log(msd(xr, yr, 200) / msd(xr, yr, 50)) / math.log(4.0)
    assert 1.25 < slope < 1.75 and slope > slope_rt + 0.08


def test_flocking_orders_at_low_noise_and_not_at_full_noise():
    def order(noise):
        box = st.Arena(shapely.box(0, 0, 1000, 1000))  # dense enough to order as one flock (walls reflect it)
        sim = simulate(box, 400, 30.0, motion=Flocking(speed=10.0, radius=150.0, noise=noise), rng=4,
                       trajectory_every=0.1)
        tr = sim.trajectories
        x, y = tr["x"].reshape(-1, 400), tr["y"].reshape(-1, 400)
        h = np.arctan2(np.diff(y, axis=0), np.diff(x, axis=0))
        return np.abs(np.mean(np.exp(1j * h), axis=1))  # phi(t) = |mean unit velocity|

    ordered, disordered = order(0.2), order(2 * math.pi)
    assert ordered[-50:].mean() > 0.7
    assert disordered[-50:].mean() < 3 / math.sqrt(400)


def test_alignment_takes_the_mean_heading_of_neighbours_within_the_radius():
    agents = np.zeros(3, AGENT_DTYPE)
    agents["x"] = [0.0, 20.0, 100.0]
    agents["heading"] = [0.0, math.pi / 2, math.pi]
    w = walkers.make_walker(Flocking(radius=30.0, noise=0.0), 0.1, 7.5)
    walkers.align.py_func(agents, w, np.random.default_rng(0))
    np.testing.assert_allclose(agents["heading"], [math.pi / 4, math.pi / 4, math.pi])


@pytest.mark.parametrize("motion", [Billiard(), RunAndTumble(), Brownian(), LevyWalk(), Flocking()])
def test_walkers_stay_inside_a_holed_arena_and_runs_are_reproducible(motion):
    arena = st.random_arena(2, rng=3)
    sim = simulate(arena, 60, 8.0, motion=motion, rng=5, trajectory_every=0.1)
    tr = sim.trajectories
    inside = shapely.contains_xy(arena.geometry, tr["x"], tr["y"])
    assert inside.all()
    again = simulate(arena, 60, 8.0, motion=motion, rng=5)
    np.testing.assert_array_equal(sim.log.t, again.log.t)
    np.testing.assert_array_equal(sim.log.a, again.log.a)
    with interpreted_kernels():
        slow = simulate(arena, 60, 8.0, motion=motion, rng=5)
    np.testing.assert_array_equal(sim.log.t, slow.log.t)
    np.testing.assert_array_equal(sim.log.b, slow.log.b)
    assert sim.log.meta["simulation"]["motion_model"] == motion.name
    assert set(sim.log.status_state) == {RW}


def test_commands_hold_walkers_and_wall_following_is_refused():
    arena = st.random_arena(1, rng=3)
    sim = simulate(arena, 20, 4.0, motion=Billiard(), rng=1, trajectory_every=0.1,
                   commands=[Command(1.0, "S", agents=(0, 1)), Command(3.0, "free", agents=(0,))])
    tr = sim.trajectories
    x = tr["x"].reshape(-1, 20)
    held = slice(11, 30)  # t = 1.1 .. 2.9 s: positions of agents 0 and 1 stay put
    assert np.ptp(x[held, 0]) == 0 and np.ptp(x[held, 1]) == 0 and np.ptp(x[held, 2]) > 0
    assert np.ptp(x[31:, 0]) > 0 and np.ptp(x[31:, 1]) == 0
    states = list(zip(sim.log.status_t, sim.log.status_agent, sim.log.status_state))
    assert (1.0, 0, S) in states and (3.0, 0, RW) in states
    with pytest.raises(InputError, match="'WF' command needs the cockroach model"):
        simulate(arena, 20, 4.0, motion=Brownian(), commands=[Command(1.0, "WF", fraction=0.5)])
    with pytest.raises(InputError, match="steers the cockroach model only"):
        simulate(arena, 20, 4.0, motion=Billiard(), beacon=st.long_axis_track(arena.bounds, 100.0), leash=100.0)


def test_motion_parameters_and_options_are_checked():
    assert make_motion("run-and-tumble", {"tumble_rate": 2.0, "speed": None}) == RunAndTumble(tumble_rate=2.0)
    assert make_motion("cockroach") == MotionParams()
    with pytest.raises(InputError, match="tumble-rate is not an option of billiard motion"):
        make_motion("billiard", {"tumble_rate": 1.0})
    with pytest.raises(InputError, match="unknown motion model"):
        make_motion("crab")
    with pytest.raises(InputError, match="exponent must be in"):
        LevyWalk(exponent=3.5)
    with pytest.raises(InputError, match=r"noise must be in \[0, 2 pi\]"):
        Flocking(noise=7.0)
    with pytest.raises(InputError, match="Brownian agents move sqrt"):
        simulate(st.random_arena(1, rng=1), 10, 1.0, motion=Brownian(diffusion=3000.0))
    with pytest.raises(InputError, match="speed \\* dt"):
        simulate(st.random_arena(1, rng=1), 10, 1.0, motion=Billiard(speed=100.0))
