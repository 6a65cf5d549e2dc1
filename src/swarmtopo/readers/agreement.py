r"""Cross-window cycle agreement: is a rank's loop the same loop in overlapping windows?

A region's log is mapped in overlapping time windows (:mod:`swarmtopo.pipeline.map`).  A
true hole is the same hole in every window, and consecutive windows share events; a
noise loop of one window need not be a loop of the next.  A gated classifier
(:class:`~swarmtopo.readers.ratio.RatioClassifier` with an ``agreement`` threshold: the ``gated``
preset; the default reads the score alone) counts a rank k only if its pooled score
passes *and* its agreement A_k does.

Circular coordinates (de Silva, Morozov and Vejdemo-Johansson 2011).  For each of a
window's ``BARS`` longest H1 bars, its representative cocycle over Z/``PRIME`` (ripser.py)
is lifted to the integers (coefficients above (p - 1) / 2 minus p) and smoothed by least
squares on the Rips 1-skeleton at the middle of the bar, radius b + (d - b) / 2:
theta = argmin ||delta theta - c||, taken mod 1, one value in [0, 1) per landmark.  Every
event of the window takes the theta of its nearest landmark in the window's graph.

Agreement.  Two windows whose spans overlap by at least ``OVERLAP`` of the shorter one
are compared on the events they share (at least ``MIN_SHARED``), bar i of one with bar
j of the other, by the centred correlation of z = exp(2 pi i theta), free of rotation
and reflection of the circle:

    a_ij = max(|<z_i - mean, z_j - mean>|, |<z_i - mean, conj(z_j) - mean>|) / (|z_i - mean| |z_j - mean|)

(uncentred, two nearly constant fields would agree).  A window's bar k agrees by its
best a_kj, averaged over the windows it overlaps (0 if the window has fewer than k
bars); A_k is the mean of that over the region's windows that overlap another.  A
region with no two overlapping windows has no agreement (NaN: the gate lets it pass).

The least squares run on the Rips 1-skeleton at mid-bar as it is: landmarks in a
component of it that the cocycle does not touch keep theta = 0.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
from scipy import sparse
from scipy.sparse.csgraph import dijkstra
from scipy.sparse.linalg import lsqr

from ..topology.persistence import Diagram, rips_persistence

BARS = 5
"""M: a window's longest H1 bars given circular coordinates (A_1 .. A_M)."""
PRIME = 47
"""Coefficients of the cocycles (a Z/2 cocycle cannot be lifted to an integer one)."""
OVERLAP = 0.4
"""Windows overlapping by this share of the shorter one are compared."""
MIN_SHARED = 10
"""Two windows sharing fewer events than this do not agree on anything (a_ij = 0)."""


def circular_coordinates(distances: np.ndarray, bar: np.ndarray, cocycle: np.ndarray) -> np.ndarray:
    """theta in [0, 1) of each landmark for one H1 bar (birth, death) and its Z/PRIME cocycle."""
    birth, death = bar
    radius = birth + 0.5 * ((death if np.isfinite(death) else distances.max()) - birth)
    iu, ju = np.triu_indices(len(distances), 1)
    keep = distances[iu, ju] <= radius
    iu, ju = iu[keep], ju[keep]
    rows = np.asarray(cocycle, dtype=np.int64).reshape(-1, 3)
    values = rows[:, 2].astype(float)
    values[values > (PRIME - 1) / 2] -= PRIME  # the integer lift
    lifted = np.zeros(distances.shape)
    lifted[rows[:, 0], rows[:, 1]] = values
    lifted[rows[:, 1], rows[:, 0]] = -values
    edges = np.arange(len(iu))
    coboundary = sparse.csr_matrix((np.r_[-np.ones(len(iu)), np.ones(len(iu))], (np.r_[edges, edges], np.r_[iu, ju])),
                                   shape=(len(iu), len(distances)))
    return np.mod(lsqr(coboundary, lifted[iu, ju], atol=1e-10, btol=1e-10, iter_lim=5000)[0], 1.0)


def window_coordinates(distances: np.ndarray, diagram: Diagram, nodes: np.ndarray,
                       graph) -> tuple[np.ndarray, np.ndarray]:
    """One window's (events, sorted by log index; (BARS, events) theta, NaN rows for missing bars).

    ``distances`` are the window's landmark distances, ``diagram`` their (Z/2) persistence,
    ``nodes`` the landmark nodes in ``graph`` (an :class:`~swarmtopo.metric.graph.EncounterGraph`
    of the window's events).  The cocycles come from a second run over Z/PRIME, stopped
    at the last death of the BARS longest bars (bars dying later are left infinite and
    not used): half the time of the whole filtration, the same bars.
    """
    if not len(diagram[1]):
        return graph.event_index[:0], np.full((BARS, 0), np.nan)
    stop = float(diagram[1][_longest(diagram), 1].max())
    result = rips_persistence(distances, maxdim=1, cocycles=True, coefficients=PRIME,
                              threshold=stop if np.isfinite(stop) else np.inf)
    pairs = result.diagram[1]
    theta = np.full((BARS, len(distances)), np.nan)
    for k, i in enumerate(_longest(result.diagram)):
        theta[k] = circular_coordinates(distances, pairs[i], result.cocycles[1][i])
    _, _, source = dijkstra(graph.adjacency, indices=nodes, min_only=True, return_predecessors=True)
    landmark_of_node = np.full(graph.n_nodes, -1)
    landmark_of_node[nodes] = np.arange(len(nodes))
    event_source = source[graph.node_of_event]  # scipy marks a node no landmark reaches with a negative source
    nearest = np.where(event_source >= 0, landmark_of_node[np.maximum(event_source, 0)], -1)
    reached = nearest >= 0
    events = graph.event_index[reached]
    order = np.argsort(events, kind="stable")
    return events[order], theta[:, nearest[reached]][:, order]


def _longest(diagram: Diagram) -> np.ndarray:
    """Indices of the BARS longest finite H1 bars (ties by position)."""
    lengths = diagram.lengths(1)
    finite = np.flatnonzero(np.isfinite(lengths))
    return finite[np.argsort(-lengths[finite], kind="stable")[:BARS]]


def pair_agreement(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """(BARS, BARS) centred agreements a_ij of window a's bars with window b's (0 for a missing bar)."""
    _, ia, ib = np.intersect1d(a[0], b[0], return_indices=True)
    if len(ia) < MIN_SHARED:
        return np.zeros((BARS, BARS))
    za, zb = np.exp(2j * np.pi * a[1][:, ia]), np.exp(2j * np.pi * b[1][:, ib])
    ca, cb = za - za.mean(axis=1, keepdims=True), zb - zb.mean(axis=1, keepdims=True)
    norms = np.outer(np.linalg.norm(ca, axis=1), np.linalg.norm(cb, axis=1)) + 1e-12
    return np.nan_to_num(np.maximum(np.abs(ca @ cb.conj().T), np.abs(ca @ cb.T)) / norms)


def overlapping(spans: Sequence[tuple[float, float]], i: int) -> list[int]:
    """The windows whose span overlaps window i's by at least OVERLAP of the shorter one."""
    lo, hi = spans[i]
    return [j for j, (lo2, hi2) in enumerate(spans)
            if j != i and min(hi, hi2) - max(lo, lo2) >= OVERLAP * min(hi - lo, hi2 - lo2)]


def agreement_array(values) -> np.ndarray:
    """A_k as floats from an array or a JSON list (null: NaN)."""
    return np.array([np.nan if a is None else a for a in values], dtype=float)


def rank_agreement(coordinates: Sequence[tuple[np.ndarray, np.ndarray] | None],
                   spans: Sequence[tuple[float, float]]) -> np.ndarray:
    """A_1 .. A_BARS of a region from its windows' coordinates (:func:`window_coordinates`; None
    allowed for a window that overlaps no other) and spans (t0, t1); all NaN when no two
    windows overlap (module docstring)."""
    pairs = {}  # (i, j), i < j: a_ij of the two windows (a_ji is its transpose)
    per_window = []
    for i in range(len(coordinates)):
        near = overlapping(spans, i)
        if not near:
            continue
        for j in near:
            if (min(i, j), max(i, j)) not in pairs:
                pairs[min(i, j), max(i, j)] = pair_agreement(coordinates[min(i, j)], coordinates[max(i, j)])
        best = np.mean([(pairs[i, j] if i < j else pairs[j, i].T).max(axis=1) for j in near], axis=0)
        per_window.append(np.where(np.isnan(coordinates[i][1]).all(axis=1), 0.0, best))
    return np.mean(per_window, axis=0) if per_window else np.full(BARS, np.nan)
