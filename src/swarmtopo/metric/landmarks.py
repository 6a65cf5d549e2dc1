r"""Landmark subsampling of the encounter metric (paper, "Subsampling").

The point cloud X is the set of events under the encounter metric d.  Here a point
is a *node* of an :class:`~swarmtopo.metric.graph.EncounterGraph`: a node of multiplicity m
stands for m events at distance 0 from each other, and d is the shortest-path
distance of the graph.  Three subsamplers choose landmarks L in X:

``maxmin``
    Farthest-point sampling (de Silva & Carlsson): l_1 at random, then
    l_k = argmax_x d(x, L).  Sensitive to outliers: they are far from everything.
``knn``
    KNN filtering then maxmin.  d̄_k(x) is the mean distance from x to its k nearest
    other points (inversely related to the local density); the points with
    d̄_k(x) <= tau_{q,k}, the q-quantile of d̄_k over X, are kept (V) and maxmin runs
    on V, with distances still measured in the whole graph.
``probabilistic``
    Probabilistic maxmin: l_k = argmax_x alpha(d(x, L), v(x)), alpha(u, v) = u + omega v,
    with v a local density (see :func:`probabilistic_maxmin` for the unit-free v).

Never N x N
-----------
Every method keeps u(x) = d(x, L) for all nodes and updates it with one search per
new landmark.  A new landmark l can lower u(x) only where d(x, l) < u(x), and a search
that stops at every node it does not improve is still exact (triangle inequality), so
each search covers only l's Voronoi cell: at 10^6 nodes the 500 picks cost about a
second instead of minutes (an unbounded search each), also on hub-heavy graphs where a
covering-radius bound prunes little.  The k-NN search of every node stops after k points (counting
multiplicity); the landmark-to-landmark matrix comes from one search per landmark
that stops at the last landmark it reaches.  Memory is O(n + nnz + L^2).

Ties in an argmax go to the smallest node index.  The graph must be connected (the
pipeline splits components first).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from . import _kernels
from .._validate import non_negative, positive, positive_int
from ..errors import InputError, SwarmtopoError

MIN_LANDMARKS = 3
"""The fewest landmarks a run stopped by its ``cover`` radius keeps (a triangle: the least that can hold a loop)."""

Progress = Callable[[str], None]
"""Progress callback: receives the name of the stage that starts."""


@dataclass(frozen=True, eq=False)
class Landmarks:
    """Landmarks chosen from the nodes of an encounter graph.

    Attributes
    ----------
    nodes
        ``(L,)`` int64 graph node indices, in selection order (l_1, l_2, ...).
    distances
        ``(L, L)`` float64 exact graph distances d(l_i, l_j): symmetric, zero diagonal.
    cover_radius
        max over the candidate set (all nodes, or the KNN-kept set V) of the distance
        to the nearest landmark, after all L picks.
    cover_radii
        ``(L,)`` covering radius after each pick, non-increasing;
        ``cover_radii[-1] == cover_radius``.
    method
        ``"maxmin"``, ``"knn"`` or ``"probabilistic"``.
    params
        The parameters used (``k``, ``q``, ``omega``, ``start`` node, ...).
    """

    nodes: np.ndarray
    distances: np.ndarray
    cover_radius: float
    cover_radii: np.ndarray
    method: str
    params: dict[str, Any] = field(default_factory=dict)


def maxmin(graph, n_landmarks: int, *, rng=None, progress: Progress | None = None,
           candidates: np.ndarray | None = None, cover: float | None = None, start: int | None = None) -> Landmarks:
    """Maxmin (farthest-point) landmarks: l_k = argmax_x d(x, L).

    Parameters
    ----------
    graph
        An :class:`~swarmtopo.metric.graph.EncounterGraph` (uses ``adjacency`` and
        ``multiplicity``); must be connected.
    n_landmarks
        L; if it is at least the number of nodes, every node becomes a landmark.
    rng
        Seed or Generator; l_1 is a node drawn uniformly at random.
    progress
        Called with the name of each stage as it starts (``"picks"``,
        ``"distances"``) and with ``"done"`` at the end.
    candidates
        Optional (n_nodes,) bool mask: landmarks are drawn among these nodes only,
        and the covering radius is over them (distances still through every node).
    cover
        Optional radius: stop at the first pick that brings the covering radius to at
        most ``cover`` (at least ``MIN_LANDMARKS`` picks), so L is then how many the
        greedy run needs to cover within ``cover``, at most ``n_landmarks``.
    start
        Optional rank of l_1 among the start pool (:func:`start_pool`), instead of a
        draw from ``rng``: the draw is ``rng.integers(pool size)``, so a caller that
        draws it elsewhere (the pipeline, before its window tasks run) gets the same l_1.

    Returns
    -------
    Landmarks
        ``params``: ``start`` (l_1).  Maxmin property: d(l_i, l_j) >= cover_radii[j-1]
        for i < j (0-based), and every candidate is within ``cover_radius`` of L.
    """
    arrays = _GraphArrays.of(graph)
    n_landmarks = positive_int("n_landmarks", n_landmarks)
    _check_connected(arrays)
    rng = np.random.default_rng(rng)
    notify = progress or _quiet
    if candidates is None:
        candidates = np.ones(arrays.n, bool)
    else:
        candidates = np.asarray(candidates, bool)
        if candidates.shape != (arrays.n,) or not candidates.any():
            raise InputError(f"candidates must be a bool mask of shape ({arrays.n},) with at least one node set, "
                             f"got shape {candidates.shape} with {int(candidates.sum())} set")
    start = _start_node(candidates, rng, start)
    notify("picks")
    nodes, radii = _pick(arrays, candidates, n_landmarks, start, cover=cover)
    return _result(arrays, nodes, radii, "maxmin", {"start": start}, notify)


def knn_maxmin(graph, n_landmarks: int, *, k: int = 10, q: float = 0.9, rng=None,
               progress: Progress | None = None, cover: float | None = None, start: int | None = None) -> Landmarks:
    """KNN-filtered maxmin: maxmin on the points with d̄_k(x) <= tau_{q,k}.

    d̄_k(x) is the mean distance to the k nearest other points (events, so a node of
    multiplicity m has m - 1 neighbours at distance 0) and tau_{q,k} its q-quantile
    over all events (``numpy.quantile``, linear interpolation).  The paper keeps
    d̄_k < tau; we keep <=, so that a cloud of equal densities (a uniform cycle) keeps
    every point instead of none.  Distances stay those of the whole graph.

    Parameters
    ----------
    graph
        Connected encounter graph.
    n_landmarks
        L; if it is at least the number of kept nodes, every kept node is a landmark.
    k, q
        Neighbours and quantile (paper: k = 10, q = 0.9); 1 <= k < number of events,
        0 < q <= 1.
    rng
        Seed or Generator; l_1 is drawn uniformly from the kept nodes.
    progress
        Called with each stage's name as it starts (``"knn"``, ``"picks"``,
        ``"distances"``) and with ``"done"`` at the end.
    cover
        As for :func:`maxmin` (the covering radius over the kept set V).
    start
        As for :func:`maxmin` (a rank among the kept nodes).

    Returns
    -------
    Landmarks
        ``cover_radius`` is over the kept set V.  ``params``: ``k``, ``q``,
        ``threshold`` (tau_{q,k}), ``n_kept`` (nodes in V), ``start``.
    """
    arrays = _GraphArrays.of(graph)
    n_landmarks = positive_int("n_landmarks", n_landmarks)
    k = positive_int("k", k)
    q = positive("q", q)
    if q > 1.0:
        raise InputError("q must be in (0, 1]", value=q)
    _check_connected(arrays)
    rng = np.random.default_rng(rng)
    notify = progress or _quiet
    notify("knn")
    candidates, threshold = _knn_kept(arrays, k, q)
    start = _start_node(candidates, rng, start)
    notify("picks")
    nodes, radii = _pick(arrays, candidates, n_landmarks, start, cover=cover)
    params = {"k": k, "q": q, "threshold": threshold, "n_kept": int(candidates.sum()), "start": start}
    return _result(arrays, nodes, radii, "knn", params, notify)


def probabilistic_maxmin(graph, n_landmarks: int, *, k: int = 10, omega: float = 1.0, rng=None,
                         progress: Progress | None = None, cover: float | None = None,
                         start: int | None = None) -> Landmarks:
    r"""Probabilistic maxmin: l_k = argmax_x alpha(d(x, L), v(x)), alpha(u, v) = u + omega v.

    The paper's v is a local density and omega a constant, which makes omega carry
    the units of distance (and depend on the density scale).  We make it unit-free:

        v(x) = r * rho(x),   rho(x) = fraction of events with d̄_k > d̄_k(x),

    where r is the current covering radius (max_x d(x, L)) and d̄_k the mean k-NN
    distance.  rho in [0, 1) is the density rank: near 1 in the densest part of the
    cloud, 0 at the sparsest point (an outlier).  So alpha / r = u / r + omega rho:
    a point of density rank rho beats a point of rank 0 that is up to omega rho
    covering radii farther from L.  Multiplying the metric by c > 0 multiplies u, r
    and alpha by c and changes no choice; any monotone change of the density
    estimate changes nothing either.  alpha(0, 0) = 0, alpha is increasing in u and,
    for omega > 0, in v, as the paper requires; omega = 0 is plain maxmin.
    Landmarks already chosen are excluded from the argmax (alpha(0, v) > 0 for them).

    Parameters
    ----------
    graph
        Connected encounter graph.
    n_landmarks
        L; if it is at least the number of nodes, every node becomes a landmark.
    k
        Neighbours of the density estimate, 1 <= k < number of events.
    omega
        Weight of density against distance, >= 0 (in covering radii).
    rng
        Seed or Generator; l_1 is a node drawn uniformly at random.
    progress
        As for :func:`knn_maxmin`.
    cover, start
        As for :func:`maxmin`.

    Returns
    -------
    Landmarks
        ``params``: ``k``, ``omega``, ``start``.
    """
    arrays = _GraphArrays.of(graph)
    n_landmarks = positive_int("n_landmarks", n_landmarks)
    k = positive_int("k", k)
    omega = non_negative("omega", omega)
    _check_connected(arrays)
    rng = np.random.default_rng(rng)
    notify = progress or _quiet
    notify("knn")
    density_rank = _density_rank(_mean_knn_distance(arrays, k), arrays.multiplicity)
    candidates = np.ones(arrays.n, bool)
    start = _start_node(candidates, rng, start)
    notify("picks")
    nodes, radii = _pick(arrays, candidates, n_landmarks, start,
                         bonus=lambda radius: (omega * radius) * density_rank, cover=cover)
    params = {"k": k, "omega": omega, "start": start}
    return _result(arrays, nodes, radii, "probabilistic", params, notify)


def knn_distances(graph, k: int) -> np.ndarray:
    """Distances from every node to its k nearest other points, ascending.

    A node of multiplicity m counts m points: m - 1 neighbours at distance 0 for each
    of its events, and m copies at d(x, y) for every other node y.

    Parameters
    ----------
    graph
        Encounter graph (need not be connected).
    k
        Number of neighbours, >= 1.

    Returns
    -------
    ndarray, shape ``(n_nodes, k)``
        +inf where the component holds fewer than k other points.
    """
    arrays = _GraphArrays.of(graph)
    k = positive_int("k", k)
    return _kernels.knn_rows(arrays.indptr, arrays.indices, arrays.weights, arrays.multiplicity, k)


SUBSAMPLERS: dict[str, Callable[..., Landmarks]] = {
    "maxmin": maxmin, "knn": knn_maxmin, "probabilistic": probabilistic_maxmin,
}
"""Subsampler by name, as in the paper's "Subsampling" section."""


# -- internals -------------------------------------------------------------------------
@dataclass(frozen=True)
class _GraphArrays:
    """CSR arrays in the dtypes the kernels are compiled for."""

    indptr: np.ndarray
    indices: np.ndarray
    weights: np.ndarray
    multiplicity: np.ndarray

    @property
    def n(self) -> int:
        return len(self.indptr) - 1

    @classmethod
    def of(cls, graph) -> "_GraphArrays":
        adjacency = sp.csr_matrix(graph.adjacency)
        n = adjacency.shape[0]
        if adjacency.shape != (n, n) or n == 0:
            raise InputError("the graph adjacency must be a non-empty square matrix, "
                             f"got shape {adjacency.shape}")
        weights = adjacency.data.astype(np.float64)
        bad = ~(np.isfinite(weights) & (weights > 0))
        if bad.any():
            raise InputError("graph edge weights must be finite and > 0 (merge zero-weight joins first), "
                             f"got {weights[np.argmax(bad)]!r}")
        multiplicity = np.asarray(graph.multiplicity).astype(np.int64)
        if multiplicity.shape != (n,) or (multiplicity < 1).any():
            raise InputError(f"multiplicity must have shape ({n},) and entries >= 1")
        return cls(adjacency.indptr.astype(np.int64), adjacency.indices.astype(np.int64),
                   weights, multiplicity)


def _check_connected(arrays: _GraphArrays) -> None:
    adjacency = sp.csr_matrix((arrays.weights, arrays.indices, arrays.indptr), shape=(arrays.n, arrays.n))
    count, labels = connected_components(adjacency, directed=False)
    if count > 1:
        sizes = np.bincount(labels)
        raise SwarmtopoError(
            f"the encounter graph is not connected ({count} components, sizes up to {sizes.max()} of "
            f"{arrays.n} nodes): landmarks need one component; split the graph into components first")


def start_pool(graph, method: str, *, k: int = 10, q: float = 0.9,
               candidates: np.ndarray | None = None) -> np.ndarray:
    """The nodes l_1 is drawn from, in index order: ``candidates`` (maxmin; None: every
    node), the kept set V (knn) or every node (probabilistic).  A subsampler called with
    ``start=i`` starts at the pool's i-th node, as with a drawn ``rng.integers(len(pool))``."""
    if method == "knn":
        return np.flatnonzero(_knn_kept(_GraphArrays.of(graph), positive_int("k", k), q)[0])
    if method == "maxmin" and candidates is not None:
        return np.flatnonzero(candidates)
    return np.arange(graph.adjacency.shape[0])


def _start_node(candidates: np.ndarray, rng: np.random.Generator, rank: int | None) -> int:
    """l_1: the pool's node at ``rank``, else at a rank drawn from ``rng``."""
    pool = np.flatnonzero(candidates)
    if rank is None:
        rank = rng.integers(len(pool))
    elif not 0 <= rank < len(pool):
        raise InputError(f"start must be a rank in the start pool of {len(pool)} nodes", value=rank)
    return int(pool[rank])


def _knn_kept(arrays: _GraphArrays, k: int, q: float) -> tuple[np.ndarray, float]:
    """(V as a node mask, tau_{q,k}): the nodes whose mean k-NN distance is at most its q-quantile."""
    mean_knn = _mean_knn_distance(arrays, k)
    threshold = float(np.quantile(np.repeat(mean_knn, arrays.multiplicity), q))
    return mean_knn <= threshold, threshold


def _mean_knn_distance(arrays: _GraphArrays, k: int) -> np.ndarray:
    """d̄_k(x) for every node (the graph must hold more than k events)."""
    n_events = int(arrays.multiplicity.sum())
    if k >= n_events:
        raise InputError(f"k = {k} nearest neighbours need more than k events; the graph has {n_events}")
    rows = _kernels.knn_rows(arrays.indptr, arrays.indices, arrays.weights, arrays.multiplicity, k)
    return rows.mean(axis=1)


def _density_rank(mean_knn: np.ndarray, multiplicity: np.ndarray) -> np.ndarray:
    """rho(x): fraction of events whose d̄_k is larger than d̄_k(x), in [0, 1)."""
    event_values = np.sort(np.repeat(mean_knn, multiplicity))
    at_most = np.searchsorted(event_values, mean_knn, side="right")
    return (len(event_values) - at_most) / len(event_values)


def _pick(arrays: _GraphArrays, candidates: np.ndarray, n_landmarks: int, start: int,
          bonus: Callable[[float], np.ndarray] | None = None,
          cover: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Sequential landmark picks.

    ``to_set`` holds d(x, L); each new landmark lowers it with a search that stops
    where it cannot improve and beyond the covering radius r before the pick (exact
    wherever d(x, L) <= r, so on every candidate; see :func:`_kernels.lower_distances`:
    with candidates in a band of a window the searches stay out of the rest of it).
    ``u`` is d(x, L) on the candidates and -inf elsewhere, so non-candidates never win
    an argmax nor count in the covering radius r = max u.  The next landmark is argmax
    u (maxmin) or argmax u + bonus(r) over non-landmarks.  Picks stop at ``n_landmarks``
    or, with ``cover``, once r <= ``cover`` has been reached and there are at least
    ``MIN_LANDMARKS``.  Returns the landmark nodes and the covering radius after each
    pick.  The graph must be connected.
    """
    n_landmarks = min(n_landmarks, int(candidates.sum()))
    search = _kernels.Searcher(arrays.indptr, arrays.indices, arrays.weights)
    to_set = np.full(arrays.n, np.inf)
    is_landmark = np.zeros(arrays.n, bool)
    nodes = np.empty(n_landmarks, np.int64)
    radii = np.empty(n_landmarks)
    landmark = start
    radius = np.inf  # before the first pick nothing is covered
    covered = False
    for i in range(n_landmarks):
        nodes[i] = landmark
        is_landmark[landmark] = True
        search.add_landmark(landmark, to_set, radius)
        u = np.where(candidates, to_set, -np.inf)
        radius = radii[i] = u.max()
        covered = covered or (cover is not None and radius <= cover)
        if i + 1 == n_landmarks or (covered and i + 1 >= MIN_LANDMARKS):
            break
        if bonus is None:
            # weights > 0, so every candidate that is not a landmark has u > 0 = u(landmark)
            landmark = int(np.argmax(u))
        else:
            score = u + bonus(radius)
            score[is_landmark] = -np.inf
            landmark = int(np.argmax(score))
    return nodes[:i + 1], radii[:i + 1]


def covering_prefix(land: Landmarks, cover: float) -> Landmarks:
    """The first landmarks of a whole greedy run that a run with ``cover`` keeps (the first
    pick whose covering radius is <= ``cover``, at least ``MIN_LANDMARKS``; all of them if
    none is): what ``cover`` stops at, read off a run that did not stop."""
    within = np.flatnonzero(land.cover_radii <= cover)
    n = min(max(int(within[0]) + 1, MIN_LANDMARKS) if len(within) else len(land.nodes), len(land.nodes))
    return Landmarks(nodes=land.nodes[:n], distances=land.distances[:n, :n], cover_radius=float(land.cover_radii[n - 1]),
                     cover_radii=land.cover_radii[:n], method=land.method, params=land.params)


def _landmark_distances(arrays: _GraphArrays, nodes: np.ndarray) -> np.ndarray:
    """Exact (L, L) distances: one search per landmark, stopped at the last landmark."""
    rows = _kernels.rows_to_targets(arrays.indptr, arrays.indices, arrays.weights, nodes, nodes)
    # d(a, b) and d(b, a) are sums of the same path in two orders: equal up to rounding
    return _kernels.symmetrize_min(rows)


def _result(arrays, nodes, radii, method, params, notify) -> Landmarks:
    notify("distances")
    distances = _landmark_distances(arrays, nodes)
    notify("done")
    return Landmarks(nodes=nodes, distances=distances, cover_radius=float(radii[-1]),
                     cover_radii=radii, method=method, params=params)


def _quiet(stage: str) -> None:
    """Default progress callback: report nothing."""
