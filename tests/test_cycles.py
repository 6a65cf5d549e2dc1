"""Representative cycles of H1 bars (swarmtopo.topology.cycles)."""

import itertools

import networkx as nx
import numpy as np
import pytest
import shapely

from swarmtopo.arena import default_arena
from swarmtopo.topology.cycles import (Cycle, encircled_obstacles, event_positions, localization_scores, odd_winding,
                              region_cycles, representative_cycles, shortest_odd_loop, wilson_interval)
from swarmtopo.errors import InputError
from swarmtopo.topology.persistence import rips_persistence


def _euclidean(xy):
    return np.sqrt(((xy[:, None, :] - xy[None, :, :]) ** 2).sum(-1))


def _circle(n, centre=(0.0, 0.0), radius=1.0, phase=0.0):
    angle = phase + 2 * np.pi * np.arange(n) / n
    return np.column_stack([centre[0] + radius * np.cos(angle), centre[1] + radius * np.sin(angle)])


def _turns(xy, centre):
    """Winding number of the closed polygon xy around centre (sum of turning angles / 2 pi)."""
    angle = np.arctan2(xy[:, 1] - centre[1], xy[:, 0] - centre[0])
    step = np.diff(np.append(angle, angle[0]))
    return (step + np.pi) % (2 * np.pi) - np.pi


def _cocycle_edges(result, index):
    cocycle = np.asarray(result.cocycles[1][index]).reshape(-1, 3)
    return {frozenset(map(int, e)) for e in cocycle[cocycle[:, 2] % 2 == 1, :2]}


def _crossings(loop, edges):
    return sum(frozenset((int(u), int(v))) in edges for u, v in zip(loop, np.roll(loop, -1)))


def test_unit_square_loop_is_the_four_sides():
    # Bar [1, sqrt 2): at the midpoint only the four sides are edges, so the one loop is the square, length 4.
    xy = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    d = _euclidean(xy)
    result = rips_persistence(d, cocycles=True)
    (cycle,) = representative_cycles(d, result)
    assert cycle.bar == pytest.approx((1.0, np.sqrt(2)))
    assert cycle.scale == pytest.approx((1 + np.sqrt(2)) / 2)
    assert cycle.length == pytest.approx(4.0)
    assert sorted(cycle.landmarks) == [0, 1, 2, 3]
    assert all(d[u, v] == 1.0 for u, v in zip(cycle.landmarks, np.roll(cycle.landmarks, -1)))


@pytest.mark.parametrize("position", [0.0, 0.5, 0.9])
def test_circle_cycle_goes_round_once_and_crosses_the_cocycle_oddly(position):
    xy = _circle(24)
    d = _euclidean(xy)
    result = rips_persistence(d, cocycles=True)
    (cycle,) = representative_cycles(d, result, bars=[0], position=position)
    loop = cycle.landmarks
    assert len(set(loop.tolist())) == len(loop) >= 3  # simple loop
    assert abs(_turns(xy[loop], (0, 0)).sum()) == pytest.approx(2 * np.pi)
    assert _crossings(loop, _cocycle_edges(result, 0)) % 2 == 1
    assert all(d[u, v] <= cycle.scale for u, v in zip(loop, np.roll(loop, -1)))
    # A closed polygon with vertices on the unit circle around its centre has two vertices at least
    # 120 degrees apart (diameter >= sqrt 3), and a closed curve is at least twice its diameter long.
    assert cycle.length >= 2 * np.sqrt(3)
    # ... and it is no longer than the polygon through all 24 points.
    assert cycle.length <= 24 * d[0, 1] + 1e-12


def test_two_circles_give_one_loop_on_each():
    xy = np.vstack([_circle(16), _circle(16, centre=(6.0, 0.0), radius=1.5, phase=0.1)])
    d = _euclidean(xy)
    result = rips_persistence(d, cocycles=True)
    cycles = representative_cycles(d, result, threshold=0.5)
    assert len(cycles) == 2
    sides = sorted(int(np.all(c.landmarks >= 16)) for c in cycles)
    assert sides == [0, 1]  # each loop lies entirely on one circle, one per circle
    for c in cycles:
        centre = (6.0, 0.0) if c.landmarks[0] >= 16 else (0.0, 0.0)
        assert np.all((c.landmarks >= 16) == (c.landmarks[0] >= 16))
        assert abs(_turns(xy[c.landmarks], centre).sum()) == pytest.approx(2 * np.pi)


def _literal_shortest_odd_loop(d, edges, scale):
    """Enumerate every simple cycle of the Rips graph and keep the shortest odd one."""
    n = len(d)
    graph = nx.Graph([(i, j) for i, j in itertools.combinations(range(n), 2) if d[i, j] <= scale])
    best = np.inf
    for cycle in nx.simple_cycles(graph):
        if len(cycle) >= 3 and _crossings(cycle, edges) % 2 == 1:
            best = min(best, sum(d[u, v] for u, v in zip(cycle, np.roll(cycle, -1))))
    return best


@pytest.mark.parametrize("seed", range(4))
def test_agrees_with_enumerating_every_simple_cycle(seed):
    rng = np.random.default_rng(seed)
    xy = _circle(9) * rng.uniform(0.8, 1.2, (9, 1)) + rng.normal(0, 0.05, (9, 2))
    d = _euclidean(xy)
    result = rips_persistence(d, cocycles=True)
    for index, (b, death) in enumerate(result.diagram[1]):
        scale = 0.5 * (b + death)
        edges = _cocycle_edges(result, index)
        loop = shortest_odd_loop(d, np.array([tuple(e) for e in edges]), scale)
        length = sum(d[u, v] for u, v in zip(loop, np.roll(loop, -1)))
        assert length == pytest.approx(_literal_shortest_odd_loop(d, edges, scale))


def test_no_odd_loop_in_a_tree_graph():
    # Three points on a line at scale 1: the Rips graph is the path 0-1-2, no loop exists.
    d = _euclidean(np.array([[0.0, 0], [1, 0], [2, 0]]))
    assert shortest_odd_loop(d, np.array([[0, 1]]), 1.0) is None


def test_needs_cocycles():
    d = _euclidean(_circle(8))
    with pytest.raises(InputError, match="cocycles"):
        representative_cycles(d, rips_persistence(d, backend="gudhi"))
    with pytest.raises(InputError, match="position"):
        representative_cycles(d, rips_persistence(d, cocycles=True), position=1.0)


def test_odd_winding_on_simple_eight_and_double_loops():
    square = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], float)
    points = np.array([[1, 1], [3, 1], [-1, 1]], float)
    assert odd_winding(square, points).tolist() == [True, False, False]
    # Figure eight: each lobe is wound once (odd), the crossing point's outside is not.
    eight = np.array([[0, 0], [2, 2], [4, 0], [4, 2], [2, 0], [0, 2]], float)
    assert odd_winding(eight, np.array([[0.5, 1], [3.5, 1], [2, 3]])).tolist() == [True, True, False]
    # Twice round: winding number 2, even, not encircled in Z/2.
    twice = np.vstack([square, square])
    assert odd_winding(twice, np.array([[1.0, 1.0]])).tolist() == [False]


def test_encircled_obstacles_of_the_default_arena():
    arena = default_arena()  # hole [175, 325]^2
    around = np.array([[150, 150], [350, 150], [350, 350], [150, 350]], float)
    beside = np.array([[20, 20], [120, 20], [120, 120], [20, 120]], float)
    # Cutting a corner of the hole: still encloses well over half of it.
    corner_cut = np.array([[150, 150], [350, 150], [350, 300], [300, 350], [150, 350]], float)
    assert encircled_obstacles(around, arena) == [0]
    assert encircled_obstacles(beside, arena) == []
    assert encircled_obstacles(corner_cut, arena) == [0]
    assert encircled_obstacles(np.vstack([around, around]), arena) == []


def test_scores_and_wilson_interval():
    scores = localization_scores([([[0], [0, 1], []], 2), ([[1]], 2)])
    assert (scores.detected, scores.correct, scores.obstacles, scores.found) == (4, 2, 4, 3)
    assert scores.precision == 0.5 and scores.recall == 0.75
    # Reference values of the Wilson score interval (z = 1.96).
    assert wilson_interval(5, 10) == pytest.approx((0.2366, 0.7634), abs=1e-4)
    assert wilson_interval(0, 10) == pytest.approx((0.0, 0.2775), abs=1e-4)


def test_simulated_one_hole_cycle_encircles_the_hole(demo_run, demo_map):
    # The demo's log (seed 0, 200 agents x 30 s): the default finds beta_1 = 1 (checked below).
    sim, tmap = demo_run, demo_map
    assert tmap.betti[1] == 1
    (region,) = tmap.regions
    cycles = region_cycles(region)
    assert len(cycles) == 1
    cycle = cycles[0]
    assert isinstance(cycle, Cycle)
    assert np.array_equal(cycle.events, region.landmark_events[cycle.landmarks])
    loop_xy = event_positions(sim.truth, cycle.events)
    assert encircled_obstacles(loop_xy, sim.arena) == [0]
    hole = sim.arena.obstacles[0]
    assert shapely.Polygon(loop_xy).is_valid and shapely.Polygon(loop_xy).contains(hole.centroid)
    again = region_cycles(region)
    assert np.array_equal(again[0].landmarks, cycle.landmarks)
    doc = cycle.to_json()
    assert doc["events"] == [int(e) for e in cycle.events] and doc["bar"][1] == pytest.approx(cycle.bar[1])
