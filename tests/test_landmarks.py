"""Landmark subsampling: agreement with dense literal versions, theorems, robustness."""

import re
from dataclasses import dataclass

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components, shortest_path
from scipy.spatial import cKDTree

from swarmtopo.errors import InputError, SwarmtopoError
from swarmtopo.metric.graph import build_graph, literal_distances
from swarmtopo.metric.landmarks import (SUBSAMPLERS, Landmarks, covering_prefix, knn_distances, knn_maxmin, maxmin,
                                 probabilistic_maxmin)
from swarmtopo.log import EncounterLog

RTOL = 1e-12  # distances from different Dijkstra codes differ only by summation rounding


@dataclass(frozen=True, eq=False)
class Graph:
    """The part of EncounterGraph the landmark code reads."""

    adjacency: sp.csr_matrix
    multiplicity: np.ndarray


def graph_from_edges(n, i, j, w, multiplicity=None) -> Graph:
    i, j, w = np.asarray(i), np.asarray(j), np.asarray(w, float)
    adjacency = sp.csr_matrix((np.r_[w, w], (np.r_[i, j], np.r_[j, i])), shape=(n, n))
    mult = np.ones(n, np.int64) if multiplicity is None else np.asarray(multiplicity, np.int64)
    return Graph(adjacency, mult)


def random_geometric_graph(n, seed, radius=0.18, max_multiplicity=3) -> Graph:
    """Largest component of a random geometric graph in the unit square, Euclidean weights."""
    rng = np.random.default_rng(seed)
    points = rng.uniform(0, 1, (n, 2))
    pairs = cKDTree(points).query_pairs(radius, output_type="ndarray")
    w = np.linalg.norm(points[pairs[:, 0]] - points[pairs[:, 1]], axis=1)
    g = graph_from_edges(n, pairs[:, 0], pairs[:, 1], w, rng.integers(1, max_multiplicity + 1, n))
    _, labels = connected_components(g.adjacency, directed=False)
    keep = np.flatnonzero(labels == np.argmax(np.bincount(labels)))
    return Graph(g.adjacency[keep][:, keep].tocsr(), g.multiplicity[keep])


def noisy_cycle_with_outliers(n_cycle=120, n_outliers=4, far=25.0, seed=0) -> tuple[Graph, np.ndarray]:
    """A cycle with random edge lengths in [0.5, 1.5] and ``n_outliers`` pendant nodes at
    distance ``far`` from evenly spaced cycle nodes.  Returns the graph and the outliers."""
    rng = np.random.default_rng(seed)
    i = np.arange(n_cycle)
    w = rng.uniform(0.5, 1.5, n_cycle)
    outliers = np.arange(n_cycle, n_cycle + n_outliers)
    anchors = np.arange(n_outliers) * (n_cycle // n_outliers)
    g = graph_from_edges(n_cycle + n_outliers, np.r_[i, outliers], np.r_[(i + 1) % n_cycle, anchors],
                         np.r_[w, np.full(n_outliers, far)])
    return g, outliers


# -- dense literal versions (all-pairs matrix, textbook loops) ---------------------------
def dense(g: Graph) -> np.ndarray:
    return shortest_path(g.adjacency, directed=False)


def literal_knn(g: Graph, k: int) -> np.ndarray:
    """k-NN distances of every node from the event-level point cloud (multiplicity expanded)."""
    node_of_event = np.repeat(np.arange(len(g.multiplicity)), g.multiplicity)
    d_events = dense(g)[np.ix_(node_of_event, node_of_event)]
    first_event = np.searchsorted(node_of_event, np.arange(len(g.multiplicity)))
    rows = []
    for e in first_event:
        others = np.sort(np.delete(d_events[e], e))
        rows.append(np.r_[others, np.full(k, np.inf)][:k])
    return np.array(rows)


def literal_farthest_points(d, candidates, n_landmarks, start, bonus=None):
    """Textbook maxmin on a full matrix; ``bonus(r)`` turns it into argmax u + bonus."""
    chosen, u = [start], d[start].copy()
    radii = [u[candidates].max()]
    while len(chosen) < min(n_landmarks, candidates.sum()):
        if bonus is None:
            score = np.where(candidates, u, -np.inf)
        else:
            score = u + bonus(radii[-1])
            score[chosen] = -np.inf
        x = int(np.argmax(score))
        chosen.append(x)
        u = np.minimum(u, d[x])
        radii.append(u[candidates].max())
    return np.array(chosen), np.array(radii)


def literal_knn_maxmin(g, n_landmarks, k, q, start):
    mean_knn = literal_knn(g, k).mean(axis=1)
    event_values = np.repeat(mean_knn, g.multiplicity)  # one value per event
    keep = mean_knn <= np.quantile(event_values, q)
    return literal_farthest_points(dense(g), keep, n_landmarks, start)


def literal_probabilistic(g, n_landmarks, k, omega, start):
    mean_knn = literal_knn(g, k).mean(axis=1)
    event_values = np.repeat(mean_knn, g.multiplicity)
    rho = np.array([(event_values > m).mean() for m in mean_knn])
    return literal_farthest_points(dense(g), np.ones(len(mean_knn), bool), n_landmarks, start,
                                   bonus=lambda r: (omega * r) * rho)


def assert_matches(result: Landmarks, g: Graph, nodes, radii):
    np.testing.assert_array_equal(result.nodes, nodes)
    np.testing.assert_allclose(result.cover_radii, radii, rtol=RTOL)
    np.testing.assert_allclose(result.distances, dense(g)[np.ix_(nodes, nodes)], rtol=RTOL)
    assert result.cover_radius == result.cover_radii[-1]


# -- agreement with the literal versions --------------------------------------------------
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_maxmin_equals_dense_literal(seed):
    g = random_geometric_graph(250, seed)
    result = maxmin(g, 30, rng=seed)
    nodes, radii = literal_farthest_points(dense(g), np.ones(len(g.multiplicity), bool), 30,
                                           result.nodes[0])
    assert_matches(result, g, nodes, radii)
    assert result.method == "maxmin" and result.params["start"] == result.nodes[0]


@pytest.mark.parametrize("seed", [0, 1])
def test_maxmin_among_candidates_equals_dense_literal(seed):
    # picks only among the candidates, covering radius over them, distances through every node
    g = random_geometric_graph(250, seed)
    candidates = np.random.default_rng(seed).random(len(g.multiplicity)) < 0.4
    result = maxmin(g, 20, rng=seed, candidates=candidates)
    assert candidates[result.nodes].all()
    nodes, radii = literal_farthest_points(dense(g), candidates, 20, result.nodes[0])
    assert_matches(result, g, nodes, radii)
    with pytest.raises(InputError, match="candidates"):
        maxmin(g, 5, rng=seed, candidates=np.zeros(len(g.multiplicity), bool))


@pytest.mark.parametrize("seed", [0, 1])
def test_maxmin_in_a_band_equals_dense_literal(seed):
    # candidates in a strip, as a landmark band is the middle of a window: the searches
    # stop at the covering radius, most of the graph outside the strip is never settled
    # again, and the picks and radii are still those of the full distance matrix
    g = random_geometric_graph(400, seed, radius=0.1)
    x = np.linalg.eigh(dense(g))[1][:, -2]  # any coordinate along the graph will do
    candidates = np.abs(x - np.median(x)) <= np.quantile(np.abs(x - np.median(x)), 0.3)
    result = maxmin(g, 30, rng=seed, candidates=candidates)
    nodes, radii = literal_farthest_points(dense(g), candidates, 30, result.nodes[0])
    assert_matches(result, g, nodes, radii)


@pytest.mark.parametrize("subsample", SUBSAMPLERS)
@pytest.mark.parametrize("quantile", [0.0, 0.3, 0.9])
def test_cover_stops_the_run_at_its_first_covering_prefix(subsample, quantile):
    # with cover c, the run is the full run's first n picks, n = the first pick with
    # radius <= c (at least 3): same nodes, radii and distances
    g = random_geometric_graph(300, 5)
    full = SUBSAMPLERS[subsample](g, 60, rng=5)
    cover = float(np.quantile(full.cover_radii, quantile))
    within = np.flatnonzero(full.cover_radii <= cover)
    n = max(int(within[0]) + 1, 3)
    stopped = SUBSAMPLERS[subsample](g, 60, rng=5, cover=cover)
    np.testing.assert_array_equal(stopped.nodes, full.nodes[:n])
    np.testing.assert_array_equal(stopped.cover_radii, full.cover_radii[:n])
    np.testing.assert_array_equal(stopped.distances, full.distances[:n, :n])
    assert stopped.cover_radius == full.cover_radii[n - 1] and (n == 3 or stopped.cover_radius <= cover)
    np.testing.assert_array_equal(covering_prefix(full, cover).distances, stopped.distances)  # read off the full run


def test_lower_distances_is_exact_up_to_its_limit():
    # the invariant of _kernels.lower_distances: after each landmark with limit r,
    # to_set = d(x, L) where d(x, L) <= r, and to_set >= d(x, L) elsewhere
    from swarmtopo.metric._kernels import Searcher
    g = random_geometric_graph(300, 3, radius=0.12)
    d = dense(g)
    a = g.adjacency
    search = Searcher(a.indptr.astype(np.int64), a.indices.astype(np.int64), a.data.astype(float))
    to_set = np.full(len(d), np.inf)
    order = np.random.default_rng(3).permutation(len(d))[:25]
    limits = np.r_[np.inf, np.linspace(d.max(), d.max() / 10, 24)]
    for i, (node, limit) in enumerate(zip(order, limits)):
        search.add_landmark(int(node), to_set, limit)
        exact = d[order[: i + 1]].min(axis=0)
        within = exact <= limit
        np.testing.assert_allclose(to_set[within], exact[within], rtol=RTOL)
        assert (to_set[~within] >= exact[~within] * (1 - RTOL)).all()
    assert (~within).any() and (to_set[~within] > exact[~within] * (1 + RTOL)).any()  # the limit cut something


@pytest.mark.parametrize("seed", [0, 1])
def test_knn_maxmin_equals_dense_literal(seed):
    g = random_geometric_graph(250, seed)
    result = knn_maxmin(g, 30, k=7, q=0.8, rng=seed)
    nodes, radii = literal_knn_maxmin(g, 30, 7, 0.8, result.nodes[0])
    assert_matches(result, g, nodes, radii)
    mean_knn = literal_knn(g, 7).mean(axis=1)
    kept = mean_knn <= result.params["threshold"]
    assert result.params["n_kept"] == kept.sum() < len(kept)
    assert kept[result.nodes].all()


@pytest.mark.parametrize("omega", [0.3, 1.0, 4.0])
def test_probabilistic_maxmin_equals_dense_literal(omega):
    g = random_geometric_graph(250, 5)
    result = probabilistic_maxmin(g, 30, k=6, omega=omega, rng=5)
    nodes, radii = literal_probabilistic(g, 30, 6, omega, result.nodes[0])
    assert_matches(result, g, nodes, radii)
    assert result.params == {"k": 6, "omega": omega, "start": int(result.nodes[0])}


def test_knn_distances_equal_dense_literal():
    g = random_geometric_graph(200, 3, max_multiplicity=4)
    for k in (1, 5, 12):
        np.testing.assert_allclose(knn_distances(g, k), literal_knn(g, k), rtol=RTOL)


def test_knn_distances_hand_computed_with_multiplicity():
    # path 0 --1-- 1 --2-- 2, node 0 stands for 3 events, nodes 1 and 2 for one each:
    # from node 0: two co-merged events at 0, node 1 at 1, node 2 at 3, then nothing.
    g = graph_from_edges(3, [0, 1], [1, 2], [1.0, 2.0], multiplicity=[3, 1, 1])
    expected = np.array([[0, 0, 1, 3, np.inf],
                         [1, 1, 1, 2, np.inf],
                         [2, 3, 3, 3, np.inf]])
    np.testing.assert_array_equal(knn_distances(g, 5), expected)
    np.testing.assert_array_equal(knn_distances(g, 2), expected[:, :2])


@pytest.mark.parametrize("metric", ["plain", "contracted"])
def test_knn_and_maxmin_on_an_encounter_graph_match_the_event_metric(metric):
    # real merged nodes: times on a 0.5 s grid (equal times on one agent merge) and two
    # stops (contracted metric); the reference is the paper's literal event-level metric
    rng = np.random.default_rng(3)
    t = np.sort(rng.integers(0, 40, 90)) * 0.5
    a = rng.integers(0, 6, 90)
    b = (a + rng.integers(1, 6, 90)) % 6
    keep = np.unique(np.c_[t, np.minimum(a, b), np.maximum(a, b)], axis=0, return_index=True)[1]
    log = EncounterLog.from_records(t[keep], a[keep], b[keep],
                                    status=([4, 12, 6, 15], [1, 1, 4, 4], ["S", "RW", "S", "RW"]))
    graph = build_graph(log, metric)
    assert graph.components()[0] == 1 and graph.multiplicity.max() > 1
    d_events = literal_distances(log, metric)
    first_event = np.unique(graph.node_of_event, return_index=True)[1]
    for k in (1, 4, 9):
        expected = [np.sort(np.delete(d_events[e], e))[:k] for e in first_event]
        np.testing.assert_allclose(knn_distances(graph, k), expected, rtol=RTOL)
    result = maxmin(graph, 12, rng=0)
    np.testing.assert_allclose(result.distances, d_events[np.ix_(first_event[result.nodes],
                                                                 first_event[result.nodes])], rtol=RTOL)


def test_maxmin_on_a_path_hand_computed():
    # path 0-1-2-3-4, unit weights, start 2: farthest are 0 and 4 (tie -> 0), then 4,
    # then 1 (tie with 3), then 3.  Radii: 2, 2, 1, 1, 0.
    g = graph_from_edges(5, [0, 1, 2, 3], [1, 2, 3, 4], np.ones(4))
    seed = next(s for s in range(100) if np.random.default_rng(s).integers(5) == 2)
    result = maxmin(g, 5, rng=seed)
    np.testing.assert_array_equal(result.nodes, [2, 0, 4, 1, 3])
    np.testing.assert_array_equal(result.cover_radii, [2, 2, 1, 1, 0])
    np.testing.assert_array_equal(result.distances, np.abs(np.subtract.outer(result.nodes, result.nodes)))


# -- theorems ------------------------------------------------------------------------------
@pytest.mark.parametrize("method", ["maxmin", "knn", "probabilistic"])
def test_cover_radius_bounds_every_candidate(method):
    g = random_geometric_graph(300, 11)
    result = SUBSAMPLERS[method](g, 25, rng=4)
    d = dense(g)
    if method == "knn":
        candidates = literal_knn(g, 10).mean(axis=1) <= result.params["threshold"]
    else:
        candidates = np.ones(len(g.multiplicity), bool)
    to_landmarks = d[:, result.nodes].min(axis=1)
    assert np.all(np.diff(result.cover_radii) <= 0)
    assert to_landmarks[candidates].max() == pytest.approx(result.cover_radius, rel=RTOL)
    # after i + 1 picks every candidate is within cover_radii[i] of the first i + 1 landmarks
    for i in range(len(result.nodes)):
        reach = d[:, result.nodes[: i + 1]].min(axis=1)[candidates].max()
        assert reach == pytest.approx(result.cover_radii[i], rel=RTOL)


@pytest.mark.parametrize("method", ["maxmin", "knn"])
def test_maxmin_separation_property(method):
    # the j-th landmark was the farthest candidate: d(l_i, l_j) >= cover radius before it
    g = random_geometric_graph(300, 12)
    result = SUBSAMPLERS[method](g, 40, rng=1)
    dist = result.distances
    for j in range(1, len(result.nodes)):
        assert dist[j, :j].min() >= result.cover_radii[j - 1] * (1 - RTOL)
        assert dist[j, :j].min() == pytest.approx(result.cover_radii[j - 1], rel=RTOL)


def test_distances_matrix_is_a_metric_on_landmarks():
    result = maxmin(random_geometric_graph(200, 8), 20, rng=0)
    dist = result.distances
    assert dist.dtype == np.float64 and dist.shape == (20, 20)
    np.testing.assert_array_equal(dist, dist.T)
    np.testing.assert_array_equal(np.diag(dist), 0)
    assert (dist[~np.eye(20, dtype=bool)] > 0).all()


@pytest.mark.parametrize("method", ["maxmin", "knn", "probabilistic"])
def test_more_landmarks_than_points_takes_all(method):
    g = random_geometric_graph(40, 9)
    n = len(g.multiplicity)
    result = SUBSAMPLERS[method](g, n + 5, k=3, rng=0) if method != "maxmin" else maxmin(g, n + 5, rng=0)
    n_candidates = result.params.get("n_kept", n)
    assert len(result.nodes) == len(np.unique(result.nodes)) == n_candidates
    assert result.cover_radius == 0.0
    np.testing.assert_allclose(result.distances, dense(g)[np.ix_(result.nodes, result.nodes)], rtol=RTOL)


def test_probabilistic_with_omega_zero_is_maxmin():
    g = random_geometric_graph(250, 6)
    a, b = maxmin(g, 30, rng=2), probabilistic_maxmin(g, 30, omega=0.0, rng=2)
    np.testing.assert_array_equal(a.nodes, b.nodes)
    np.testing.assert_array_equal(a.cover_radii, b.cover_radii)


@pytest.mark.parametrize("method", ["maxmin", "knn", "probabilistic"])
def test_choices_are_scale_invariant(method):
    # omega is unit-free and the k-NN quantile is a rank: scaling the metric by a power
    # of two (exact in floating point) scales radii and distances and changes no choice
    g = random_geometric_graph(200, 7)
    scaled = Graph(g.adjacency * 8.0, g.multiplicity)
    a, b = SUBSAMPLERS[method](g, 25, rng=3), SUBSAMPLERS[method](scaled, 25, rng=3)
    np.testing.assert_array_equal(a.nodes, b.nodes)
    np.testing.assert_array_equal(a.cover_radii * 8.0, b.cover_radii)
    np.testing.assert_array_equal(a.distances * 8.0, b.distances)


# -- outliers ---------------------------------------------------------------------------------
def test_knn_filtering_ignores_outliers_maxmin_does_not():
    # 4 outliers in 124 points (3%): their 10-NN mean is about far + 3, the cycle points'
    # about 3, so the 0.9-quantile drops them (with the 8 sparsest cycle points).
    # maxmin's second pick is already an outlier: they are the farthest points.
    g, outliers = noisy_cycle_with_outliers()
    for seed in range(5):
        plain = maxmin(g, 12, rng=seed)
        assert np.isin(plain.nodes[1:5], outliers).sum() >= 3
        filtered = knn_maxmin(g, 12, rng=seed)
        assert not np.isin(filtered.nodes, outliers).any()
        assert filtered.params["n_kept"] >= int(0.9 * len(g.multiplicity))
        assert (knn_distances(g, 10)[outliers].mean(axis=1) > filtered.params["threshold"]).all()
        soft = probabilistic_maxmin(g, 12, omega=1.0, rng=seed)
        assert np.isin(soft.nodes, outliers).sum() < np.isin(plain.nodes, outliers).sum()


# -- determinism and errors ------------------------------------------------------------------
@pytest.mark.parametrize("method", ["maxmin", "knn", "probabilistic"])
def test_same_seed_same_bytes_and_start_rule(method):
    g = random_geometric_graph(200, 4)
    a, b = SUBSAMPLERS[method](g, 20, rng=7), SUBSAMPLERS[method](g, 20, rng=np.random.default_rng(7))
    assert a.nodes.tobytes() == b.nodes.tobytes() and a.distances.tobytes() == b.distances.tobytes()
    assert a.cover_radii.tobytes() == b.cover_radii.tobytes() and a.params == b.params
    starts = {int(SUBSAMPLERS[method](g, 2, rng=s).nodes[0]) for s in range(6)}
    assert len(starts) > 1
    if method != "knn":  # the start is a uniform draw from the candidate nodes
        assert a.nodes[0] == np.random.default_rng(7).integers(len(g.multiplicity))


@pytest.mark.parametrize("method", ["maxmin", "knn", "probabilistic"])
def test_disconnected_graph_is_a_clear_error(method):
    g = graph_from_edges(6, [0, 1, 3, 4], [1, 2, 4, 5], np.ones(4))
    with pytest.raises(SwarmtopoError, match="not connected"):
        SUBSAMPLERS[method](g, 3, k=2, rng=0) if method != "maxmin" else maxmin(g, 3, rng=0)


@pytest.mark.parametrize("call, message", [
    (lambda g: maxmin(g, 0), "n_landmarks must be a positive integer"),
    (lambda g: maxmin(g, 2.5), "n_landmarks must be a positive integer"),
    (lambda g: knn_maxmin(g, 3, k=0), "k must be a positive integer"),
    (lambda g: knn_maxmin(g, 3, q=0.0), "q must be a positive finite number"),
    (lambda g: knn_maxmin(g, 3, q=1.5), "q must be in (0, 1]"),
    (lambda g: knn_maxmin(g, 3, k=5), "k = 5 nearest neighbours need more than k events"),
    (lambda g: probabilistic_maxmin(g, 3, omega=-1.0), "omega must be a finite number >= 0"),
    (lambda g: probabilistic_maxmin(g, 3, omega=float("nan")), "omega must be a finite number >= 0"),
    (lambda g: knn_distances(g, 0), "k must be a positive integer"),
])
def test_bad_parameters_are_input_errors(call, message):
    g = graph_from_edges(5, [0, 1, 2, 3], [1, 2, 3, 4], np.ones(4))
    with pytest.raises(InputError, match=re.escape(message)):
        call(g)


def test_nonpositive_weights_are_rejected():
    adjacency = sp.csr_matrix(np.array([[0, 1, 0], [1, 0, -1], [0, -1, 0]], float))
    with pytest.raises(InputError, match="> 0"):
        maxmin(Graph(adjacency, np.ones(3, np.int64)), 2)


@pytest.mark.parametrize("method, stages", [("maxmin", ["picks", "distances", "done"]),
                                            ("knn", ["knn", "picks", "distances", "done"]),
                                            ("probabilistic", ["knn", "picks", "distances", "done"])])
def test_progress_reports_each_stage_once_in_order(method, stages):
    seen = []
    SUBSAMPLERS[method](random_geometric_graph(60, 0), 5, rng=0, progress=seen.append)
    assert seen == stages


# -- bucket-queue searches and the drawn start --------------------------------------------
def _arrays(g: Graph):
    a = g.adjacency
    return a.indptr.astype(np.int64), a.indices.astype(np.int64), a.data.astype(float)


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("hop", [0.05, 0.0])
def test_bucket_searches_give_the_heap_and_scipy_distances_bit_for_bit(seed, hop):
    """Every label-setting search ends at the same floating-point fixpoint: the bucket
    queue (with a per-hop cost, as the pipeline's weights have) and the heap agree bit
    for bit with each other and with scipy, in parallel and in one thread."""
    import numba

    from swarmtopo.metric import _kernels

    g = random_geometric_graph(300, seed)
    indptr, indices, weights = _arrays(g)
    weights = weights + hop
    layout = _kernels.bucket_layout(weights)
    assert (layout[1] > 0) == (hop > 0)  # without a floor on the weights, the heap is the better choice
    nodes = np.random.default_rng(seed).choice(len(indptr) - 1, 40, replace=False)
    scipy_rows = shortest_path(sp.csr_matrix((weights, indices, indptr)), indices=nodes)[:, nodes]
    before = numba.get_num_threads()
    try:
        for threads in (1, before):
            numba.set_num_threads(threads)
            heap = _kernels.rows_to_targets(indptr, indices, weights, nodes, nodes, buckets=False)
            buckets = _kernels.rows_to_targets(indptr, indices, weights, nodes, nodes)
            assert np.array_equal(heap, buckets) and np.array_equal(heap, scipy_rows)
    finally:
        numba.set_num_threads(before)


def test_bucket_layout_hand_computed():
    from swarmtopo.metric._kernels import BUCKET_SPREAD, bucket_layout

    # width: half the least weight; ceil(17 / 1) + 3 = 20 buckets needed, rounded up to 32
    assert bucket_layout(np.array([2.0, 3.0, 17.0])) == (1.0, 32)
    spread = np.r_[1.0, np.full(9, 2 * BUCKET_SPREAD * 10 / 9)]  # mean over 32 x the least: heap
    assert bucket_layout(spread) == (0.0, 0)
    assert bucket_layout(np.array([1e-300, 1e300])) == (0.0, 0)  # no overflow on the way to "heap"
    assert bucket_layout(np.array([1e-310, 1.0])) == (0.0, 0)


def test_buckets_never_wrap_onto_the_one_being_scanned():
    """The longest edge relaxed from just below a bucket boundary lands the farthest
    ahead: it must not land in the bucket being scanned (a path of two shortest edges
    and a tuned one to just below a boundary, then the longest edge, against a detour)."""
    from swarmtopo.metric import _kernels

    least, longest, target = 8.176950185803168, 183.98137918057125, 192.15832936637443
    tuned = target - 2 * least
    while 2 * least + tuned != target:
        tuned = np.nextafter(tuned, np.inf) if 2 * least + tuned < target else np.nextafter(tuned, 0)
    edges = [(0, 1, least), (1, 2, least), (2, 3, tuned), (3, 4, longest), (0, 5, 100.0), (5, 6, 100.0),
             (6, 4, 100.0), (4, 7, 100.0)]
    i, j, w = (np.array(column) for column in zip(*edges))
    indptr, indices, weights = _arrays(graph_from_edges(8, i, j, w))
    nodes = np.array([0, 4, 7])
    buckets = _kernels.rows_to_targets(indptr, indices, weights, nodes, nodes)
    assert buckets.tolist() == [[0.0, 300.0, 400.0], [300.0, 0.0, 100.0], [400.0, 100.0, 0.0]]


@pytest.mark.parametrize("seed", range(3))
def test_buckets_agree_with_the_heap_on_weights_on_a_grid(seed):
    """Weights that are multiples of one step (times on 0.1 s ticks) put many keys on
    bucket boundaries: buckets and heap still agree bit for bit."""
    from swarmtopo.metric import _kernels

    rng = np.random.default_rng(seed)
    for _ in range(60):
        n = int(rng.integers(50, 300))
        i = np.r_[rng.integers(0, n, 3 * n), np.arange(n - 1)]
        j = np.r_[rng.integers(0, n, 3 * n), np.arange(1, n)]
        keep = i != j
        step = rng.choice([0.1, 0.15, 1 / 3, 0.7])
        low = int(rng.integers(1, 5))
        w = rng.integers(low, low + int(rng.integers(1, 40)), keep.sum()) * step
        g = graph_from_edges(n, i[keep], j[keep], w)  # duplicate pairs add up: still positive weights
        indptr, indices, weights = _arrays(g)
        assert _kernels.bucket_layout(weights)[1] > 0
        nodes = rng.choice(n, min(40, n), replace=False)
        assert np.array_equal(_kernels.rows_to_targets(indptr, indices, weights, nodes, nodes),
                              _kernels.rows_to_targets(indptr, indices, weights, nodes, nodes, buckets=False))


@pytest.mark.parametrize("method", sorted(SUBSAMPLERS))
def test_a_given_start_rank_is_the_draw_from_the_stream(method):
    """The pipeline draws each window's start rank beforehand: rng.integers(pool size);
    the subsampler given that rank starts where it would have drawn it."""
    from swarmtopo.metric.landmarks import start_pool

    g = random_geometric_graph(200, 3)
    band = np.arange(g.adjacency.shape[0]) % 3 == 0
    extra = {"candidates": band} if method == "maxmin" else {}
    pool = start_pool(g, method, candidates=band if method == "maxmin" else None)
    drawn = SUBSAMPLERS[method](g, 20, rng=np.random.default_rng(7), **extra)
    rank = int(np.random.default_rng(7).integers(len(pool)))
    given = SUBSAMPLERS[method](g, 20, start=rank, **extra)
    assert drawn.params["start"] == given.params["start"] == pool[rank]
    assert np.array_equal(drawn.nodes, given.nodes) and np.array_equal(drawn.distances, given.distances)
    with pytest.raises(InputError, match="start must be a rank"):
        SUBSAMPLERS[method](g, 20, start=len(pool), **extra)
