"""Levers the accuracy issue names, measured on the benchmark's tuning cases.

Each variant maps the tuning cases of ``swarmtopo-accuracy/1`` (inside
``tuning_session``: reporting cases are closed; no L-shaped holes) from logs stripped of
ground truth, and the ratio classifier (q_1, tau_1) is fitted for each variant on its
own maps (``experiments.tuning.fit_thresholds``), so a variant is compared at its
best.  Printed per variant and per way of pooling the windows (mean scores, as the
shipped classifier, and the lower median of the windows' counts, as before): fitted
exact (beta_0, beta_1), the 4-fold cross-validated count (thresholds fitted without
each quarter), per-cell counts, counts per hole family (the family of a case's holes;
"no hole" for none) and seconds per map, after a line with the variant's wall time; then the exact count, per-cell counts and
each cell's counts per hole family when the maps are read by the shipped ``default``
classifier (as ``swarmtopo map`` reads a
log with status changes; ``trace/`` variants' maps too, which ``map`` would read with
the ``trace`` classifier).  Windows are never capped (``MapConfig.max_windows`` None)
unless a variant sets the cap: the suite's maps have at most 44 windows, but variants
that add windows would otherwise be cut back to 48.

Variants (all: hybrid metric, maxmin, automatic landmarks, h = r_d / v_c, automatic
diffusion time, wall following x 2):

* ``default`` -- ``MapConfig()`` (windows of 15, 20 and 25 encounters per agent).
* ``20s`` -- fixed 20 s windows overlapping by half (the previous default).
* ``whole`` -- the whole log at once.
* ``quarter`` -- automatic windows started every quarter window (twice the windows).
* ``draws`` -- three landmark draws (seeds) per window, all their windows pooled;
  ``draws-K`` K draws, ``draws-K/VARIANT`` K draws of another variant (e.g.
  ``draws-3/max_landmarks=250``).  The map's seed is the case's; draw d uses seed + d.
* ``seed+D`` -- the default with the landmark draw of seed + D: one of ``draws-K``'s
  draws on its own (``default`` is draw 0), to measure the spread a draw causes;
  ``VARIANT@D`` is any variant with the landmark draw of seed + D.
* ``switch`` -- a cost per change of agent instead of per hop: every pair of one
  agent's events joined with D_tau(its chain time) + h (the paper's all-pairs graph plus
  h: a path pays h once per agent it rides), built literally, O(m^2) per agent; wall
  following is charged like any other time.
* ``geodesic`` -- Vietoris-Rips on geodesic distances of a k-NN graph of the landmarks
  (k = 10, joined with a minimum spanning tree so it is connected): the Isomap-style
  re-estimate of the landmark metric from its shortest distances only.
* ``hop-half``, ``hop-double`` -- half and twice the default hop cost h; ``hop-data`` the
  hop cost a log without r_d and v_c gets, ``HOP_GAP_FACTOR`` x the mean time between an
  agent's encounters.
* ``trace/VARIANT`` -- any variant mapping only the encounters of the log, as a real
  contact trace gives them (``experiments.sweep.contact_trace``: no status changes, so
  no wall following; no r_d or speeds, so h from the data); ``trace/default`` the
  default pipeline so.
* ``dense`` -- up to 800 landmarks, covering radius down to 1 x the k-NN scale (the
  default: 400, 1.5 x); ``cover-F[/VARIANT]`` the automatic count stopping at F x the
  k-NN scale (``dense`` is ``cover-1/max_landmarks=800``).
* ``diffusive-C`` -- diffusion time tau = C x the mean time between an agent's
  encounters (the default is C = ``DIFFUSION_GAP_FACTOR``; ``diffusion_time=inf`` is
  off, the paper's weights); ``switch-C`` the same with ``switch``, where D_tau applies
  to a whole ride on one agent, not to each gap.
* ``wall-C`` -- an agent's wall-following time weighs C per second outside the
  diffusive weights (``MapConfig.wall_follow_weight``; the default is C = 2);
  ``wall-none`` charges it like any other time.
* ``pad-F`` -- each window's graph built on the window widened by F x its length on
  both sides, landmarks drawn (maxmin, whatever ``subsample`` says) only among the nodes
  inside the window: paths may
  leave the window in time, so the events at its edges are no longer the ends of cut
  chains, which maxmin otherwise favours as outliers.
* ``band-B`` -- ``MapConfig(landmark_bands=(B,))``: landmarks drawn (maxmin) only among
  the nodes of each window's middle B x its length; distances still on the whole
  window's graph: landmarks that differ in place rather than in time (the metric grows
  about 0.35 s per second between two events at one place, ``metric_vs_truth.py``).
  ``landmark_bands=1,0.5`` maps each window at both in one run, as
  ``pool:default+band-0.5`` does in two.
* ``smooth-HOW-K`` -- Vietoris-Rips on neighbourhood-averaged landmark distances:
  d~(l_i, l_j) = (A_ij + A_ji) / 2 with A_ij the mean (HOW = ``mean``) or median
  (``median``) of d(l_i, y) over the K nodes y nearest l_j, or that mean minus their
  mean distance to l_j (``meanc``): a denoiser of each landmark's own distortion.
* ``paths-C`` -- landmarks and Vietoris-Rips on the window's chain graph with every
  edge cut into pieces of at most C x its k-NN scale: points along the agents' paths
  between two encounters (event-to-event distances unchanged), so landmarks can sit
  where agents passed without meeting.  Whole-window landmarks only (``landmark_bands=1``):
  the new points have no time of their own to place them in a band.
* ``dtm-K`` -- the DTM-filtration of the landmarks (p = 1, Anai et al. 2019) instead of
  Vietoris-Rips: l_i enters at f_i, the root mean square of its distances to its K
  nearest nodes, and edge ij at max(f_i, f_j, (f_i + f_j + d_ij) / 2), so landmarks
  where few encounters happen enter late.
* ``mds-D`` -- Vietoris-Rips on the landmarks' classical MDS coordinates in R^D (the
  projection on the top D eigenvectors as a denoiser) instead of their metric.
* ``static-F`` -- the case simulated with a fraction F of its agents static from the
  start (placed at random like the rest, then never moving; the log's ``meta.json``
  lists them, so the hybrid metric links all of a static agent's encounters),
  ``static-F/VARIANT`` any variant so: what a deployment gains by parking some of its
  agents, at the same swarm size.  ``extra-F`` adds F x the cell's agents, walking;
  ``extra-static-F`` adds them static: given spare agents, park them or let them walk.
* ``FIELD=VALUE`` -- ``MapConfig(FIELD=VALUE)`` (e.g. ``subsample=knn``, ``metric=plain``).
* ``log-C`` -- chain gaps compressed logarithmically instead, tau ln(1 + w / tau), with
  tau = C x the mean time between an agent's encounters.
* ``mix`` -- the windows of K = 15 and 25 encounters per agent and the whole log, all
  in one vote; ``mix-K1-K2-...`` those of K1, K2, ..., and ``mix-K1-...-whole`` with
  the whole log too (each K at window scale 1; ``window_scales=S1,S2`` is the
  pipeline's own form of ``mix-K1-K2``, K_i = S_i x ``window_encounters``).
* ``hub`` -- h paid per change of agent instead of per hop, with the default's per-gap
  weights: each event a hub joined to one copy per agent at h / 2, an agent's
  consecutive copies joined by D_tau of the gap (wall following x 2) without h;
  Vietoris-Rips on these distances among the default's landmarks.  (``switch`` charges
  D_tau of the whole ride instead.)
* ``pool:V1+V2+...`` -- the windows of several variants (e.g. other hop costs) pooled in
  one region's score sequence, as the three window lengths are: an ensemble of metrics
  over the same events (beta_0 from V1).
* ``tcorr-S`` -- Vietoris-Rips on the landmark distances with their time separation
  taken out: within a window, events at one place but dt apart are about c + b dt
  apart (measured against the simulations' truth with ``lab/metric_vs_truth.py``),
  so d becomes sqrt((d - c)^2 - (S b dt)^2), c + b dt the lower envelope of d against dt
  fitted on the window's landmarks.
* ``witness`` -- lazy witness complex (nu = 1) on the landmarks with every event of the
  window as a witness, instead of Vietoris-Rips: edge (i, j) enters at
  min_w max(d(w, l_i), d(w, l_j)) - m_w, m_w the distance of w to its nearest landmark.

Usage::

    python lab/levers.py [--per-cell 12] [--variants default switch ...] [--cells "200 x 30" ...]
                                [--processes 2]
"""

from __future__ import annotations

import argparse
import dataclasses
import threading
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from scipy import sparse
from scipy.sparse.csgraph import dijkstra, minimum_spanning_tree, shortest_path

from swarmtopo.metric import graph as G
from swarmtopo.metric import landmarks as L
from swarmtopo.pipeline import map as P
from swarmtopo.pipeline import tasks as T
from swarmtopo.topology.embed import mds
from swarmtopo.readers.registry import load_classifier
from swarmtopo.errors import SwarmtopoError
from swarmtopo.experiments.accuracy import CELLS, tuning_arena
from swarmtopo.experiments.sweep import contact_trace, stripped_log
from tuning import TuningMap, cross_validated, exact, fit_thresholds
from swarmtopo.topology.persistence import Diagram, PersistenceResult, rips_persistence
from swarmtopo.pipeline.config import WALL_FOLLOW_WEIGHT, WHOLE_LOG
from swarmtopo.pipeline import MapConfig, config_from_options, map_encounters
from swarmtopo.pipeline.result import RegionScales, WindowMap
from swarmtopo.pipeline.settings import HOP_GAP_FACTOR, mean_agent_gap
from swarmtopo.pipeline.settings import diffusion_time as diffusion_time_of
from swarmtopo.pipeline.settings import hop_cost as hop_cost_of
from swarmtopo.pipeline.windows import in_band, window_length
from swarmtopo.readers.ratio import POOLINGS
from swarmtopo.sim import simulate


def _windows_of(log, seed, **options):
    """Each region's windows' diagrams and beta_0, every window mapped (no ``max_windows``
    cap, so window variants map the windows they describe) unless ``options`` set one."""
    tmap = map_encounters(log, MapConfig(seed=seed, embed_dim=0, cycles=False, **{"max_windows": None, **options}))
    return [[w.diagram for w in r.windows] for r in tmap.regions], tmap.betti[0]


def _quarter(log, seed):
    config = MapConfig()
    span = float(log.t[-1] - log.t[0])
    length, _ = window_length(mean_agent_gap(log), None, config.window_encounters, span)
    return _windows_of(log, seed, window_step=length / 4 if np.isfinite(length) else None)


def _draws(log, seed, k=3, mapper=None):
    mapper = mapper or _windows_of
    regions, beta0 = mapper(log, seed)
    for d in range(1, k):
        more, _ = mapper(log, seed + d)
        regions = [a + b for a, b in zip(regions, more)]
    return regions, beta0


def _log_gaps(log, seed, factor):
    """Chain gaps compressed logarithmically, tau ln(1 + w / tau), tau = factor x the mean gap."""
    original = G.diffusive_weight
    tau = factor * mean_agent_gap(log)
    G.diffusive_weight = lambda weight, diffusion_time: tau * np.log1p(weight / tau)
    try:
        return _windows_of(log, seed)
    finally:
        G.diffusive_weight = original


def _window_mix(log, seed, encounters=(15.0, 25.0), whole=True):
    """The windows of several K (encounters per agent), and the whole log, in one vote."""
    runs = [_windows_of(log, seed, window_encounters=k, window_scales=(1.0,)) for k in encounters]
    if whole:
        runs.append(_windows_of(log, seed, window_length=WHOLE_LOG, window_scales=(1.0,)))
    regions = [sum((list(r[i]) for r, _ in runs), []) for i in range(len(runs[0][0]))]
    return regions, runs[0][1]


def _switch_graph(log, metric="plain", *, window=None, hop_cost=0.0, diffusion_time=np.inf, wall_follow_weight=None):
    """The per-change-of-agent metric: every pair of one agent's events joined with
    D_tau(the chain time between them) (stops contracted as in the paper) + h; wall
    following is charged like any other time (``_switch`` maps with it off)."""
    assert wall_follow_weight is None, "the per-ride metric does not split off wall following"
    chains = G.chain_edges(log, metric, window)
    heads = np.flatnonzero(np.r_[True, chains.agent[1:] != chains.agent[:-1], True])
    u, v, w = [], [], []
    for lo, hi in zip(heads[:-1], heads[1:]):
        events = np.r_[chains.first[lo:hi], chains.second[hi - 1]]
        elapsed = np.r_[0.0, np.cumsum(chains.weight[lo:hi])]
        i, j = np.triu_indices(len(events), 1)
        u.append(events[i]), v.append(events[j])
        w.append(G.diffusive_weight(elapsed[j] - elapsed[i], diffusion_time) + hop_cost)
    return G._contract(chains.t, np.concatenate(u), np.concatenate(v), np.concatenate(w), chains.event_index, metric)


class _Rebuilt:
    """A stand-in for the pipeline's ``WeightedChains`` whose graphs are each built anew by
    ``build(log, metric, window=..., **options)``: the whole mapped log's and every
    window's, so a variant can change how a window's graph is made."""

    def __init__(self, build, log, metric, window, options):
        self.build, self.log, self.metric, self.window, self.options = build, log, metric, window, options

    def graph(self, span=None):
        return self.build(self.log, self.metric, window=self.window if span is None else span, **self.options)


def _with_graphs(build, log, seed, **options):
    """Map with every graph built by ``build`` (a ``build_graph``-like function)."""
    original = P.weighted_chains
    P.weighted_chains = lambda log_, metric, *, window=None, **kw: _Rebuilt(build, log_, metric, window, kw)
    try:
        return _windows_of(log, seed, **options)
    finally:
        P.weighted_chains = original


def _switch(log, seed, **options):
    return _with_graphs(_switch_graph, log, seed, wall_follow_weight=None, **options)


def _witness_filtration(to_nodes: np.ndarray) -> np.ndarray:
    """Lazy witness (nu = 1) edge values from (L, N) landmark-to-node distances."""
    nearest = to_nodes.min(axis=0)
    values = np.empty((len(to_nodes), len(to_nodes)))
    for i, row in enumerate(to_nodes):
        values[i] = (np.maximum(row[None, :], to_nodes) - nearest[None, :]).min(axis=1)
    values = np.maximum(np.minimum(values, values.T), 0.0)
    np.fill_diagonal(values, 0.0)
    return values


def _other_persistence(log, seed, persistence_of):
    """Map with ``persistence_of(window, sub, maxdim)`` (a PersistenceResult from a
    window's landmarks and its graph) instead of Vietoris-Rips on the landmarks' metric."""
    original = P.map_band

    def band_with_other_persistence(part, span, knn_scale, n_land, config, band, start):
        window, *seconds = original(part, span, knn_scale, n_land, config, band, start)
        return (dataclasses.replace(window, persistence=persistence_of(window, part, config.maxdim)), *seconds)

    P.map_band = band_with_other_persistence
    try:
        return _windows_of(log, seed)
    finally:
        P.map_band = original


def _other_filtration(log, seed, values_of):
    """Map with Vietoris-Rips on ``values_of(window, sub)`` (an L x L matrix from a
    window's landmarks and its graph) instead of the landmarks' metric."""
    return _other_persistence(log, seed, lambda window, sub, maxdim: rips_persistence(values_of(window, sub),
                                                                                      maxdim=maxdim))


def _witness(log, seed):
    return _other_filtration(log, seed, lambda window, sub: _witness_filtration(
        sub.distances_from(window.landmarks.nodes)))


def _geodesic_values(distances: np.ndarray, k: int = 10) -> np.ndarray:
    """Shortest paths among the landmarks over their symmetric k-NN graph joined with a
    minimum spanning tree of ``distances`` (so every pair is connected)."""
    n = len(distances)
    k = min(k, n - 1)
    rows = np.repeat(np.arange(n), k)
    cols = np.argsort(distances, axis=1, kind="stable")[:, 1:k + 1].ravel()
    knn = sparse.csr_matrix((distances[rows, cols], (rows, cols)), shape=(n, n))
    edges = knn.maximum(knn.T).maximum(minimum_spanning_tree(distances)).tocsr()
    return shortest_path(edges, method="D", directed=False)


def _geodesic(log, seed):
    return _other_filtration(log, seed, lambda window, sub: _geodesic_values(window.landmarks.distances))


def _hub_distances(log, window, hop_cost: float, diffusion_time: float, wall_follow_weight) -> np.ndarray:
    """Distances among a window's landmarks when h is paid per change of agent: every
    event is a hub joined to one copy per agent at h / 2, consecutive copies of one
    agent joined by the default's gap weight without h (D_tau of the random-walk part
    plus C x the wall-following part), so riding one agent through its encounters pays
    no h (zero weights, inside stops, become 1e-9)."""
    chains = G.chain_edges(log, "hybrid", (window.t0, window.t1))
    n = len(chains.t)
    if wall_follow_weight is None:
        weight = G.diffusive_weight(chains.weight, diffusion_time)
    else:
        following = np.minimum(G.state_time(log, G.WF, chains.agent, chains.t[chains.first],
                                            chains.t[chains.second]), chains.weight)
        weight = G.diffusive_weight(chains.weight - following, diffusion_time) + wall_follow_weight * following
    side_a = log.a[chains.event_index]
    first = n + 2 * chains.first + (side_a[chains.first] != chains.agent)
    second = n + 2 * chains.second + (side_a[chains.second] != chains.agent)
    hubs = np.arange(n)
    u = np.concatenate([first, hubs, hubs])
    v = np.concatenate([second, n + 2 * hubs, n + 2 * hubs + 1])
    w = np.maximum(np.concatenate([weight, np.full(2 * n, hop_cost / 2)]), 1e-9)
    graph = sparse.coo_matrix((np.r_[w, w], (np.r_[u, v], np.r_[v, u])), shape=(3 * n, 3 * n)).tocsr()
    sources = np.searchsorted(chains.event_index, window.landmark_events)
    values = dijkstra(graph, directed=False, indices=sources)[:, sources]
    values = np.minimum(values, values.T)
    np.fill_diagonal(values, 0.0)
    return values


def _hub(log, seed):
    hop_cost = hop_cost_of(log, None)[0]
    diffusion_time = diffusion_time_of(mean_agent_gap(log), None)[0]
    return _other_filtration(log, seed, lambda window, sub: _hub_distances(
        log, window, hop_cost, diffusion_time, WALL_FOLLOW_WEIGHT))


def _time_corrected(distances: np.ndarray, times: np.ndarray, share: float) -> np.ndarray:
    """sqrt(max(0, (d - c)^2 - (share b |t_i - t_j|)^2)): the landmark distances with the
    time separation taken out, c + b dt the lower envelope of d against dt (the 2 % quantile
    of d in 12 bins of dt up to its 90th percentile, fitted by a line)."""
    gap = np.abs(times[:, None] - times[None, :])
    upper = np.triu_indices(len(distances), 1)
    d, dt = distances[upper], gap[upper]
    edges = np.quantile(dt, np.linspace(0.0, 0.9, 13))
    points = [(np.median(dt[inside]), np.quantile(d[inside], 0.02))
              for inside in ((dt >= lo) & (dt <= hi) for lo, hi in zip(edges[:-1], edges[1:])) if inside.sum() >= 20]
    slope, offset = np.polyfit(*np.array(points).T, 1)
    values = np.sqrt(np.maximum(np.maximum(distances - offset, 0.0) ** 2 - (share * max(slope, 0.0) * gap) ** 2, 0.0))
    np.fill_diagonal(values, 0.0)
    return values


def _tcorr(log, seed, share):
    return _other_filtration(log, seed, lambda window, sub: _time_corrected(
        window.landmarks.distances, log.t[window.landmark_events], share))


def _planar_distances(distances: np.ndarray, dim: int) -> np.ndarray:
    """Euclidean distances between the landmarks' classical MDS coordinates in R^dim."""
    points = mds(distances, dim=dim, method="classical").coords
    return np.sqrt(((points[:, None, :] - points[None, :, :]) ** 2).sum(-1))


def _mds(log, seed, dim):
    return _other_filtration(log, seed, lambda window, sub: _planar_distances(window.landmarks.distances, dim))


def _smoothed_distances(to_nodes: np.ndarray, k: int, how: str) -> np.ndarray:
    """d~ of ``smooth-HOW-K`` from the (L, N) landmark-to-node distances (row i: l_i)."""
    near = np.argsort(to_nodes, axis=1, kind="stable")[:, :k]  # the K nodes nearest each landmark
    around = to_nodes[:, near]  # (L, L, K): d(l_i, y) for y near l_j
    averaged = np.median(around, axis=-1) if how == "median" else around.mean(axis=-1)
    if how == "meanc":
        averaged = averaged - np.take_along_axis(to_nodes, near, axis=1).mean(axis=1)[None, :]
    values = np.maximum(0.5 * (averaged + averaged.T), 0.0)
    np.fill_diagonal(values, 0.0)
    return values


def _smooth(log, seed, how, k):
    return _other_filtration(log, seed, lambda window, sub: _smoothed_distances(
        sub.distances_from(window.landmarks.nodes), k, how))


def _dtm_persistence(to_nodes: np.ndarray, distances: np.ndarray, k: int, maxdim: int):
    """DTM-filtration (p = 1; Anai et al. 2019) of the landmarks: l_i enters at
    f_i = DTM_k(l_i), the root mean square of its distances to its K nearest nodes, and
    edge ij at max(f_i, f_j, (f_i + f_j + d_ij) / 2); ripser.py reads a sparse matrix's
    diagonal as the vertices' values."""
    from ripser import ripser

    near = np.partition(to_nodes, min(k, to_nodes.shape[1]) - 1, axis=1)[:, :k]
    f = np.sqrt((near ** 2).mean(axis=1))
    values = np.maximum(np.maximum(f[:, None], f[None, :]), (f[:, None] + f[None, :] + distances) / 2)
    np.fill_diagonal(values, f)
    out = ripser(sparse.coo_matrix(values), maxdim=maxdim, distance_matrix=True)
    pairs = [np.asarray(d, float).reshape(-1, 2) for d in out["dgms"]]
    return PersistenceResult(Diagram(tuple(pairs), "ripser"), None, "ripser", 0.0)


def _dtm(log, seed, k):
    """Map with the DTM-filtration of each window's landmarks instead of Vietoris-Rips."""
    return _other_persistence(log, seed, lambda window, sub, maxdim: _dtm_persistence(
        sub.distances_from(window.landmarks.nodes), window.landmarks.distances, k, maxdim))


def _subdivided(graph, step: float):
    """``graph`` with every edge longer than ``step`` cut into ceil(w / step) equal
    pieces by new nodes (multiplicity 1): points of the agents' paths between two
    encounters, so the event-to-event metric is unchanged."""
    upper = sparse.triu(graph.adjacency, k=1).tocoo()
    u, v, w = upper.row.astype(np.int64), upper.col.astype(np.int64), upper.data
    pieces = np.maximum(np.ceil(w / step - 1e-9).astype(np.int64), 1)
    first_new = graph.n_nodes + np.cumsum(pieces - 1) - (pieces - 1)
    edge = np.repeat(np.arange(len(w)), pieces)
    j = np.arange(len(edge)) - np.repeat(np.cumsum(pieces) - pieces, pieces)
    a = np.where(j == 0, u[edge], first_new[edge] + j - 1)
    b = np.where(j == pieces[edge] - 1, v[edge], first_new[edge] + j)
    n = graph.n_nodes + int((pieces - 1).sum())
    half = sparse.csr_matrix((w[edge] / pieces[edge], (a, b)), shape=(n, n))
    adjacency = (half + half.T).tocsr()
    adjacency.sort_indices()
    return dataclasses.replace(graph, adjacency=adjacency,
                               multiplicity=np.r_[graph.multiplicity, np.ones(n - graph.n_nodes, np.int64)])


def _trajectory(log, seed, factor):
    """Landmarks and Rips on the chain graph's edges cut every ``factor`` x the window's
    k-NN scale s (virtual points along the agents' paths); landmarks cover to 1.5 s as
    by default."""
    original = P.map_band

    def window_on_paths(part, span, knn_scale, n_land, config, band, start):
        assert band == 1.0, band
        dense = _subdivided(part, factor * knn_scale)  # the part's nodes first: the start is one of them
        land = T.subsample(dense, config, min(config.max_landmarks, dense.n_nodes), start,
                           cover=T.AUTO_COVER_FACTOR * knn_scale)
        persistence = rips_persistence(land.distances, maxdim=config.maxdim)
        return WindowMap(t0=0.0, t1=0.0, n_events=part.n_events, landmarks=land,
                         landmark_events=np.zeros(len(land.nodes), np.int64),
                         scales=RegionScales(knn=knn_scale, cover_radius=float(land.cover_radius)),
                         persistence=persistence), 0.0, 0.0

    P.map_band = window_on_paths
    try:
        return _windows_of(log, seed, landmark_bands=(1.0,))
    finally:
        P.map_band = original


def _padded(log, seed, factor):
    """Each window's graph built on the window widened by ``factor`` x its length on both
    sides, landmarks drawn only among the nodes inside the window (inside its landmark
    band, with bands): paths may leave the
    window in time, so the events at its edges are not outliers of a cut chain."""
    original_map, original_subsample = P.map_band, T.subsample
    current = threading.local()  # windows map on parallel threads: each its own span and band

    def build(log_, metric, *, window=None, **options):
        if window is not None and None not in window:
            pad = factor * (window[1] - window[0])
            window = (window[0] - pad, window[1] + pad)
        return G.build_graph(log_, metric, window=window, **options)

    def map_band(part, span, knn_scale, n_land, config, band, start):
        current.span, current.band = span, band
        try:
            return original_map(part, span, knn_scale, n_land, config, band, start)
        finally:
            current.span = None

    def subsample(graph, config, n_landmarks, start, candidates=None, cover=None):
        if getattr(current, "span", None) is None:
            return original_subsample(graph, config, n_landmarks, start, candidates, cover)
        inside = in_band(graph.node_times(), current.span, current.band)
        # the start was drawn among the padded window's band: fold it into the window's own
        return L.maxmin(graph, n_landmarks, start=start % int(inside.sum()), cover=cover, candidates=inside)

    P.map_band, T.subsample = map_band, subsample
    try:
        return _with_graphs(build, log, seed)
    finally:
        P.map_band, T.subsample = original_map, original_subsample


def config_override(text: str) -> dict:
    """``FIELD=VALUE`` as ``{FIELD: VALUE}`` for MapConfig, VALUE read as the field's
    default's type (a tuple from comma-separated numbers: ``window_scales=0.75,1``)."""
    field, text = text.split("=", 1)
    default = getattr(MapConfig(), field)
    if isinstance(default, str):
        value = text
    elif isinstance(default, tuple):
        value = tuple(float(x) for x in text.split(","))
    else:
        value = float(text) if default is None else type(default)(float(text))
    return {field: value}


def _override(text):
    """The variant ``FIELD=VALUE``: MapConfig(FIELD=VALUE) (:func:`config_override`)."""
    options = config_override(text)
    return lambda log, seed: _windows_of(log, seed, **options)


def _pooled(names):
    """The windows of the variants ``names`` pooled per region (``pool:``); beta_0 of the first."""
    runs = [_variant(n) for n in names]

    def mapper(log, seed):
        maps = [run(log, seed) for run in runs]
        if len({len(regions) for regions, _ in maps}) > 1:
            raise ValueError(f"pool:{'+'.join(names)}: the variants find different regions")
        return [sum((list(m[0][i]) for m in maps), []) for i in range(len(maps[0][0]))], maps[0][1]
    return mapper


def _variant(name):
    if name.startswith("pool:"):
        return _pooled(name.split(":", 1)[1].split("+"))
    if "@" in name:
        base, offset = name.rsplit("@", 1)
        return lambda log, seed: _variant(base)(log, seed + int(offset))
    if name.startswith("trace/"):
        inner = _variant(name.split("/", 1)[1])
        return lambda log, seed: inner(contact_trace(log), seed)
    if name.startswith("draws-"):
        k, _, inner = name.split("-", 1)[1].partition("/")
        return lambda log, seed: _draws(log, seed, int(k), _variant(inner) if inner else None)
    if "=" in name:
        return _override(name)
    if name.startswith("seed+"):
        return lambda log, seed: _windows_of(log, seed + int(name.split("+", 1)[1]))
    if name.startswith("wall-"):
        return lambda log, seed: _windows_of(log, seed, wall_follow_weight=config_from_options({"wall_follow_weight": name.split("-", 1)[1]}).wall_follow_weight)
    if name.startswith("pad-"):
        return lambda log, seed: _padded(log, seed, float(name.split("-", 1)[1]))
    if name.startswith("band-"):
        return lambda log, seed: _windows_of(log, seed, landmark_bands=(float(name.split("-", 1)[1]),))
    if name.startswith("smooth-"):
        _, how, k = name.split("-")
        return lambda log, seed: _smooth(log, seed, how, int(k))
    if name.startswith("paths-"):
        return lambda log, seed: _trajectory(log, seed, float(name.split("-", 1)[1]))
    if name.startswith("mix-"):
        parts = name.split("-")[1:]
        whole = parts[-1] == "whole"
        encounters = tuple(float(k) for k in parts[:len(parts) - whole])
        return lambda log, seed: _window_mix(log, seed, encounters, whole=whole)
    if name.startswith("cover-"):
        factor, _, inner = name.split("-", 1)[1].partition("/")
        return _covering(float(factor), _variant(inner or "default"))
    if name.startswith("dtm-"):
        return lambda log, seed: _dtm(log, seed, int(name.split("-", 1)[1]))
    if name.startswith("mds-"):
        return lambda log, seed: _mds(log, seed, int(name.split("-", 1)[1]))
    if name.startswith("tcorr-"):
        return lambda log, seed: _tcorr(log, seed, float(name.split("-", 1)[1]))
    if name.startswith("log-"):
        return lambda log, seed: _log_gaps(log, seed, float(name.split("-", 1)[1]))
    if name.startswith(("diffusive-", "switch-")):
        mapper = _windows_of if name.startswith("diffusive-") else _switch
        factor = float(name.split("-", 1)[1])
        return lambda log, seed: mapper(log, seed, diffusion_time=factor * mean_agent_gap(log))
    return VARIANTS[name]


def _hop_times(factor):
    return lambda log, seed: _windows_of(log, seed, hop_cost=factor * hop_cost_of(log, None)[0])


def _covering(factor, inner):
    """``inner`` mapped with the automatic landmark count stopping at r_cover <= factor x
    the k-NN scale (``cover-F``)."""
    def mapper(log, seed):
        original = T.AUTO_COVER_FACTOR
        T.AUTO_COVER_FACTOR = factor
        try:
            return inner(log, seed)
        finally:
            T.AUTO_COVER_FACTOR = original
    return mapper


SHIPPED = load_classifier("default")
"""The classifier ``map`` reads a log with status changes with: each variant's maps are also read by it."""

VARIANTS = {
    "default": lambda log, seed: _windows_of(log, seed),
    "20s": lambda log, seed: _windows_of(log, seed, window_length=20.0),
    "whole": lambda log, seed: _windows_of(log, seed, window_length=WHOLE_LOG),
    "quarter": _quarter,
    "draws": _draws,
    "switch": _switch,
    "witness": _witness,
    "geodesic": _geodesic,
    "hop-half": _hop_times(0.5),
    "hop-double": _hop_times(2.0),
    "hop-data": lambda log, seed: _windows_of(log, seed, hop_cost=HOP_GAP_FACTOR * mean_agent_gap(log)),
    "dense": _covering(1.0, lambda log, seed: _windows_of(log, seed, max_landmarks=800)),
    "mix": _window_mix,
    "hub": _hub,
}


SWARM_PREFIXES = ("static-", "extra-static-", "extra-")
"""Variant prefixes that change the simulated swarm (``_swarm``), longest match first."""


def _swarm(name, agents):
    """(agents, static fraction, variant) of a swarm variant (module docstring): ``static-F``
    parks F of the ``agents``, ``extra-F`` adds F x ``agents`` walkers, ``extra-static-F``
    adds them parked; ``/VARIANT`` maps with VARIANT (default without), ``@D`` keeps its
    landmark draw.  Any other name: (agents, 0, name)."""
    prefix = next((p for p in sorted(SWARM_PREFIXES, key=len, reverse=True) if name.startswith(p)), None)
    if prefix is None:
        return agents, 0.0, name
    share, _, inner = name[len(prefix):].partition("/")
    share, at, draw = share.partition("@")
    share, inner = float(share), (inner or "default") + at + draw
    if prefix == "static-":
        return agents, share, inner
    total = int(round(agents * (1 + share)))
    return total, ((total - agents) / total if prefix == "extra-static-" else 0.0), inner


def _run(task):
    name, cell_index, index = task
    cell = CELLS[cell_index]
    arena_table, seed, arena, stream = tuning_arena(cell, index)
    agents, static, name = _swarm(name, cell.agents)
    log = stripped_log(simulate(arena, agents, cell.duration, static_fraction=static, rng=stream).log)
    family = arena_table["shapes"][0] if arena_table["holes"] else "no hole"
    start = time.perf_counter()
    try:
        regions, beta0 = _variant(name)(log, seed % 2**32)
    except SwarmtopoError:
        return None, cell.name, family, time.perf_counter() - start
    truth = arena.betti
    return (TuningMap(tuple(tuple(r) for r in regions), beta0, truth[0], truth[1], cell.name), cell.name, family,
            time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-cell", type=int, default=12)
    parser.add_argument("--variants", nargs="+", default=["default", "20s", "whole", "quarter", "draws", "switch"],
                        help=f"{', '.join(sorted(VARIANTS))}, diffusive-C, switch-C, log-C, wall-C, wall-none, "
                             "static-F, extra-F, extra-static-F (each [/VARIANT]), smooth-HOW-K, pad-F, band-B, paths-C, dtm-K, mds-D, mix-K1-K2[-whole], draws-K[/VARIANT], trace/VARIANT, seed+D, "
                             "tcorr-S, pool:V1+V2+..., cover-F[/VARIANT] or "
                             "FIELD=VALUE; "
                             "VARIANT@D: with the landmark draw of seed + D")
    parser.add_argument("--cells", nargs="+", metavar="TEXT",
                        help="only the cells whose name contains one of these (default: all)")
    parser.add_argument("--processes", type=int, default=2)
    args = parser.parse_args()
    cells = [i for i, c in enumerate(CELLS) if not args.cells or any(text in c.name for text in args.cells)]
    if args.per_cell * len(cells) < 4:
        parser.error(f"{args.per_cell * len(cells)} map(s) per variant: the 4-fold cross-validation needs at least 4")
    print(f"tuning cases of {len(cells)} cells x {args.per_cell}; per cell: "
          + ", ".join(CELLS[c].name for c in cells))
    for name in args.variants:
        tasks = [(name, c, i) for i in range(args.per_cell) for c in cells]
        start = time.perf_counter()
        with ProcessPoolExecutor(args.processes) as pool:
            results = list(pool.map(_run, tasks))
        print(f"{name}: {len(tasks)} maps in {(time.perf_counter() - start) / 60:.1f} min", flush=True)
        maps = [m for m, _, _, _ in results if m is not None]
        family_of = [f for m, _, f, _ in results if m is not None]
        seconds = np.mean([s for _, _, _, s in results])
        for pooling in POOLINGS:
            fit = fit_thresholds(maps, pooling)
            right = exact(maps, fit.thresholds, pooling)
            cv = cross_validated(maps, pooling)
            per_cell = [int(sum(ok for m, ok in zip(maps, right) if m.cell == CELLS[c].name)) for c in cells]
            per_family = ", ".join(f"{f} {sum(ok for g, ok in zip(family_of, right) if g == f)}/{family_of.count(f)}"
                                   for f in sorted(set(family_of)))
            th = fit.thresholds
            print(f"{name}, {pooling}: {int(right.sum())}/{len(tasks)} exact (q {th.q:g}, tau {th.tau:g}); "
                  f"4-fold CV {cv}/{len(tasks)}; per cell {per_cell}; per hole family {per_family}; "
                  f"{seconds:.2f} s per map", flush=True)
        shipped = exact(maps, SHIPPED.thresholds_[1], SHIPPED.pooling)
        per_cell = [int(sum(ok for m, ok in zip(maps, shipped) if m.cell == CELLS[c].name)) for c in cells]
        print(f"{name}, read by the shipped default classifier: {int(shipped.sum())}/{len(tasks)} exact; "
              f"per cell {per_cell}", flush=True)
        for c in cells:
            inside = [(f, ok) for m, f, ok in zip(maps, family_of, shipped) if m.cell == CELLS[c].name]
            print(f"    {CELLS[c].name}: " + ", ".join(
                f"{f} {sum(ok for g, ok in inside if g == f)}/{sum(g == f for g, _ in inside)}"
                for f in sorted({f for f, _ in inside})), flush=True)


if __name__ == "__main__":
    main()
