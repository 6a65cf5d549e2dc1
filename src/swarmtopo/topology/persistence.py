"""Vietoris-Rips persistence of a landmark distance matrix, behind one adapter.

The paper computes Rips persistence of the L x L encounter-metric matrix of the
landmarks (Dionysus); here a Ripser-family library does it, and nothing downstream
knows which one ran: every backend's output is normalised into :class:`Diagram`.

Backends (see :func:`available_backends`), all Rips persistence of a *dense* distance
matrix over the field Z/2:

``"gudhi"``
    ``gudhi.sklearn.rips_persistence.RipsPersistence`` (MIT; Gudhi's Ripser fork in
    double precision).  Fastest in ``benchmarks/bench_persistence.py``; the default.
``"ripser"``
    ripser.py (MIT).  The only backend that returns representative cocycles, so
    ``cocycles=True`` picks it under ``backend="auto"``.
``"giotto"``
    giotto-ph's ``ripser_parallel`` (AGPL): used only if the user installed it.

Conventions shared by all backends (the adapter enforces them):

* The filtration is the Rips filtration X(eps): an edge {i, j} enters at
  eps = d_ij, a simplex when all its edges are in.  Edges longer than ``threshold``
  never enter; classes alive at the threshold are reported as infinite bars.
* ``dgm_n`` holds the bars [b, d) of dimension n; ``d = inf`` for bars that never
  die.  A connected input has exactly one infinite H0 bar, born at 0.
* Zero-length bars (b == d) are dropped: they carry no topology, and Ripser-family
  libraries drop most of them natively (the adapter drops the rest).  So are bars at
  most ``ROUNDING_RTOL`` (1e-9) times the dimension's largest value long: encounter
  distances are sums of time gaps, and the same path summed in two orders differs in
  the last bit, which opens bars of length ~1e-15 s.
* Bars are sorted by decreasing length d - b (infinite first), ties by birth.
* Birth and death values are exact entries of the input matrix (float64).  ripser.py
  and giotto-ph compute in float32; the adapter feeds them the *ranks* of the
  distances (the Rips filtration only depends on their order) and maps the ranks
  back, so every backend returns bit-identical diagrams.

Infinite distances are refused: an encounter graph that falls apart into components
must be split first (each component gets its own matrix and diagram), so that
"separate regions" and "too little data" can be told apart by the caller.
"""

from __future__ import annotations

import importlib
import importlib.util
import time
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, SwarmtopoError

BACKENDS: tuple[str, ...] = ("gudhi", "ripser", "giotto")
"""All supported backends, fastest permissively licensed first."""

_BACKEND_MODULES = {"gudhi": "gudhi", "ripser": "ripser", "giotto": "gph"}
_BACKEND_ENTRY_MODULES = {"gudhi": "gudhi.sklearn.rips_persistence", "ripser": "ripser", "giotto": "gph"}
_INSTALL_HINTS = {
    "gudhi": "pip install gudhi",
    "ripser": "pip install ripser",
    "giotto": "pip install giotto-ph (AGPL-licensed)",
}

SYMMETRY_RTOL = 1e-9
"""|d_ij - d_ji| and |d_ii| may be at most this times max |d| (Dijkstra from i and
from j may sum the same path in different orders); the matrix is then symmetrised
and its diagonal set to 0."""

ROUNDING_RTOL = 1e-9
"""Bars no longer than this times the largest finite birth/death of their dimension are
dropped as rounding noise (see :func:`_canonical_order`)."""

_FLOAT32_EXACT_INTEGERS = 2**24
"""Ranks above this are not exactly representable in float32."""


# -- Diagram ----------------------------------------------------------------------------
def _canonical_order(pairs: np.ndarray) -> np.ndarray:
    """Indices of the bars longer than rounding noise, by decreasing length then birth.

    A bar at most ROUNDING_RTOL times the dimension's largest finite value long is
    rounding noise (two sums of the same path in different orders), not topology.
    """
    lengths = pairs[:, 1] - pairs[:, 0]
    values = np.abs(pairs[np.isfinite(pairs)])
    floor = ROUNDING_RTOL * values.max() if len(values) else 0.0
    keep = np.flatnonzero(lengths > floor)
    order = np.lexsort((pairs[keep, 0], -lengths[keep]))
    return keep[order]


def _as_pairs(values, dim) -> np.ndarray:
    pairs = np.asarray(values, dtype=np.float64)
    if pairs.size == 0:
        return np.empty((0, 2))
    if pairs.ndim != 2 or pairs.shape[1] != 2:
        raise InputError(
            f"dimension {dim}: expected an (m, 2) array of [birth, death] pairs, got shape {pairs.shape}"
        )
    if not np.isfinite(pairs[:, 0]).all():
        raise InputError(f"dimension {dim}: births must be finite numbers")
    if np.isnan(pairs[:, 1]).any() or (pairs[:, 1] < pairs[:, 0]).any():
        raise InputError(f"dimension {dim}: every death must be >= its birth (or inf)")
    return pairs


@dataclass(frozen=True, eq=False)
class Diagram:
    """Persistence diagrams dgm_0 .. dgm_maxdim of one Rips filtration.

    Attributes
    ----------
    pairs
        ``pairs[n]`` is an (m_n, 2) float64 read-only array of bars [b^i_n, d^i_n];
        ``d = inf`` for infinite bars.  On construction, zero-length bars and rounding noise (ROUNDING_RTOL) are dropped
        and bars are sorted by decreasing length, then birth.
    backend
        Which library computed it (or ``"json"`` when read back).
    """

    pairs: tuple[np.ndarray, ...]
    backend: str

    def __post_init__(self):
        if len(self.pairs) == 0:
            raise InputError("a diagram needs at least dimension 0")
        canonical = []
        for dim, values in enumerate(self.pairs):
            pairs = _as_pairs(values, dim)
            pairs = np.ascontiguousarray(pairs[_canonical_order(pairs)])
            pairs.flags.writeable = False
            canonical.append(pairs)
        object.__setattr__(self, "pairs", tuple(canonical))

    def __getitem__(self, dim: int) -> np.ndarray:
        """dgm_dim as an (m, 2) array."""
        if not 0 <= dim <= self.maxdim:
            raise IndexError(f"diagram has dimensions 0..{self.maxdim}, asked for {dim}")
        return self.pairs[dim]

    @property
    def maxdim(self) -> int:
        """Highest homology dimension computed."""
        return len(self.pairs) - 1

    def lengths(self, dim: int) -> np.ndarray:
        """Bar lengths d - b in dimension ``dim`` (inf for infinite bars), decreasing."""
        pairs = self[dim]
        return pairs[:, 1] - pairs[:, 0]

    def finite(self, dim: int) -> np.ndarray:
        """The bars of dimension ``dim`` that die."""
        pairs = self[dim]
        return pairs[np.isfinite(pairs[:, 1])]

    def to_json(self) -> dict:
        """``{"0": [[b, d], ...], "1": ...}`` with ``None`` as the death of infinite bars."""
        return {
            str(dim): [[float(b), float(d) if np.isfinite(d) else None] for b, d in pairs]
            for dim, pairs in enumerate(self.pairs)
        }

    @classmethod
    def from_json(cls, obj: dict, backend: str = "json") -> "Diagram":
        """Inverse of :meth:`to_json`; keys must be "0".."maxdim"."""
        if not isinstance(obj, dict):
            raise InputError("a diagram must be a JSON object {\"0\": [[b, d], ...], ...}", value=obj)
        expected = [str(dim) for dim in range(len(obj))]
        if sorted(obj, key=str) != sorted(expected):
            raise InputError(f"diagram keys must be {expected}", value=list(obj))
        pairs = []
        for key in expected:
            try:
                rows = [[b, np.inf if d is None else d] for b, d in obj[key]]
            except (TypeError, ValueError):
                raise InputError(f"dimension {key}: expected a list of [birth, death] pairs",
                                 value=obj[key]) from None
            pairs.append(_as_pairs(rows, key) if rows else np.empty((0, 2)))
        return cls(tuple(pairs), backend)


@dataclass(frozen=True, eq=False)
class PersistenceResult:
    """What :func:`rips_persistence` computed.

    Attributes
    ----------
    diagram
        The persistence diagrams.
    cocycles
        Only with ``cocycles=True`` (ripser.py): ``cocycles[n][i]`` is the
        representative cocycle of bar ``diagram[n][i]`` as ripser.py returns it, an
        int array whose rows are ``[v_0, ..., v_n, coefficient]`` (an n-simplex and
        its coefficient in Z/p); ``cocycles[0]`` is empty.  Otherwise ``None``.
    backend
        The backend that ran.
    seconds
        Wall time of the backend call, input conversion included, validation not.
    """

    diagram: Diagram
    cocycles: list | None
    backend: str
    seconds: float


# -- input checks -----------------------------------------------------------------------
def check_distance_matrix(distances, *, name: str = "distances") -> np.ndarray:
    """Validate a dense distance matrix and return it as a symmetric float64 array.

    Square, at least 1 x 1, no NaN, no infinite or negative entry, symmetric and with a
    zero diagonal up to :data:`SYMMETRY_RTOL` (then made exact).

    Raises
    ------
    InputError
        Naming the first offending entry.  Infinite distances mean disconnected
        points: split the components first.
    """
    try:
        matrix = np.array(distances, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a numeric square matrix") from None
    if matrix.ndim != 2 or matrix.shape[0] != matrix.shape[1] or matrix.shape[0] == 0:
        raise InputError(f"{name} must be a non-empty square matrix, got shape {matrix.shape}")
    if not np.isfinite(matrix).all():
        nan = np.argwhere(np.isnan(matrix))
        if len(nan):
            i, j = nan[0]
            raise InputError(f"{name}[{i}, {j}] is NaN; distances must be numbers")
        i, j = np.argwhere(~np.isfinite(matrix))[0]
        if matrix[i, j] > 0:
            raise InputError(
                f"{name}[{i}, {j}] is infinite: the points are not all connected. Split the "
                "encounter graph into connected components first and compute persistence "
                "per component (beta_0 counts the components)"
            )
    negative = np.argwhere(matrix < 0)
    if len(negative):
        i, j = negative[0]
        raise InputError(f"{name}[{i}, {j}] = {matrix[i, j]!r} is negative; distances must be >= 0")
    tolerance = SYMMETRY_RTOL * matrix.max()
    asymmetry = np.abs(matrix - matrix.T)
    if asymmetry.max() > tolerance:
        i, j = np.unravel_index(np.argmax(asymmetry), asymmetry.shape)
        raise InputError(
            f"{name} is not symmetric: [{i}, {j}] = {matrix[i, j]!r} but [{j}, {i}] = {matrix[j, i]!r}"
        )
    diagonal = np.abs(np.diagonal(matrix))
    if diagonal.max() > tolerance:
        i = int(np.argmax(diagonal))
        raise InputError(f"{name}[{i}, {i}] = {matrix[i, i]!r}; the diagonal must be 0")
    matrix = 0.5 * (matrix + matrix.T)  # exact no-op on an exactly symmetric matrix
    np.fill_diagonal(matrix, 0.0)
    return matrix


# -- backends ---------------------------------------------------------------------------
def available_backends() -> list[str]:
    """Installed backends, in order of preference (fastest permissive first)."""
    return [name for name in BACKENDS if importlib.util.find_spec(_BACKEND_MODULES[name]) is not None]


def _choose_backend(backend: str, cocycles: bool) -> str:
    installed = available_backends()
    if backend == "auto":
        if cocycles:
            backend = "ripser"
        elif installed:
            return installed[0]
        else:
            raise SwarmtopoError("no persistence backend installed: pip install gudhi")
    if backend not in BACKENDS:
        raise InputError(f"unknown persistence backend; expected 'auto' or one of {list(BACKENDS)}",
                         value=backend)
    if backend not in installed:
        raise SwarmtopoError(f"persistence backend '{backend}' is not installed: {_INSTALL_HINTS[backend]}")
    if cocycles and backend != "ripser":
        raise InputError("representative cocycles are only available from backend 'ripser'",
                         value=backend)
    return backend


def _rank_transform(matrix: np.ndarray, threshold: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Distances -> their ranks among the distinct values, exactly as float32 can hold.

    The Rips filtration depends only on the order of the distances, so persistence
    of the ranks, mapped back through ``values[rank]``, is the exact persistence of
    the input.  Returns (ranks, values, threshold as a rank).
    """
    values, inverse = np.unique(matrix, return_inverse=True)
    if len(values) > _FLOAT32_EXACT_INTEGERS:
        raise SwarmtopoError(
            f"{len(values)} distinct distances exceed float32 precision; use backend 'gudhi'"
        )
    ranks = inverse.reshape(matrix.shape).astype(np.float32)
    rank_threshold = np.inf if np.isinf(threshold) else float(
        np.searchsorted(values, threshold, side="right") - 1
    )
    return ranks, values, rank_threshold


def _unrank(pairs: np.ndarray, values: np.ndarray) -> np.ndarray:
    pairs = np.asarray(pairs, dtype=np.float64).reshape(-1, 2)
    exact = np.full_like(pairs, np.inf)
    finite = np.isfinite(pairs)
    exact[finite] = values[pairs[finite].astype(np.int64)]
    return exact


def _gudhi(matrix, maxdim, threshold):
    from gudhi.sklearn.rips_persistence import RipsPersistence

    rips = RipsPersistence(
        homology_dimensions=list(range(maxdim + 1)),
        threshold=threshold,
        input_type="full distance matrix",
        homology_coeff_field=2,
    )
    return rips.fit_transform([matrix])[0], None


def _ripser(matrix, maxdim, threshold, cocycles):
    from ripser import ripser

    ranks, values, rank_threshold = _rank_transform(matrix, threshold)
    out = ripser(ranks, maxdim=maxdim, thresh=rank_threshold, coeff=2,
                 distance_matrix=True, do_cocycles=cocycles)
    return [_unrank(d, values) for d in out["dgms"]], out["cocycles"] if cocycles else None


def _giotto(matrix, maxdim, threshold):
    from gph import ripser_parallel

    ranks, values, rank_threshold = _rank_transform(matrix, threshold)
    out = ripser_parallel(ranks, maxdim=maxdim, thresh=rank_threshold, coeff=2, metric="precomputed")
    return [_unrank(d, values) for d in out["dgms"]], None


def rips_persistence(distances, maxdim: int = 1, *, backend: str = "auto",
                     threshold: float = np.inf, cocycles: bool = False) -> PersistenceResult:
    """Vietoris-Rips persistence diagrams dgm_0 .. dgm_maxdim of a distance matrix.

    Parameters
    ----------
    distances
        (L, L) distances between the landmarks (encounter metric), finite, symmetric,
        zero diagonal; see :func:`check_distance_matrix`.
    maxdim
        Highest homology dimension: 0 (components), 1 (holes) or 2.
    backend
        ``"auto"`` (gudhi, or ripser.py when cocycles are asked for) or one of
        :data:`BACKENDS`.
    threshold
        Largest filtration value eps; longer edges never enter the complex.
    cocycles
        Also return representative cocycles (ripser.py only).

    Returns
    -------
    PersistenceResult
        Diagrams in the conventions of the module docstring, identical whatever the
        backend.
    """
    matrix = check_distance_matrix(distances)
    if isinstance(maxdim, bool) or not isinstance(maxdim, (int, np.integer)) or maxdim not in (0, 1, 2):
        raise InputError("maxdim must be 0, 1 or 2", value=maxdim)
    maxdim = int(maxdim)
    if not (isinstance(threshold, (int, float, np.number)) and threshold > 0):
        raise InputError("threshold must be a positive number (or inf)", value=threshold)
    threshold = float(threshold)
    name = _choose_backend(backend, cocycles)
    importlib.import_module(_BACKEND_ENTRY_MODULES[name])  # keep import time out of `seconds`

    start = time.perf_counter()
    if name == "gudhi":
        raw, raw_cocycles = _gudhi(matrix, maxdim, threshold)
    elif name == "ripser":
        raw, raw_cocycles = _ripser(matrix, maxdim, threshold, cocycles)
    else:
        raw, raw_cocycles = _giotto(matrix, maxdim, threshold)
    seconds = time.perf_counter() - start

    pairs, kept_cocycles = [], [] if cocycles else None
    for dim in range(maxdim + 1):
        dgm = np.asarray(raw[dim], dtype=np.float64).reshape(-1, 2) if dim < len(raw) else np.empty((0, 2))
        order = _canonical_order(dgm)
        pairs.append(dgm[order])
        if cocycles:
            kept_cocycles.append([raw_cocycles[dim][i] for i in order] if dim > 0 else [])
    return PersistenceResult(Diagram(tuple(pairs), name), kept_cocycles, name, seconds)


def bottleneck(d1: Diagram, d2: Diagram, dim: int) -> float:
    """Bottleneck distance between dgm_dim of two diagrams (``gudhi.bottleneck_distance``).

    Infinite bars are matched among themselves (inf if their numbers differ).
    """
    import gudhi

    for diagram in (d1, d2):
        if not 0 <= dim <= diagram.maxdim:
            raise InputError(f"diagram has dimensions 0..{diagram.maxdim}", value=dim)
    return float(gudhi.bottleneck_distance(d1[dim], d2[dim]))


# -- Signal-to-noise ratio (paper, "Probabilistic maxmin") -------------------------------
@dataclass(frozen=True)
class SignalToNoise:
    """SNR of one diagram in dimension n given the true beta_n.

    signal_power
        P_S = mean |l|^2 over the beta_n longest bars (0 when beta_n = 0).
    noise_power
        P_N = mean |l|^2 over the other bars (0 when there are none).
    ratio
        P_S / P_N; 0 when beta_n = 0, inf when there is no noise bar.
    """

    signal_power: float
    noise_power: float
    ratio: float


def snr(diagram: Diagram, dim: int, beta: int, *, infinite_length: float | None = None) -> SignalToNoise:
    """The paper's SNR of ``dgm_dim``: signal = the ``beta`` longest bars, noise = the rest.

    The paper sorts the lengths "in non-decreasing order" and takes the first beta_n,
    which would make the shortest bars the signal; we take the *longest* (its stated
    intent: long bars are signal).  An infinite bar counts with length
    ``infinite_length``, by default the largest finite death in the diagram minus its
    birth (the scale at which the filtration is complete).  If the diagram has fewer
    than ``beta`` bars, the missing signal bars count with length 0.
    """
    if beta < 0:
        raise InputError(f"beta must be >= 0, got {beta}")
    lengths = _capped_lengths(diagram, dim, infinite_length)
    signal = np.zeros(beta)
    signal[: min(beta, len(lengths))] = lengths[:beta]
    noise = lengths[beta:]
    p_signal = float(np.mean(signal**2)) if beta else 0.0
    p_noise = float(np.mean(noise**2)) if len(noise) else 0.0
    if p_noise > 0:
        ratio = p_signal / p_noise
    else:
        ratio = 0.0 if p_signal == 0 else float("inf")
    return SignalToNoise(signal_power=p_signal, noise_power=p_noise, ratio=ratio)


def mean_snr(diagrams, dim: int, beta: int) -> float:
    """Average SNR ratio over N diagrams of independent subsampling runs (paper's measure)."""
    ratios = [snr(d, dim, beta).ratio for d in diagrams]
    if not ratios:
        raise InputError("mean_snr needs at least one diagram")
    return float(np.mean(ratios))


def _capped_lengths(diagram: Diagram, dim: int, infinite_length: float | None) -> np.ndarray:
    """Bar lengths of ``dgm_dim``, decreasing, with infinite bars capped (see :func:`snr`)."""
    pairs = diagram[dim]
    lengths = pairs[:, 1] - pairs[:, 0]
    infinite = ~np.isfinite(lengths)
    if infinite.any():
        if infinite_length is None:
            deaths = np.concatenate([p[:, 1] for p in diagram.pairs])
            deaths = deaths[np.isfinite(deaths)]
            top = float(deaths.max()) if len(deaths) else 0.0
            lengths = np.where(infinite, np.maximum(top - pairs[:, 0], 0.0), lengths)
        else:
            lengths = np.where(infinite, float(infinite_length), lengths)
    return np.sort(lengths)[::-1]
