"""Tests of swarmtopo.topology.persistence: hand-computed diagrams, backend agreement,
the stability theorem, conventions, validation."""

import json

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import shortest_path
from scipy.spatial.distance import cdist

from swarmtopo.errors import InputError, SwarmtopoError
from swarmtopo.topology.persistence import (
    BACKENDS,
    Diagram,
    available_backends,
    bottleneck,
    check_distance_matrix,
    rips_persistence,
)

INSTALLED = available_backends()
SQRT2 = np.sqrt(2.0)
# 4 points on a unit square, in cyclic order: sides 1, diagonals sqrt 2.
SQUARE = np.array(
    [[0, 1, SQRT2, 1], [1, 0, 1, SQRT2], [SQRT2, 1, 0, 1], [1, SQRT2, 1, 0]], dtype=float
)


def noisy_circle(n, noise, rng):
    rng = np.random.default_rng(rng)
    angle = rng.uniform(0, 2 * np.pi, n)
    points = np.c_[np.cos(angle), np.sin(angle)] + rng.normal(0, noise, (n, 2))
    return points, angle


def graph_metric(n, rng, *, integer_weights):
    """Shortest paths on a ring plus random chords (a circle-like graph metric).

    Integer weights make many distances tie, which exercises tie handling."""
    rng = np.random.default_rng(rng)
    rows = np.r_[np.arange(n), rng.integers(0, n, n // 3)]
    cols = np.r_[(np.arange(n) + 1) % n, rng.integers(0, n, n // 3)]
    keep = rows != cols
    rows, cols = rows[keep], cols[keep]
    if integer_weights:
        weights = rng.integers(1, 4, len(rows)).astype(float)
    else:
        weights = rng.uniform(0.5, 2, len(rows))
    graph = coo_matrix((weights, (rows, cols)), shape=(n, n)).tocsr()
    return shortest_path(graph, directed=False)


# -- hand-computed diagrams ---------------------------------------------------------------
@pytest.mark.parametrize("backend", INSTALLED)
def test_square_has_one_hole_from_side_to_diagonal(backend):
    # Edges (sides) enter at 1: three merge the four points, the fourth closes a
    # 4-cycle.  The diagonals enter at sqrt 2 and fill it with triangles.
    dgm = rips_persistence(SQUARE, maxdim=2, backend=backend).diagram
    np.testing.assert_array_equal(dgm[0], [[0, np.inf], [0, 1], [0, 1], [0, 1]])
    np.testing.assert_array_equal(dgm[1], [[1, SQRT2]])
    assert dgm[2].shape == (0, 2)
    assert dgm.backend == backend


@pytest.mark.parametrize("backend", INSTALLED)
def test_two_far_clusters_merge_at_their_gap(backend):
    # Points on a line: cluster {0, 0.1, 0.25}, cluster {10, 10.2}; gap 10 - 0.25.
    x = np.array([0.0, 0.1, 0.25, 10.0, 10.2])
    dgm = rips_persistence(np.abs(x[:, None] - x[None, :]), maxdim=1, backend=backend).diagram
    np.testing.assert_array_equal(
        dgm[0], [[0, np.inf], [0, 9.75], [0, x[4] - x[3]], [0, 0.15], [0, 0.1]]
    )
    assert len(dgm[1]) == 0


@pytest.mark.parametrize("backend", INSTALLED)
def test_single_point_is_one_infinite_component(backend):
    dgm = rips_persistence(np.zeros((1, 1)), maxdim=2, backend=backend).diagram
    np.testing.assert_array_equal(dgm[0], [[0, np.inf]])
    assert dgm[1].shape == dgm[2].shape == (0, 2)


@pytest.mark.parametrize("backend", INSTALLED)
def test_threshold_keeps_edges_up_to_it_and_leaves_survivors_infinite(backend):
    dgm = rips_persistence(SQUARE, backend=backend, threshold=1.0).diagram
    np.testing.assert_array_equal(dgm[0], [[0, np.inf], [0, 1], [0, 1], [0, 1]])
    np.testing.assert_array_equal(dgm[1], [[1, np.inf]])
    dgm = rips_persistence(SQUARE, backend=backend, threshold=0.5).diagram
    np.testing.assert_array_equal(dgm[0], [[0, np.inf]] * 4)


@pytest.mark.parametrize("backend", INSTALLED)
def test_duplicate_points_give_no_zero_length_bars(backend):
    points = np.random.default_rng(3).random((20, 2))
    points[7] = points[3]
    points[12] = points[3]
    dgm = rips_persistence(cdist(points, points), backend=backend).diagram
    # 20 points, 18 distinct: 17 finite merges of distinct points + 1 infinite bar.
    assert len(dgm[0]) == 18
    assert np.isinf(dgm[0][:, 1]).sum() == 1
    for dim in (0, 1):
        assert (dgm.lengths(dim) > 0).all()


# -- backends agree ----------------------------------------------------------------------
def _agreement_cases():
    rng = np.random.default_rng(20240611)
    cases = []
    for n, d in [(80, 2), (60, 3)]:
        points = rng.random((n, d))
        cases.append((f"euclid{d}d-{n}", cdist(points, points), 1))
    circle, _ = noisy_circle(70, 0.1, rng)
    cases.append(("noisy-circle", cdist(circle, circle), 1))
    cases.append(("graph-real", graph_metric(70, rng, integer_weights=False), 1))
    cases.append(("graph-integer-ties", graph_metric(70, rng, integer_weights=True), 1))
    sphere = rng.normal(size=(30, 3))
    sphere /= np.linalg.norm(sphere, axis=1, keepdims=True)
    cases.append(("sphere-dim2", cdist(sphere, sphere), 2))
    cases.append(("graph-dim2", graph_metric(24, rng, integer_weights=True), 2))
    return [pytest.param(*case, id=case[0]) for case in cases]


@pytest.mark.skipif(len(INSTALLED) < 2, reason="needs two backends to compare")
@pytest.mark.parametrize("name,matrix,maxdim", _agreement_cases())
def test_installed_backends_return_identical_diagrams(name, matrix, maxdim):
    results = [rips_persistence(matrix, maxdim, backend=b).diagram for b in INSTALLED]
    reference = results[0]
    assert np.isinf(reference[0][:, 1]).sum() == 1  # connected input: one infinite H0 bar
    if name == "sphere-dim2":
        assert len(reference[1]) + len(reference[2]) > 0  # the comparison is not vacuous
    for other in results[1:]:
        for dim in range(maxdim + 1):
            assert other[dim].shape == reference[dim].shape, (other.backend, dim)
            np.testing.assert_allclose(other[dim], reference[dim], rtol=0, atol=1e-9)
            assert bottleneck(reference, other, dim) <= 1e-9


# -- theorems and statistics ---------------------------------------------------------------
@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("eps", [1e-3, 0.02, 0.1])
def test_stability_bottleneck_at_most_sup_norm_perturbation(seed, eps):
    # Rips filtrations of two dissimilarities within eps in sup norm are eps-interleaved,
    # so their diagrams are within bottleneck eps (Chazal, de Silva, Oudot 2014).
    rng = np.random.default_rng(seed)
    points = rng.random((50, 2))
    matrix = cdist(points, points)
    noise = np.triu(rng.uniform(-eps, eps, matrix.shape), k=1)
    perturbed = np.maximum(matrix + noise + noise.T, 0.0)  # clipping at 0 only shrinks the change
    assert np.abs(perturbed - matrix).max() <= eps
    before = rips_persistence(matrix).diagram
    after = rips_persistence(perturbed).diagram
    moved = [bottleneck(before, after, dim) for dim in (0, 1)]
    assert max(moved) <= eps * (1 + 1e-12)
    assert max(moved) > 0  # the perturbation did move the diagram: the bound is tested


@pytest.mark.parametrize("seed", range(5))
def test_noisy_circle_has_one_dominant_hole(seed):
    # Unit circle, 100 points, noise sd 0.05: the hole is born below the largest gap
    # between neighbours (~0.2) and dies near sqrt 3 (inscribed triangle), length ~1.5;
    # noise cycles live on the scale of the noise and the spacing (~0.1).  A ratio of 5
    # leaves a wide margin on both sides.
    points, _ = noisy_circle(100, 0.05, seed)
    lengths = rips_persistence(cdist(points, points)).diagram.lengths(1)
    assert lengths[0] > 1.0
    assert lengths[0] > 5 * lengths[1]


# -- cocycles --------------------------------------------------------------------------------
@pytest.mark.skipif("ripser" not in INSTALLED, reason="cocycles need ripser.py")
def test_cocycles_lie_within_their_bar_and_detect_the_hole():
    points, angle = noisy_circle(80, 0.05, 11)
    matrix = cdist(points, points)
    result = rips_persistence(matrix, cocycles=True)
    assert result.backend == "ripser"
    dgm1, cocycles1 = result.diagram[1], result.cocycles[1]
    assert len(cocycles1) == len(dgm1) > 1
    assert result.cocycles[0] == []
    for (birth, death), cocycle in zip(dgm1, cocycles1):
        edge_values = matrix[cocycle[:, 0], cocycle[:, 1]]
        assert edge_values.max() <= death
        assert edge_values.min() == birth  # contains the edge whose entry created the class
    # Evaluate the dominant class on the loop through the points in angular order:
    # that loop goes once around the hole, so the Z/2 pairing is 1.
    order = np.argsort(angle)
    loop = {frozenset(edge) for edge in zip(order, np.roll(order, -1))}
    assert max(matrix[a, b] for a, b in map(tuple, loop)) < dgm1[0, 1]  # loop exists before death
    pairing = sum(int(c) for i, j, c in cocycles1[0] if frozenset((i, j)) in loop)
    assert pairing % 2 == 1


@pytest.mark.skipif("ripser" not in INSTALLED, reason="cocycles need ripser.py")
def test_cocycles_follow_the_diagram_order_and_threshold():
    points, _ = noisy_circle(60, 0.05, 5)
    matrix = cdist(points, points)
    threshold = 0.8  # below the hole's death: its bar becomes infinite
    result = rips_persistence(matrix, cocycles=True, threshold=threshold)
    dgm1 = result.diagram[1]
    assert np.isinf(dgm1[0, 1])
    for (birth, _), cocycle in zip(dgm1, result.cocycles[1]):
        edge_values = matrix[cocycle[:, 0], cocycle[:, 1]]
        assert edge_values.min() == birth and edge_values.max() <= threshold


# -- Diagram ---------------------------------------------------------------------------------
def test_diagram_sorts_drops_zero_length_and_is_read_only():
    dgm = Diagram(([[0, 1], [0, np.inf], [0, 0], [0, 3]], [[2, 3], [1, 2], [0.5, 2.5]]), "test")
    np.testing.assert_array_equal(dgm[0], [[0, np.inf], [0, 3], [0, 1]])
    np.testing.assert_array_equal(dgm[1], [[0.5, 2.5], [1, 2], [2, 3]])  # equal lengths: by birth
    np.testing.assert_array_equal(dgm.lengths(0), [np.inf, 3, 1])
    np.testing.assert_array_equal(dgm.finite(0), [[0, 3], [0, 1]])
    assert dgm.maxdim == 1
    with pytest.raises(ValueError):
        dgm[0][0, 0] = 5
    with pytest.raises(IndexError):
        dgm[2]


def test_json_round_trip_maps_inf_to_none():
    points, _ = noisy_circle(40, 0.1, 2)
    dgm = rips_persistence(cdist(points, points), maxdim=1, threshold=0.9).diagram
    obj = dgm.to_json()
    assert obj["0"][0][1] is None
    text = json.dumps(obj, allow_nan=False)  # strict JSON: no Infinity literal
    back = Diagram.from_json(json.loads(text))
    assert back.backend == "json"
    for dim in (0, 1):
        np.testing.assert_array_equal(back[dim], dgm[dim])


@pytest.mark.parametrize(
    "obj",
    [{"1": []}, {"0": [[1, 0]]}, {"0": [[None, 1]]}, {"0": "x"}, [[0, 1]], {"0": [[0, 1, 2]]}],
)
def test_from_json_rejects_malformed(obj):
    with pytest.raises(InputError):
        Diagram.from_json(obj)


# -- validation ------------------------------------------------------------------------------
def test_infinite_distance_is_refused_with_advice():
    matrix = SQUARE.copy()
    matrix[0, 2] = matrix[2, 0] = np.inf
    with pytest.raises(SwarmtopoError, match=r"\[0, 2\] is infinite.*connected components"):
        rips_persistence(matrix)


@pytest.mark.parametrize(
    "edit,message",
    [
        (lambda m: m.__setitem__((1, 3), np.nan), "NaN"),
        (lambda m: m.__setitem__((1, 3), 3.0), "not symmetric"),
        (lambda m: (m.__setitem__((1, 3), -1.0), m.__setitem__((3, 1), -1.0)), "negative"),
        (lambda m: m.__setitem__((1, 3), -np.inf), "negative"),
        (lambda m: m.__setitem__((2, 2), 0.5), "diagonal"),
    ],
)
def test_bad_matrices_are_refused(edit, message):
    matrix = SQUARE.copy()
    edit(matrix)
    with pytest.raises(InputError, match=message):
        rips_persistence(matrix)


def test_shape_and_argument_checks():
    with pytest.raises(InputError, match="square"):
        rips_persistence(np.zeros((3, 4)))
    with pytest.raises(InputError, match="square"):
        rips_persistence(np.zeros((0, 0)))
    with pytest.raises(InputError, match="maxdim"):
        rips_persistence(SQUARE, maxdim=3)
    with pytest.raises(InputError, match="threshold"):
        rips_persistence(SQUARE, threshold=-1.0)
    with pytest.raises(InputError, match="unknown persistence backend"):
        rips_persistence(SQUARE, backend="dionysus")
    with pytest.raises(InputError, match="cocycles"):
        rips_persistence(SQUARE, backend="gudhi", cocycles=True)


def test_tiny_asymmetry_is_tolerated_and_removed():
    matrix = SQUARE.copy()
    matrix[0, 1] *= 1 + 1e-12  # e.g. Dijkstra summing one path in two orders
    cleaned = check_distance_matrix(matrix)
    np.testing.assert_array_equal(cleaned, cleaned.T)
    np.testing.assert_array_equal(check_distance_matrix(SQUARE), SQUARE)  # exact input untouched


def test_backend_choice():
    assert INSTALLED == [b for b in BACKENDS if b in INSTALLED]
    assert "gudhi" in INSTALLED  # a hard dependency
    assert rips_persistence(SQUARE).backend == INSTALLED[0]
    for name in set(BACKENDS) - set(INSTALLED):
        with pytest.raises(SwarmtopoError, match="not installed"):
            rips_persistence(SQUARE, backend=name)


def test_rounding_noise_bars_are_dropped_relative_to_the_diagram_scale():
    # a 1e-15 s bar among bars of seconds is two orders of summing one path: dropped
    dgm = Diagram(pairs=(np.array([[0.0, np.inf]]), np.array([[4.0, 4.0 + 8.9e-16], [3.0, 9.0]])), backend="t")
    assert dgm.lengths(1).tolist() == [6.0]
    # the same shapes at a tiny scale are real bars: the floor is relative
    tiny = Diagram(pairs=(np.array([[0.0, np.inf]]), np.array([[4e-12, 5e-12], [3e-12, 9e-12]])), backend="t")
    assert len(tiny.lengths(1)) == 2


def test_simulated_maps_have_no_rounding_noise_bars():
    from swarmtopo.arena import random_arena
    from swarmtopo.pipeline import MapConfig, map_encounters
    from swarmtopo.sim import simulate

    sim = simulate(random_arena(2, rng=0), 200, 30.0, rng=0)
    tmap = map_encounters(sim.log, MapConfig(metric="contracted", landmarks=300, embed_dim=0,
                                             diffusion_time=float("inf")))
    # every bar is at least one time step (0.1 s) long: distances are sums of time gaps
    # and of h = 2 s (diffusive weights, off here, leave that 0.1 s lattice)
    assert tmap.diagram.lengths(1).min() >= 0.1 - 1e-9


# -- SNR (paper, "Probabilistic maxmin") ----------------------------------------------
def snr_diagram():
    # H0: one infinite bar and [0, 2]; H1 lengths 4, 1, 0.5
    return Diagram(pairs=(np.array([[0.0, np.inf], [0.0, 2.0]]),
                          np.array([[1.0, 5.0], [1.0, 2.0], [1.0, 1.5]])), backend="t")


def test_snr_hand_computed():
    from swarmtopo.topology.persistence import snr

    s = snr(snr_diagram(), 1, 1)
    # signal: the longest bar (4) -> P_S = 16; noise: 1 and 0.5 -> P_N = (1 + 0.25) / 2
    assert (s.signal_power, s.noise_power, s.ratio) == pytest.approx((16.0, 0.625, 25.6))
    # beta = 2: P_S = (16 + 1) / 2, P_N = 0.25
    assert snr(snr_diagram(), 1, 2).ratio == pytest.approx(8.5 / 0.25)


def test_snr_without_signal_is_the_noise_power_alone():
    from swarmtopo.topology.persistence import snr

    s = snr(snr_diagram(), 1, 0)
    assert s.signal_power == 0 and s.ratio == 0
    assert s.noise_power == pytest.approx((16 + 1 + 0.25) / 3)


def test_snr_caps_infinite_bars_and_handles_missing_noise():
    from swarmtopo.topology.persistence import snr

    # the infinite H0 bar counts as long as the largest finite death (5) minus its birth
    s = snr(snr_diagram(), 0, 1)
    assert (s.signal_power, s.noise_power) == pytest.approx((25.0, 4.0))
    assert snr(snr_diagram(), 0, 1, infinite_length=10.0).signal_power == pytest.approx(100.0)
    # every bar is signal: no noise, infinite ratio; more signal asked than bars: zeros
    assert snr(snr_diagram(), 1, 3).ratio == np.inf
    assert snr(snr_diagram(), 1, 4).signal_power == pytest.approx((16 + 1 + 0.25) / 4)


def test_mean_snr_averages_the_ratios_of_independent_runs():
    from swarmtopo.topology.persistence import mean_snr, snr

    other = Diagram(pairs=(np.array([[0.0, np.inf]]), np.array([[0.0, 2.0], [0.0, 1.0]])), backend="t")
    assert mean_snr([snr_diagram(), other], 1, 1) == pytest.approx((25.6 + 4.0) / 2)
    with pytest.raises(InputError):
        mean_snr([], 1, 1)
    with pytest.raises(InputError):
        snr(other, 1, -1)
