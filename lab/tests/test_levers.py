"""lab/levers.py's graph surgery keeps what its docstring promises."""

import importlib.util
from pathlib import Path

import numpy as np

from swarmtopo.arena import random_arena
from swarmtopo.metric.graph import build_graph
from swarmtopo.sim import simulate

_spec = importlib.util.spec_from_file_location("levers", Path(__file__).parent.parent / "levers.py")
levers = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(levers)


def test_paths_cut_every_edge_and_keep_event_distances():
    log = simulate(random_arena(1, rng=0), 60, 10.0, rng=0).log
    graph = build_graph(log, "hybrid", hop_cost=2.0, diffusion_time=0.5, wall_follow_weight=2.0)
    step = 1.0
    cut = levers._subdivided(graph, step)
    weights = graph.adjacency.data
    # an edge of weight w becomes ceil(w / step) pieces: ceil(w / step) - 1 new nodes each
    assert cut.n_nodes - graph.n_nodes == int(np.sum(np.ceil(weights / step - 1e-9) - 1)) // 2
    assert cut.adjacency.data.max() <= step + 1e-9
    assert (cut.multiplicity[graph.n_nodes:] == 1).all()
    sources = np.arange(0, graph.n_nodes, 5)
    before = graph.distances_from(sources)
    after = cut.distances_from(sources)[:, :graph.n_nodes]
    np.testing.assert_allclose(after, before, rtol=1e-12, atol=1e-9)


def test_dtm_filtration_of_a_square_by_hand():
    # four landmarks on a unit square; each has its nearest node at 0 and the next at
    # c sqrt(2), so with K = 2 every f_i = sqrt((0 + 2 c^2) / 2) = c
    c = 0.3
    side, diagonal = 1.0, np.sqrt(2.0)
    distances = np.array([[0, side, diagonal, side], [side, 0, side, diagonal],
                          [diagonal, side, 0, side], [side, diagonal, side, 0]])
    to_nodes = np.array([[0.0, c * np.sqrt(2.0), 5.0]] * 4)
    diagram = levers._dtm_persistence(to_nodes, distances, 2, 1).diagram
    # equal weights: vertices enter at c, an edge of length d at c + d / 2
    np.testing.assert_allclose(diagram[0][np.isfinite(diagram[0][:, 1])], [[c, c + side / 2]] * 3)
    np.testing.assert_allclose(diagram[1], [[c + side / 2, c + diagonal / 2]])


def test_draws_of_a_variant_pool_that_variants_windows_at_consecutive_seeds():
    """``draws-K/VARIANT@D``: VARIANT mapped with seeds s + D, ..., s + D + K - 1, windows concatenated."""
    log = simulate(random_arena(1, rng=3), 60, 10.0, rng=3).log
    regions, beta0 = levers._variant("draws-2/max_landmarks=40@1")(log, 5)
    parts = [levers._windows_of(log, seed, max_landmarks=40) for seed in (6, 7)]
    assert beta0 == parts[0][1]
    expected = [a + b for a, b in zip(parts[0][0], parts[1][0])]
    assert [[d.lengths(1).tolist() for d in r] for r in regions] == \
        [[d.lengths(1).tolist() for d in r] for r in expected]


def test_padding_by_nothing_is_the_default_and_restores_the_pipeline():
    """``pad-0``: the window's own graph, every node a candidate, the same first pick: the default's diagrams."""
    log = simulate(random_arena(2, rng=4), 200, 30.0, rng=4).log
    originals = (levers.P.weighted_chains, levers.P.map_band, levers.T.subsample)
    padded, beta0 = levers._variant("pad-0")(log, 9)
    default, default_beta0 = levers._windows_of(log, 9)
    assert (levers.P.weighted_chains, levers.P.map_band, levers.T.subsample) == originals
    assert beta0 == default_beta0
    assert [[d.lengths(1).tolist() for d in r] for r in padded] == [[d.lengths(1).tolist() for d in r] for r in default]
    wider, _ = levers._variant("pad-0.5")(log, 9)
    assert [len(r) for r in wider] == [len(r) for r in default] and len(default[0]) > 1  # the same windows
    assert [[d.lengths(1).tolist() for d in r] for r in wider] != [[d.lengths(1).tolist() for d in r] for r in default]


def test_swarm_variants_name_their_swarm_and_inner_variant():
    assert levers._swarm("static-0.1", 200) == (200, 0.1, "default")
    assert levers._swarm("static-0.2/pad-0.5", 200) == (200, 0.2, "pad-0.5")
    assert levers._swarm("static-0.1@2", 200) == (200, 0.1, "default@2")
    assert levers._swarm("extra-0.1", 200) == (220, 0.0, "default")
    agents, static, inner = levers._swarm("extra-static-0.1/wall-3", 200)
    assert (agents, inner) == (220, "wall-3") and round(static * agents) == 20  # the 20 added agents parked
    assert levers._swarm("wall-3", 300) == (300, 0.0, "wall-3")


def test_a_pool_of_variants_concatenates_their_windows_in_order():
    """``pool:V1+V2``: each region's windows of V1, then of V2; beta_0 of V1."""
    log = simulate(random_arena(1, rng=3), 60, 10.0, rng=3).log
    regions, beta0 = levers._variant("pool:max_landmarks=40+hop-double")(log, 5)
    first, second = levers._windows_of(log, 5, max_landmarks=40), levers._variant("hop-double")(log, 5)
    assert beta0 == first[1]
    expected = [a + b for a, b in zip(first[0], second[0])]
    assert [[d.lengths(1).tolist() for d in r] for r in regions] == \
        [[d.lengths(1).tolist() for d in r] for r in expected]
    assert len(regions[0]) == len(first[0][0]) + len(second[0][0])

