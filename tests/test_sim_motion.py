"""Statistics of the motion model (paper, "Bio-Inspired Mobility Model") and its invariants.

Statistical tests run on fixed seeds; each tolerance is a stated number of standard
errors computed from the sample size, so a correct model fails with negligible
probability and a wrong law (wrong mean, per-step bias, wrong mixture) fails clearly.
"""

import math

import numpy as np
import pytest
import shapely
from scipy import stats
from shapely.geometry import Polygon, box

from swarmtopo import Arena
from swarmtopo.log import RW, S, WF
from swarmtopo.sim import Command, MotionParams, simulate
from swarmtopo.sim.params import MIN_WALL_OFFSET_FRACTION

DT = 0.1


def square_with_hole(side=500.0):
    return Arena(Polygon(box(0, 0, side, side).exterior.coords,
                         [box(0.4 * side, 0.4 * side, 0.6 * side, 0.6 * side).exterior.coords]))


def l_shaped_arena():
    """Non-convex: L-shaped outer wall, a triangular hole and a 1 mm thin-wall hole."""
    outer = [(0, 0), (600, 0), (600, 300), (300, 300), (300, 600), (0, 600)]
    triangle = [(100, 100), (200, 120), (130, 220)]
    thin_wall = [(380, 100), (560, 100), (560, 101), (380, 101)]
    return Arena(Polygon(outer, [triangle, thin_wall]))


def per_step(traj, n):
    """Trajectory columns as (samples, agents) arrays."""
    return tuple(traj[k].reshape(-1, n) for k in ("x", "y", "state"))


def status_runs(log):
    """Constant-state runs per agent: (agent, state, start, end, censored)."""
    ag, t, st = log.status_agent, log.status_t, log.status_state
    last = np.r_[ag[1:] != ag[:-1], True]
    end = np.where(last, log.duration, np.r_[t[1:], 0.0])
    return ag, st, t, end, last


def kaplan_meier(durations, observed, x):
    """Kaplan-Meier survival at times ``x`` (durations on the DT grid) and Greenwood s.e."""
    steps = np.rint(np.asarray(durations) / DT).astype(np.int64)
    observed = np.asarray(observed, bool)
    grid = np.unique(steps[observed])
    at_risk = len(steps) - np.searchsorted(np.sort(steps), grid, side="left")
    events = np.bincount(steps[observed])[grid]
    factor = 1.0 - events / at_risk
    green = events / (at_risk * np.maximum(at_risk - events, 1))
    surv, se = [], []
    for xk in np.rint(np.asarray(x) / DT).astype(np.int64):
        upto = grid <= xk
        s = float(np.prod(factor[upto]))
        surv.append(s)
        se.append(s * math.sqrt(float(np.sum(green[upto]))))
    return np.array(surv), np.array(se)


def episodes(log, inside, ending):
    """Time spent in the states ``inside`` (stops pause, not end, an episode) until a
    state in ``ending``; returns (duration, observed).  An episode starts at a run in
    ``inside`` that does not continue an episode."""
    ag, st, start, end, censored = status_runs(log)
    durations, observed = [], []
    current, open_ = 0.0, False
    for i in range(len(ag)):
        if st[i] in inside:
            current = current + (end[i] - start[i]) if open_ else end[i] - start[i]
            open_ = True
        elif st[i] in ending and open_:
            durations.append(current)
            observed.append(True)
            open_ = False
        if censored[i] and open_:
            durations.append(current)
            observed.append(False)
            open_ = False
    return np.array(durations), np.array(observed)


@pytest.fixture(scope="module")
def open_run():
    """Run-and-tumble far from walls: 2500 agents, no stops, 40 s, every step sampled."""
    side = 8000.0
    arena = Arena(box(0, 0, side, side))
    motion = MotionParams(tau_stop=math.inf)
    sim = simulate(arena, 2500, 40.0, dt=DT, motion=motion, rng=11, trajectory_every=DT)
    x, y, state = per_step(sim.trajectories, 2500)
    # agents that start farther than v_c * T + r_d from every wall can never see one
    margin = motion.v_c * 40.0 + 30.0 + 1.0
    far = arena.distance_to_boundary(x[0], y[0]) > margin
    return motion, x[:, far], y[:, far], state[:, far]


@pytest.mark.slow
def test_open_space_agents_random_walk_at_v_c(open_run):
    motion, x, y, state = open_run
    assert x.shape[1] > 1500
    assert np.all(state == RW)
    speed = np.hypot(np.diff(x, axis=0), np.diff(y, axis=0)) / DT
    assert np.median(speed) == pytest.approx(motion.v_c, abs=1e-9)
    # a step is shorter than v_c dt iff a segment ends inside it: P = 1 - exp(-v_c dt / l*)
    # exactly (Poisson turns in arc length); a per-step renewal would give another rate.
    # 600,000 nearly independent steps: s.e. 0.0003; tolerance 5 s.e.
    p_turn = 1 - math.exp(-motion.v_c * DT / motion.l_star)
    assert np.mean(speed < motion.v_c - 1e-9) == pytest.approx(p_turn, abs=5 * math.sqrt(p_turn / speed.size))
    assert speed.max() <= motion.v_c + 1e-9


@pytest.mark.slow
def test_velocity_autocorrelation_is_exponential_with_mean_free_path(open_run):
    motion, x, y, _ = open_run
    tau = motion.l_star / motion.v_c
    dx, dy = np.diff(x, axis=0), np.diff(y, axis=0)
    step = motion.v_c * DT
    for s in (0.5, 1.0, 2.0, 4.0):
        lag = int(round(s / DT))
        c = np.mean(dx[:-lag] * dx[lag:] + dy[:-lag] * dy[lag:]) / step**2
        # exact for Poisson turns in arc length: <D_0 . D_s> = v^2 e^{-s/tau} 4 tau^2 sinh^2(dt / 2 tau)
        expected = math.exp(-s / tau) * (2 * tau / DT * math.sinh(DT / (2 * tau))) ** 2
        # ~1500 agents x (40 s / 2 tau) independent blocks = 15,000 samples of a product
        # with sd <= 1, spread over ~400 correlated origins: s.e. < 0.004; tolerance 0.02
        assert c == pytest.approx(expected, abs=0.02), s


@pytest.mark.slow
def test_mean_squared_displacement_of_run_and_tumble(open_run):
    motion, x, y, _ = open_run
    tau, v = motion.l_star / motion.v_c, motion.v_c
    for t in (1.0, 2.0, 4.0, 8.0):
        lag = int(round(t / DT))
        origins = np.arange(0, x.shape[0] - lag, lag)  # non-overlapping windows
        sq = [(x[o + lag] - x[o]) ** 2 + (y[o + lag] - y[o]) ** 2 for o in origins]
        msd = np.mean(sq)
        expected = 2 * v**2 * tau**2 * (t / tau - 1 + math.exp(-t / tau))
        # |displacement|^2 has relative sd <= 1 (exponential-like at t >> tau); >= 1500 x 5
        # windows gives relative s.e. <= 1/sqrt(7500) = 1.2 %; tolerance 6 %
        assert msd == pytest.approx(expected, rel=0.06), t


@pytest.fixture(scope="module")
def natural_run():
    """The natural model in a 500 mm square with a hole: 500 agents, 600 s."""
    sim = simulate(square_with_hole(), 500, 600.0, dt=DT, rng=21)
    return sim.log


@pytest.mark.slow
def test_stop_durations_follow_the_two_exponential_mixture(natural_run):
    p = MotionParams()
    ag, st, start, end, censored = status_runs(natural_run)
    stop = st == S
    dur, obs = end[stop] - start[stop], ~censored[stop]
    assert len(dur) > 10_000
    x = np.array([0.1, 0.3, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 40.0])
    surv, se = kaplan_meier(dur, obs, x)
    expected = p.p_sh * np.exp(-x / p.tau_s) + (1 - p.p_sh) * np.exp(-x / p.tau_l)
    # Greenwood s.e. from > 10,000 stops; 4.5 s.e. per point (9 points: false alarm < 1e-4)
    np.testing.assert_array_less(np.abs(surv - expected), 4.5 * se + 1e-12)
    # for x >> tau_s only long stops survive: S(x) = (1 - p_sh) e^{-x / tau_l} (+ 5e-5)
    at5 = x == 5.0
    short_fraction = 1 - surv[at5][0] / math.exp(-5.0 / p.tau_l)
    assert short_fraction == pytest.approx(p.p_sh, abs=4.5 * se[at5][0] / math.exp(-5.0 / p.tau_l))


@pytest.mark.slow
def test_moving_time_between_stops_is_exponential(natural_run):
    p = MotionParams()
    dur, obs = episodes(natural_run, inside=(RW, WF), ending=(S,))
    assert len(dur) > 10_000
    x = np.array([0.1, 1.0, 5.0, 10.0, 20.0, 40.0, 60.0])
    surv, se = kaplan_meier(dur, obs, x)
    np.testing.assert_array_less(np.abs(surv - np.exp(-x / p.tau_stop)), 4.5 * se + 1e-12)


@pytest.mark.slow
def test_wall_following_time_until_exit_is_exponential_and_pauses_during_stops(natural_run):
    p = MotionParams()
    # WF time counts WF runs only: an S run inside the episode pauses it
    dur, obs = episodes(natural_run, inside=(WF,), ending=(RW,))
    assert obs.sum() > 3_000
    x = np.array([0.1, 1.0, 5.0, 10.0, 20.0, 30.0])
    surv, se = kaplan_meier(dur, obs, x)
    np.testing.assert_array_less(np.abs(surv - np.exp(-x / p.tau_exit)), 4.5 * se + 1e-12)


def test_wall_following_keeps_speed_v_p_and_its_offset_along_straight_walls():
    arena = Arena(box(0, 0, 500, 500))
    motion = MotionParams(tau_stop=math.inf)
    n = 200
    sim = simulate(arena, n, 60.0, dt=DT, motion=motion, rng=5, trajectory_every=DT)
    x, y, state = per_step(sim.trajectories, n)
    corners = np.array([[0, 0], [500, 0], [500, 500], [0, 500]])

    def corner_distance(px, py):
        return np.min(np.hypot(px[..., None] - corners[:, 0], py[..., None] - corners[:, 1]), axis=-1)

    wf = state[:-1] == WF
    straight = wf & (corner_distance(x[:-1], y[:-1]) > 80) & (corner_distance(x[1:], y[1:]) > 80)
    speed = np.hypot(np.diff(x, axis=0), np.diff(y, axis=0))[straight] / DT
    assert straight.sum() > 5_000
    assert np.median(speed) == pytest.approx(motion.v_p, abs=1e-9)
    assert np.quantile(speed, 0.99) == pytest.approx(motion.v_p, abs=1e-9)
    wall_distance = arena.distance_to_boundary(x[1:][wf], y[1:][wf])  # after each WF move
    assert wall_distance.min() >= MIN_WALL_OFFSET_FRACTION * 30.0 - 1e-9
    assert wall_distance.max() <= 30.0 + motion.v_p * DT + 1e-9


@pytest.mark.slow
def test_exit_angles_are_uniform_on_zero_to_pi():
    arena = Arena(box(0, 0, 500, 500))
    n = 400
    sim = simulate(arena, n, 300.0, dt=DT, motion=MotionParams(tau_stop=math.inf), rng=8,
                   trajectory_every=DT)
    x, y, state = per_step(sim.trajectories, n)
    corners = np.array([[0, 0], [500, 0], [500, 500], [0, 500]])
    k, i = np.nonzero((state[1:-1] == RW) & (state[:-2] == WF))
    k = k + 1  # exit decided at step k: p_{k-1} -> p_k along the wall, p_k -> p_{k+1} RW
    far = np.ones(len(k), bool)
    for px, py in ((x[k - 1, i], y[k - 1, i]), (x[k, i], y[k, i])):
        far &= np.min(np.hypot(px[:, None] - corners[:, 0], py[:, None] - corners[:, 1]), axis=1) > 80
    k, i = k[far], i[far]
    wall = np.c_[x[k, i] - x[k - 1, i], y[k, i] - y[k - 1, i]]
    out = np.c_[x[k + 1, i] - x[k, i], y[k + 1, i] - y[k, i]]
    cos = np.sum(wall * out, axis=1) / (np.linalg.norm(wall, axis=1) * np.linalg.norm(out, axis=1))
    angle = np.arccos(np.clip(cos, -1, 1))
    assert len(angle) > 1_000
    # the exit heading turns into free space: the first RW step moves away from the wall
    d0 = arena.distance_to_boundary(x[k, i], y[k, i])
    d1 = arena.distance_to_boundary(x[k + 1, i], y[k + 1, i])
    turned = np.abs(np.sin(angle)) > 0.05
    assert np.mean(d1[turned] > d0[turned]) > 0.9  # ~5 % renew the segment within the step
    # a segment renewal within the first step (5 %) gives a uniform angle too
    assert stats.kstest(angle, stats.uniform(0, math.pi).cdf).pvalue > 1e-3


@pytest.mark.slow
def test_agents_never_enter_obstacles_nor_cross_walls_in_a_non_convex_arena():
    arena = l_shaped_arena()
    n = 200
    commands = [Command(100.0, "RW", fraction=0.5), Command(200.0, "WF", fraction=0.3),
                Command(300.0, "free", fraction=1.0)]
    sim = simulate(arena, n, 400.0, dt=DT, commands=commands, rng=13, trajectory_every=DT)
    x, y, _ = per_step(sim.trajectories, n)
    assert np.all(arena.contains(x.ravel(), y.ravel()))
    moved = (np.diff(x, axis=0) != 0) | (np.diff(y, axis=0) != 0)
    k, i = np.nonzero(moved)
    paths = shapely.linestrings(np.stack([np.c_[x[k, i], y[k, i]], np.c_[x[k + 1, i], y[k + 1, i]]], axis=1))
    boundary = arena.geometry.boundary
    shapely.prepare(boundary)
    assert not np.any(shapely.intersects(paths, boundary))
    assert np.all(arena.distance_to_boundary(x.ravel()[::7], y.ravel()[::7]) > 0)
