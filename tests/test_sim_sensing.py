"""Encounter tracking: scripted trajectories, brute-force agreement, simulated logs."""

import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon, box

from swarmtopo import Arena
from swarmtopo.sim import EncounterTracker, SensingParams, simulate
from swarmtopo.sim.sensing import new_keys

R_D = 30.0


def run_script(tracker, positions):
    """Feed (steps, agents, 2) positions; return the events as (step, a, b) tuples."""
    events = []
    for k, p in enumerate(positions):
        a, b = tracker.update(0.5 * k, p[:, 0], p[:, 1])
        events += [(k, int(i), int(j)) for i, j in zip(a, b)]
    return events


def wall_arena():
    """200 mm square with a 2 mm thick wall from y = 20 to y = 180 at x = 100."""
    return Arena(Polygon(box(0, 0, 200, 200).exterior.coords, [box(99, 20, 101, 180).exterior.coords]))


def brute_force_contacts(x, y, r_d, arena=None):
    """All pairs a < b within r_d (and in line of sight if ``arena``), sorted."""
    a, b = np.triu_indices(len(x), 1)
    dx, dy = x[b] - x[a], y[b] - y[a]
    near = dx * dx + dy * dy <= r_d * r_d
    a, b = a[near], b[near]
    if arena is not None and len(a):
        sight = shapely.linestrings(np.stack([np.c_[x[a], y[a]], np.c_[x[b], y[b]]], axis=1))
        keep = ~shapely.intersects(sight, arena.geometry.boundary)
        a, b = a[keep], b[keep]
    return set(zip(a.tolist(), b.tolist()))


def test_approach_stay_leave_return_gives_exactly_two_events():
    path = [100, 50, 29, 10, 20, 29.9, 31, 60, 25, 25, 30.0]  # agent 1 along x; agent 0 at origin
    positions = np.array([[[0.0, 0.0], [px, 0.0]] for px in path])
    events = run_script(EncounterTracker(2, R_D), positions)
    assert events == [(2, 0, 1), (8, 0, 1)]


def test_distance_exactly_r_d_is_a_contact():
    positions = np.array([[[0.0, 0.0], [40.0, 0.0]], [[0.0, 0.0], [R_D, 0.0]]])
    assert run_script(EncounterTracker(2, R_D), positions) == [(1, 0, 1)]


def test_a_wall_between_close_agents_hides_them_only_when_walls_block():
    arena = wall_arena()
    # 20 mm apart across the wall, then both move above the wall's end (y > 180): contact
    positions = np.array([[[90.0, 100.0], [110.0, 100.0]], [[90.0, 190.0], [110.0, 190.0]]])
    assert run_script(EncounterTracker(2, R_D, arena), positions) == [(1, 0, 1)]
    assert run_script(EncounterTracker(2, R_D, None), positions) == [(0, 0, 1)]


@pytest.mark.parametrize("log_initial", [True, False])
def test_initial_contacts_follow_the_flag(log_initial):
    positions = np.array([[[0.0, 0.0], [10.0, 0.0]], [[0.0, 0.0], [12.0, 0.0]],
                          [[0.0, 0.0], [80.0, 0.0]], [[0.0, 0.0], [5.0, 0.0]]])
    events = run_script(EncounterTracker(2, R_D, log_initial_contacts=log_initial), positions)
    assert events == ([(0, 0, 1)] if log_initial else []) + [(3, 0, 1)]


def test_events_of_one_step_are_sorted_by_pair():
    x = np.array([50.0, 0.0, 10.0, 500.0, 20.0])
    y = np.zeros(5)
    a, b = EncounterTracker(5, R_D).update(0.0, x, y)
    pairs = list(zip(a.tolist(), b.tolist()))
    assert pairs == sorted(brute_force_contacts(x, y, R_D))
    assert pairs == [(0, 4), (1, 2), (1, 4), (2, 4)]


@pytest.mark.parametrize("spread", ["dense", "sparse"])
def test_cell_list_contacts_match_all_pairs_with_line_of_sight(spread):
    rng = np.random.default_rng(4)
    arena = Arena(Polygon(box(0, 0, 400, 400).exterior.coords,
                          [box(100, 100, 180, 300).exterior.coords, [(250, 250), (350, 260), (260, 330)]]))
    xy = arena.sample_uniform(600, rng)
    if spread == "sparse":  # a few agents far away: the cell side grows past r_d
        xy[:5] = rng.uniform(-1e6, 1e6, (5, 2))
    tracker = EncounterTracker(len(xy), R_D, arena)
    tracker.update(0.0, xy[:, 0], xy[:, 1])
    got = set(zip(*(c.tolist() for c in tracker.contacts)))
    assert got == brute_force_contacts(xy[:, 0], xy[:, 1], R_D, arena)
    assert len(got) > 300


def test_update_times_must_increase():
    tracker = EncounterTracker(2, R_D)
    tracker.update(1.0, np.zeros(2), np.zeros(2))
    with pytest.raises(ValueError, match="increase"):
        tracker.update(1.0, np.zeros(2), np.zeros(2))


def test_new_keys_is_the_sorted_set_difference():
    rng = np.random.default_rng(0)
    for _ in range(50):
        prev = np.unique(rng.integers(0, 40, 15))
        cur = np.unique(rng.integers(0, 40, 15))
        out = np.empty(len(cur), np.int64)
        m = new_keys(prev, cur, out)
        np.testing.assert_array_equal(out[:m], np.setdiff1d(cur, prev))


def test_simulated_log_matches_brute_force_contact_periods():
    arena = wall_arena()
    n = 40
    sim = simulate(arena, n, 30.0, rng=3, truth=True, trajectory_every=0.1)
    traj = sim.trajectories
    x, y = traj["x"].reshape(-1, n), traj["y"].reshape(-1, n)
    times = traj["t"][::n]
    expected, previous = [], set()
    for k in range(len(times)):
        now = brute_force_contacts(x[k], y[k], R_D, arena)
        expected += [(times[k], a, b) for a, b in sorted(now - previous)]
        previous = now
    log = sim.log
    assert list(zip(log.t.tolist(), log.a.tolist(), log.b.tolist())) == expected
    assert len(expected) > 50
    # truth rows align with the log and with the sampled positions
    truth = sim.truth
    np.testing.assert_array_equal(truth["t"], log.t)
    np.testing.assert_array_equal(truth["a"], log.a)
    np.testing.assert_array_equal(truth["b"], log.b)
    assert np.all(np.hypot(truth["xa"] - truth["xb"], truth["ya"] - truth["yb"]) <= R_D)
    step = np.rint(log.t / 0.1).astype(int)
    np.testing.assert_array_equal(truth["xa"], x[step, log.a])
    np.testing.assert_array_equal(truth["yb"], y[step, log.b])


@pytest.mark.parametrize("log_initial", [True, False])
def test_simulation_logs_initial_contacts_at_t0_per_flag(log_initial):
    arena = Arena(box(0, 0, 150, 150))  # dense: many pairs in contact at t = 0
    n = 60
    sim = simulate(arena, n, 1.0, rng=9, trajectory_every=0.1,
                   sensing=SensingParams(log_initial_contacts=log_initial))
    x0, y0 = sim.trajectories["x"][:n], sim.trajectories["y"][:n]
    at0 = sim.log.t == 0
    initial = brute_force_contacts(x0, y0, R_D, arena)
    assert len(initial) > 20
    got = set(zip(sim.log.a[at0].tolist(), sim.log.b[at0].tolist()))
    assert got == (initial if log_initial else set())


def _literal_wall_grid_pairs(segs, bounds, cell, reach):
    """Every cell of the bounding box tested against every segment (the definition)."""
    import math

    xmin, ymin, xmax, ymax = bounds
    ncx, ncy = max(1, math.ceil((xmax - xmin) / cell)), max(1, math.ceil((ymax - ymin) / cell))
    cy, cx = np.divmod(np.arange(ncx * ncy), ncx)
    boxes = shapely.box(xmin + cx * cell, ymin + cy * cell, xmin + (cx + 1) * cell, ymin + (cy + 1) * cell)
    lines = shapely.linestrings(np.asarray(segs, float).reshape(-1, 2, 2))
    cell_id, seg_id = shapely.STRtree(lines).query(boxes, predicate="dwithin", distance=reach)
    return sorted(zip(cell_id.tolist(), seg_id.tolist()))


@pytest.mark.parametrize("seed, cell, reach", [(0, 30.0, 30.0), (1, 30.0, 34.5), (2, 17.0, 50.0), (3, 45.0, 10.0)])
def test_wall_grid_lists_exactly_the_segments_within_reach_of_each_cell(seed, cell, reach):
    from swarmtopo.arena import random_arena
    from swarmtopo.sim.walls import build_wall_grid

    arena = random_arena(3, rng=seed, shapes=("disc", "triangle", "wall", "L"), outer="polygon")
    grid = build_wall_grid(arena.boundary_segments, arena.bounds, cell=cell, reach=reach)
    pairs = sorted((c, int(grid.index[k])) for c in range(grid.ncx * grid.ncy)
                   for k in range(grid.start[c], grid.start[c + 1]))
    assert pairs == _literal_wall_grid_pairs(arena.boundary_segments, arena.bounds, cell, reach)


def test_a_reach_beyond_the_arena_lists_every_wall_in_its_one_cell_without_overflow():
    import warnings

    from swarmtopo.arena import random_arena
    from swarmtopo.sim.walls import build_wall_grid

    arena = random_arena(2, rng=4)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a reach of 1e300 used to overflow in shapely's dwithin
        grid = build_wall_grid(arena.boundary_segments, arena.bounds, cell=1e300, reach=1e300)
    assert grid.ncx == grid.ncy == 1 and sorted(grid.index.tolist()) == list(range(len(arena.boundary_segments)))


def test_a_large_arena_builds_its_wall_grid_along_the_walls_and_an_absurd_one_is_refused():
    from swarmtopo.arena import square_arena
    from swarmtopo.errors import SwarmtopoError
    from swarmtopo.sim.walls import MAX_WALL_CELLS, build_wall_grid

    big = square_arena(100_000.0)  # 100 m: 11 million cells, of which only those along the walls are listed
    grid = build_wall_grid(big.boundary_segments, big.bounds, cell=30.0, reach=30.0)
    assert grid.ncx == grid.ncy == 3334 and 4 * 3334 <= len(grid.index) <= 4 * 3 * 3334
    huge = square_arena(1e6)
    with pytest.raises(SwarmtopoError, match="are its coordinates in mm"):
        build_wall_grid(huge.boundary_segments, huge.bounds, cell=30.0, reach=30.0)
    assert (1e6 / 30.0) ** 2 > MAX_WALL_CELLS
