"""Multidimensional scaling of the landmark distances, for pictures.

The paper projects the encounter point cloud onto 3-D Euclidean space with MDS to
let a person look at it; nothing topological is computed from the picture.  Both
methods are scikit-learn's:

``"metric"``
    SMACOF (``sklearn.manifold.MDS``, metric MDS on precomputed dissimilarities)
    started from the classical (Torgerson) solution.  That start is exact for
    Euclidean input and near the optimum otherwise: on 500-landmark geodesic
    matrices of a two-hole domain it converged in about 60 iterations to the same
    stress as four random restarts, about four times faster; hence one start,
    at most :data:`SMACOF_MAX_ITER` iterations, tolerance :data:`SMACOF_EPS`.
``"classical"``
    Classical MDS (``sklearn.manifold.ClassicalMDS``): the top eigenvectors of the
    double-centred squared distances.  Fast and exact for Euclidean input, but it
    minimises strain, not stress, so it is worse on curved metrics.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from sklearn.manifold import MDS, ClassicalMDS
from threadpoolctl import threadpool_limits

from ..errors import InputError
from .persistence import check_distance_matrix

METHODS: tuple[str, ...] = ("metric", "classical")
SMACOF_MAX_ITER = 300
"""SMACOF iteration cap (sklearn's default); the classical start usually needs < 100."""
SMACOF_EPS = 1e-6
"""SMACOF stops when the relative decrease of the stress falls below this."""


@dataclass(frozen=True, eq=False)
class Embedding:
    """Coordinates of the landmarks in R^dim.

    Attributes
    ----------
    coords
        (L, dim) float64 coordinates.
    stress
        Kruskal's stress-1 over pairs i < j:
        sqrt(sum (d_ij - delta_ij)^2 / sum delta_ij^2), where delta are the input
        distances and d the Euclidean distances of ``coords``; 0 is a perfect fit.
    method
        ``"metric"`` or ``"classical"``.
    """

    coords: np.ndarray
    stress: float
    method: str


def kruskal_stress(coords: np.ndarray, distances: np.ndarray) -> float:
    """Kruskal stress-1 of ``coords`` against the distance matrix (pairs i < j)."""
    i, j = np.triu_indices(len(distances), k=1)
    target = distances[i, j]
    fitted = np.linalg.norm(coords[i] - coords[j], axis=1)
    return float(np.sqrt(np.sum((fitted - target) ** 2) / np.sum(target**2)))


def mds(distances, dim: int = 3, *, rng=None, method: str = "metric") -> Embedding:
    """Embed the landmarks in R^dim so that Euclidean distances match ``distances``.

    Parameters
    ----------
    distances
        (L, L) landmark distances (encounter metric), validated like
        :func:`swarmtopo.topology.persistence.check_distance_matrix`; L > dim, and not all 0.
    dim
        Target dimension (3 for the paper's pictures).
    rng
        Seed or Generator, forwarded to scikit-learn's ``random_state``.  The
        classical start makes both methods deterministic, so the result does not
        depend on it; it is accepted so that swapping in a randomised start keeps
        the seeding discipline.
    method
        ``"metric"`` (SMACOF from the classical start) or ``"classical"``.

    Returns
    -------
    Embedding
    """
    matrix = check_distance_matrix(distances)
    if method not in METHODS:
        raise InputError(f"unknown MDS method; expected one of {list(METHODS)}", value=method)
    if isinstance(dim, bool) or not isinstance(dim, (int, np.integer)) or dim < 1:
        raise InputError("dim must be a positive integer", value=dim)
    if len(matrix) <= dim:
        raise InputError(f"need more than dim = {dim} points to embed, got {len(matrix)}")
    if not matrix.any():
        raise InputError("all distances are 0: nothing to embed")
    # One BLAS thread: on L <= a few thousand the threads cost more than they give
    # (measured 2x faster at L = 300 on 2 cores, up to 10x under load).
    with threadpool_limits(limits=1, user_api="blas"):
        return _embed(matrix, int(dim), rng, method)


def _embed(matrix: np.ndarray, dim: int, rng, method: str) -> Embedding:
    if method == "classical":
        coords = ClassicalMDS(n_components=dim, metric="precomputed").fit_transform(matrix)
    else:
        seed = int(np.random.default_rng(rng).integers(2**31 - 1))
        solver = MDS(
            n_components=dim,
            metric_mds=True,
            metric="precomputed",
            init="classical_mds",
            n_init=1,
            max_iter=SMACOF_MAX_ITER,
            eps=SMACOF_EPS,
            random_state=seed,
            normalized_stress=True,
        )
        coords = solver.fit_transform(matrix)
    coords = np.asarray(coords, dtype=np.float64)
    return Embedding(coords, kruskal_stress(coords, matrix), method)
