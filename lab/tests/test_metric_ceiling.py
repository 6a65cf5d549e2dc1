"""lab/metric_ceiling.py reads windows with the truth as its docstring says."""

import importlib.util
import sys
from pathlib import Path

import numpy as np
import shapely

from swarmtopo.arena import square_arena
from swarmtopo.topology.cycles import event_positions
from swarmtopo.metric.graph import build_graph
from swarmtopo.sim import simulate

_benchmarks = Path(__file__).parent.parent
sys.path.insert(0, str(_benchmarks))  # metric_ceiling imports metric_vs_truth as a sibling
_spec = importlib.util.spec_from_file_location("metric_ceiling", _benchmarks / "metric_ceiling.py")
metric_ceiling = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(metric_ceiling)
sys.path.remove(str(_benchmarks))


def test_geodesic_distances_go_round_a_wall_by_hand():
    # a wall from y = 100 to 400 at x = 245-255 in a 500 mm square: (200, 350) to (300, 350)
    # is 100 mm as the crow flies; round the wall's nearer end (250, 400) it is
    # 2 x hypot(50, 50) = 141.4 mm (round the other, 2 x hypot(50, 250) = 509.9 mm); the
    # 8-connected grid of 5 mm overestimates by < 8.3 %
    wall = shapely.box(245.0, 100.0, 255.0, 400.0)
    arena = square_arena(500.0, [wall])
    g = metric_ceiling.geodesic_distances(arena, np.array([[200.0, 350.0], [300.0, 350.0], [200.0, 300.0]]))
    assert g[0, 0] == 0 and np.allclose(g, g.T)
    round_the_end = 2 * np.hypot(50.0, 50.0)
    assert round_the_end - 15 <= g[0, 1] <= 1.083 * round_the_end + 15
    assert 50 - 1e-9 <= g[0, 2] <= 1.083 * 50 + 10  # same side of the wall: straight


def test_truth_maxmin_draws_far_apart_in_truth_and_gives_the_metrics_covering_radii():
    sim = simulate(square_arena(300.0), 40, 20.0, rng=3, truth=True)
    graph = build_graph(sim.log, "hybrid", hop_cost=2.0, diffusion_time=0.5, wall_follow_weight=2.0)
    land = metric_ceiling._truth_maxmin(sim.truth)(graph, None, 12, 0)
    nodes = land.nodes
    assert len(set(nodes.tolist())) == 12
    # farthest-point order on the true positions: each pick is the node farthest from the
    # picks before it (Euclidean), up to ties
    positions = event_positions(sim.truth, graph.representative_event())
    for i in range(1, len(nodes)):
        to_picks = np.linalg.norm(positions[:, None, :] - positions[nodes[:i]][None], axis=2).min(axis=1)
        assert to_picks[nodes[i]] >= to_picks.max() - 1e-6
    # covering radii in the encounter metric: max over nodes of the distance to the first i picks
    to_nodes = graph.distances_from(nodes)
    expected = np.array([to_nodes[:i + 1].min(axis=0).max() for i in range(len(nodes))])
    np.testing.assert_allclose(land.cover_radii, expected, rtol=1e-9)
    np.testing.assert_allclose(land.distances, to_nodes[:, nodes], rtol=1e-9, atol=1e-9)
