r"""Scale- and density-free Betti classifier, pooled across time windows (swarmtopo's default).

The paper's classifier compares bar lengths l with l_q + Delta, l_q the q-quantile of
the diagram's lengths and Delta in seconds; in our benchmark thresholds in seconds did
not transfer between swarm densities, durations or arena sizes (docs/accuracy.md).
This classifier uses only ratios, which do not change when every distance is
multiplied by a constant.  In one window, a dim-n bar of length l *scores*

    s = ln(l / l_q),   clipped to [0, LOG_RATIO_CAP]

with l_q the q-quantile of the window's finite dim-n bar lengths (the length of its
typical noise loop); an infinite bar scores LOG_RATIO_CAP.  The window's scores in
decreasing order are s_(1) >= s_(2) >= ..., and a rank the window has no bar for
scores 0.  The window's own count is #{k : s_(k) > ln tau_n}: the paper's form with
Delta = 0, bars longer than tau_n l_q.

A region's log is cut into time windows of several lengths (``MapConfig.window_length``,
``window_scales``), each mapped on its own.  Its beta_hat_n *pools* them (``pooling``):

``"mean"`` (the default)
    the mean score of each rank over the W windows, S_k = (1/W) sum_w s^w_(k), and
    beta_hat_n = #{k : S_k > ln tau_n}.  S is non-increasing (a mean of non-increasing
    sequences), so the counted ranks are the first ones.  The lower median of the
    windows' counts (below) throws away how far each window's bars are from the
    threshold and, with two windows, is their minimum; on the benchmark's tuning cases
    the mean scored higher (docs/accuracy.md).
``"median"``
    the lower median of the windows' own counts.

Either way the counted bars of a window drawn for the user are its beta_hat_n longest
(:class:`~swarmtopo.readers.base.WindowReader`).

Fitting (:meth:`RatioClassifier.fit`).  (q_1, tau_1) is chosen on maps with known
beta_1 over the grid ``q_grid`` x ``tau_grid``: each map's beta_hat_1 (the sum over its
regions) at every grid point, the exact rate of each point (a map whose beta_0 is wrong
is wrong at every point), and the point whose mean rate over itself and its two tau
neighbours (edges repeated) is highest (ties: the first), so that the choice sits inside
a plateau rather than on a lucky spike.  Neighbours in q are not averaged: l_q grows
with q, so the same tau means a different length threshold in the next q row.

Confidence.  For each region the first feature is the vote's *standardised margin* z:
how many standard errors the pooled scores are from changing the vote beta,

    z = min((S_beta - ln tau_n) / se_beta, (ln tau_n - S_{beta+1}) / se_{beta+1}),
    se_k = sqrt((v_k + SCORE_VAR_PRIOR) / W),

v_k the variance over the W windows of their k-th scores (0 for one window) and
SCORE_VAR_PRIOR a prior variance, so that a few windows that happen to agree do not
make z infinite; a side without a rank counts as Z_CAP, and z is capped there.
The second feature is the windows' *resolution* ln L: the mean over the windows of
ln min(L_w, RESOLUTION_CAP), L_w the number of landmarks of window w (its dim-0 bars:
the places it tells apart).  Windows agree on a wrong count too when they resolve few
places (a sparse swarm, a short log): no bar at all is then a confident "no hole".
P(correct) is a logistic regression of z, ln L and z ln L (so that the windows'
agreement weighs more the more places they resolve), fitted on the benchmark's tuning
maps and on a calibration grid of swarms and logs beyond the suite's budgets
(:meth:`RatioClassifier.calibrate`, ``lab/tune_accuracy.py``); files calibrated on z
alone are applied so.

A map of several regions (beta_0 >= 2) is right when every region is, and its
confidence is the product of its regions' raised to a power a, ``regions_exponent`` of
the calibration (:meth:`RatioClassifier.map_confidence`; 1, the plain product, where a
file has none).  The regional model is fitted on one-region maps, whose landmarks cover
a whole arena; a region of a two-room arena has fewer (ln L lower) and its confidence
is lower than how often it is right.  a is fitted by maximum likelihood on the
benchmark's two-room tuning maps (``lab/tune_accuracy.py``; docs/accuracy.md, "Confidence").
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
from scipy.ndimage import uniform_filter1d
from scipy.special import expit
from sklearn.base import BaseEstimator
from sklearn.linear_model import LogisticRegression

from .. import __version__
from .._validate import check_format
from ..errors import InputError, SwarmtopoError
from ..topology.persistence import Diagram
from .base import WindowReader, median_vote, product_confidence, vote

RATIO_FORMAT = "swarmtopo-ratio-classifier/5"
"""The one file format read and written."""
POOLINGS = ("mean", "median")
MAX_MARGIN = 3.0
"""Cap of the log margin (a score e^3 = 20 times off the threshold is as sure as it gets)."""
Z_CAP = 10.0
"""Cap of the standardised margin z (ten standard errors from changing is as sure as it gets)."""
SCORE_VAR_PRIOR = 0.25 ** 2
"""Prior variance of a window's score at one rank (log units squared): se_k never falls below 0.25 / sqrt(W)."""
RESOLUTION_CAP = 400
"""Landmark count at which a window's resolution saturates: the automatic count's cap
(``MapConfig.max_landmarks``) in every map the confidence was calibrated on, so a larger
``--max-landmarks`` does not read as a resolution never calibrated."""
CONFIDENCE_FEATURES = ("z", "resolution", "z_x_resolution")
"""The features :meth:`RatioClassifier.calibrate` fits: all three, or z alone."""
SPAN_FEATURES = ("log_span", "z_x_log_span")
"""ln T and z ln T, T the seconds a region's windows cover (:func:`windows_span`): candidate
features ``lab/calibration.py`` measures (not adopted, docs/accuracy.md), as is ln #windows
("windows"); no calibration weighs them."""
REGIONS_EXPONENT = "regions_exponent"
"""The calibration key of a, the power of the product of a several-region map's regional
confidences (:meth:`RatioClassifier.map_confidence`)."""

LOG_RATIO_CAP = float(np.log(1e3))
"""Cap of a bar's score: a bar 1000 times the typical noise loop (or infinite) is as long as it gets."""
Q_GRID = (0.5, 0.6, 0.7, 0.8, 0.9)
TAU_GRID = tuple(np.round(np.geomspace(1.2, 12.0, 80), 4))
"""The (q_1, tau_1) grid :meth:`RatioClassifier.fit` searches by default."""


@dataclass(frozen=True)
class RatioThresholds:
    """(q_n, tau_n) of one dimension: a bar counts in its window when l > tau_n l_q."""

    q: float
    tau: float

    def to_json(self) -> dict[str, float]:
        return {"q": self.q, "tau": self.tau}


def noise_length(diagram: Diagram, dim: int, q: float) -> float:
    """l_q: the q-quantile of the window's finite dim-n bar lengths (0 without one)."""
    length = diagram.lengths(dim)
    finite = length[np.isfinite(length)]
    return float(np.quantile(finite, q)) if len(finite) else 0.0


def window_scores(diagram: Diagram, dim: int, q: float) -> np.ndarray:
    """s_(1) >= s_(2) >= ...: the clipped log-ratios ln(l / l_q) of the window's dim-n bars,
    decreasing (module docstring); empty without bars."""
    if dim > diagram.maxdim or not len(diagram[dim]):
        return np.empty(0)
    length = diagram.lengths(dim)
    finite = np.isfinite(length)
    lq = noise_length(diagram, dim, q)
    scores = np.full(len(length), LOG_RATIO_CAP)
    if lq > 0:
        with np.errstate(divide="ignore"):
            scores[finite] = np.clip(np.log(length[finite] / lq), 0.0, LOG_RATIO_CAP)
    else:  # no finite bar with a length (none, or all of length 0): only infinite bars score
        scores[finite] = 0.0
    return np.sort(scores)[::-1]


def resolution(windows: Sequence[Diagram]) -> float:
    """ln L of a region: the mean over its windows of ln min(L_w, RESOLUTION_CAP), L_w the
    window's landmarks that are apart (its dim-0 bars: one per landmark, the zero-length
    bars of coincident ones dropped)."""
    return float(np.mean([np.log(max(1, min(len(w[0]), RESOLUTION_CAP))) for w in windows]))


def windows_span(windows: Sequence[dict[str, Any]]) -> float:
    """T, the seconds a region's windows cover: the last window's end minus the first one's
    start (their stored records' ``t0`` and ``t1``)."""
    return float(max(w["t1"] for w in windows) - min(w["t0"] for w in windows))


def below_full_resolution(windows: Sequence[Diagram]) -> bool:
    """Whether the windows average fewer than RESOLUTION_CAP landmarks (in log units, so
    that windows all at the cap are at full resolution)."""
    return resolution(windows) < np.log(RESOLUTION_CAP) - 1e-9


def confidence_readout(classifier: "RatioClassifier", landmarks: Sequence[int] = (RESOLUTION_CAP, 100, 20)) -> str:
    """How a beta_1 calibration of z and the resolution reads at windows of ``landmarks``
    landmarks (what docs/accuracy.md quotes): z's slope, the coefficient of z plus that of
    z ln L times ln L, and P(right) at z = 0."""
    model = classifier.calibration_["1"]
    ln_l = np.log(np.asarray(landmarks, dtype=float))
    slopes = model["z"] + model.get("z_x_resolution", 0.0) * ln_l
    at_zero = [calibrated_probability(model, {"z": 0.0, "resolution": x, "z_x_resolution": 0.0}) for x in ln_l]
    return "; ".join(f"L = {count}: z's slope {slope:.2f}, P(right | z = 0) {p:.2f}"
                     for count, slope, p in zip(landmarks, slopes, at_zero))


def calibrated_probability(model: dict[str, float], features: dict[str, float]) -> float:
    """P(right) of a fitted calibration ``model`` (intercept, maps and one coefficient per
    feature it weighs) at ``features``: expit(intercept + sum of coefficient x feature).
    A feature it weighs that ``features`` lacks is an error, not a zero."""
    weighed = {name: coef for name, coef in model.items() if name not in ("intercept", "maps", REGIONS_EXPONENT)}
    missing = sorted(set(weighed) - set(features))
    if missing:
        raise ValueError(f"the confidence calibration weighs {', '.join(missing)}, which the region's features lack")
    return float(expit(model["intercept"] + sum(coef * features[name] for name, coef in weighed.items())))


def confidence_model() -> LogisticRegression:
    """The (unfitted) logistic model :meth:`RatioClassifier.calibrate` fits on :func:`confidence_design`."""
    return LogisticRegression(C=1.0)


def confidence_design(features: Sequence[dict[str, float]], names: Sequence[str] = CONFIDENCE_FEATURES) -> np.ndarray:
    """(regions, len(names)) matrix of the named features (:meth:`RatioClassifier.region_features`) of each region."""
    return np.array([[f[name] for name in names] for f in features], dtype=float).reshape(-1, len(names))


def score_matrix(diagrams: Sequence[Diagram], dim: int, q: float) -> np.ndarray:
    """(W, K) scores s^w_(k) of the W windows, a rank a window has no bar for scoring 0."""
    ranked = [window_scores(d, dim, q) for d in diagrams]
    out = np.zeros((len(ranked), max((len(s) for s in ranked), default=0)))
    for w, s in enumerate(ranked):
        out[w, :len(s)] = s
    return out


def pooled_scores(diagrams: Sequence[Diagram], dim: int, q: float) -> np.ndarray:
    """S_k: the mean over windows of their k-th score, a missing rank scoring 0 (module docstring)."""
    matrix = score_matrix(diagrams, dim, q)
    return matrix.mean(axis=0) if len(matrix) else np.zeros(0)


def standardised_margin(matrix: np.ndarray, count: int, tau: float) -> float:
    """z of a vote of ``count`` from the windows' score ``matrix`` (:func:`score_matrix`):
    the nearer of S_count and S_{count+1} to ln tau in standard errors (module docstring)."""
    n_windows, n_ranks = matrix.shape
    means = matrix.mean(axis=0)
    var = matrix.var(axis=0, ddof=1) if n_windows > 1 else np.zeros(n_ranks)
    se = np.sqrt((var + SCORE_VAR_PRIOR) / n_windows)
    sides = [Z_CAP]
    if count >= 1:
        sides.append((means[count - 1] - np.log(tau)) / se[count - 1])
    if count < n_ranks:
        sides.append((np.log(tau) - means[count]) / se[count])
    return float(min(sides))


def count_above(scores: np.ndarray, tau: float) -> int:
    """#{k : scores_k > ln tau} of non-increasing scores."""
    return int(np.count_nonzero(scores > np.log(tau)))


def score_margin(scores: np.ndarray, tau: float) -> float:
    """How far, in log units, the count of non-increasing ``scores`` is from changing:
    the nearer of the last counted and the first uncounted score to ln tau (capped)."""
    count = count_above(scores, tau)
    sides = []
    if count:
        sides.append(scores[count - 1] - np.log(tau))
    if count < len(scores):
        sides.append(np.log(tau) - scores[count])
    return float(min([MAX_MARGIN, *sides]))


def grid_estimates(maps: Sequence[Sequence[Sequence[Diagram]]], pooling: str = "mean",
                   q_grid: Sequence[float] = Q_GRID, tau_grid: Sequence[float] = TAU_GRID) -> np.ndarray:
    """beta_hat_1 of every map at every grid point, ``(len(maps), len(q_grid), len(tau_grid))``:
    the pooled count (:meth:`RatioClassifier.pooled_betti`) summed over each map's regions,
    at once for every tau.  ``maps[k]`` is map k's regions, each its windows' diagrams."""
    log_tau = np.log(np.asarray(tau_grid, dtype=float))

    def counts_over_tau(scores: np.ndarray) -> np.ndarray:  # #{k : scores_k > ln tau} for every tau
        return len(scores) - np.searchsorted(np.sort(scores), log_tau, side="right")

    est = np.zeros((len(maps), len(q_grid), len(log_tau)), np.int64)
    for k, regions in enumerate(maps):
        for region in regions:
            for i, q in enumerate(q_grid):
                if pooling == "mean":
                    est[k, i] += counts_over_tau(pooled_scores(region, 1, q))
                else:
                    counts = np.sort([counts_over_tau(window_scores(d, 1, q)) for d in region], axis=0)
                    est[k, i] += counts[(len(region) - 1) // 2]
    return est


class RatioClassifier(WindowReader, BaseEstimator):
    """beta_hat_n from bar lengths over their window's noise scale, pooled over windows.

    scikit-learn conventions: ``__init__`` only stores, :meth:`fit` returns self,
    learned attributes end in ``_``.  A classifier of given thresholds (a file, a
    study's candidate) is made by :meth:`from_thresholds`.

    Parameters
    ----------
    pooling
        ``"mean"`` (pooled scores) or ``"median"`` (lower median of the windows' counts).
    q_grid, tau_grid
        The grid :meth:`fit` searches (q in [0, 1]; tau in [1, 1000), increasing).

    Attributes
    ----------
    thresholds_ : dict[int, RatioThresholds]
        ``{n: (q_n, tau_n)}`` for each homology dimension n >= 1.
    calibration_ : dict
        Per dimension the logistic P(correct): ``{"intercept", "z", "resolution",
        "z_x_resolution"}`` or ``{"intercept", "z"}`` (:meth:`region_features`), either
        with ``"regions_exponent"`` (:meth:`map_confidence`); empty = uncalibrated.
        (beta_0's confidence is the pipeline's: :mod:`swarmtopo.readers.beta0`.)
    provenance_ : dict
        Free-form record of how it was fitted (name, data, script, ``pipeline``).
    accuracy_ : float
        The exact rate of the fitted grid point on the training maps (:meth:`fit` only).
    surface_ : np.ndarray
        ``(len(q_grid), len(tau_grid))`` exact rates on the training maps (:meth:`fit` only).
    """

    def __init__(self, pooling: str = "mean", q_grid: Sequence[float] = Q_GRID,
                 tau_grid: Sequence[float] = TAU_GRID):
        self.pooling = pooling
        self.q_grid = q_grid
        self.tau_grid = tau_grid

    # -- fitting -------------------------------------------------------------------------
    def fit(self, X: Sequence[Sequence[Sequence[Diagram]]], y, beta0_right=None,
            provenance: dict | None = None) -> "RatioClassifier":
        """(q_1, tau_1) on the grid (module docstring, "Fitting").

        ``X[k]`` is map k's regions, each a sequence of its windows' diagrams; ``y[k]``
        its true beta_1; ``beta0_right[k]`` whether its beta_0 was right (default: all),
        a map whose beta_0 is wrong being wrong whatever the thresholds.
        """
        _check_pooling(self.pooling)
        q_grid = [float(q) for q in self.q_grid]
        tau_grid = np.asarray(self.tau_grid, dtype=float)
        if not q_grid or any(not 0.0 <= q <= 1.0 for q in q_grid):
            raise SwarmtopoError(f"q_grid must be values in [0, 1], got {list(self.q_grid)}")
        if (tau_grid.ndim != 1 or not len(tau_grid) or np.any(np.diff(tau_grid) <= 0) or tau_grid[0] < 1.0
                or tau_grid[-1] >= np.exp(LOG_RATIO_CAP)):
            raise SwarmtopoError(f"tau_grid must be increasing values in [1, 1000), got {list(self.tau_grid)}")
        truth = np.asarray(y, dtype=np.int64)
        right_beta0 = np.ones(len(X), bool) if beta0_right is None else np.asarray(beta0_right, dtype=bool)
        if not len(X) or truth.shape != (len(X),) or right_beta0.shape != (len(X),):
            raise SwarmtopoError(f"fit needs one or more maps and one true beta_1 (and beta0_right) per map, got "
                                 f"{len(X)} maps, y of shape {truth.shape}, beta0_right of shape {right_beta0.shape}")
        if (truth < 0).any():
            raise SwarmtopoError("true Betti numbers must be >= 0")
        right = (grid_estimates(X, self.pooling, q_grid, tau_grid) == truth[:, None, None]) & right_beta0[:, None, None]
        surface = right.mean(axis=0)
        smooth = uniform_filter1d(surface, size=3, axis=1, mode="nearest")
        i, j = np.unravel_index(int(np.argmax(smooth + 1e-9 * surface)), surface.shape)
        self.thresholds_ = {1: RatioThresholds(q_grid[i], float(tau_grid[j]))}
        self.calibration_ = {}
        self.provenance_ = dict(provenance or {})
        self.accuracy_ = float(surface[i, j])
        self.surface_ = surface
        return self

    def calibrate(self, features: Sequence[dict[str, float]], correct,
                  names: Sequence[str] = CONFIDENCE_FEATURES) -> "RatioClassifier":
        """Fit P(correct | the ``names`` features: CONFIDENCE_FEATURES or z alone) for dimension 1.

        ``features[k]`` are region k's (:meth:`region_features`, of this or of another
        classifier when the outcomes are cross-fitted) and ``correct[k]`` whether its
        vote was right.
        """
        self._check_fitted()
        if tuple(names) not in (CONFIDENCE_FEATURES, ("z",)):
            raise SwarmtopoError(f"a calibration weighs {', '.join(CONFIDENCE_FEATURES)} or z alone, "
                                 f"not {', '.join(names)}")
        X = confidence_design(features, names)
        y = np.asarray(correct, dtype=bool)
        if len(np.unique(y)) == 2:
            model = confidence_model().fit(X, y)
            intercept, coefficients = float(model.intercept_[0]), model.coef_[0]
        else:  # all right (or all wrong): the smoothed rate, whatever the features
            rate = (y.sum() + 1) / (len(y) + 2)
            intercept, coefficients = float(np.log(rate / (1 - rate))), np.zeros(len(names))
        self.calibration_ = {"1": {"intercept": intercept, **dict(zip(names, map(float, coefficients))),
                                   "maps": int(len(y))}}
        self.provenance_.pop("regions_calibration", None)  # a new regional model: no power fitted on it yet
        return self

    @classmethod
    def from_thresholds(cls, thresholds: dict[int, RatioThresholds], calibration: dict | None = None,
                        provenance: dict | None = None, pooling: str = "mean") -> "RatioClassifier":
        """A classifier of given thresholds (and calibration), not fitted here; checked."""
        _check_pooling(pooling)
        model = cls(pooling=pooling)
        model.thresholds_ = _checked_thresholds(thresholds)
        model.calibration_ = _checked_calibration(calibration or {}, model.thresholds_)
        model.provenance_ = dict(provenance or {})
        return model

    def _check_fitted(self) -> None:
        if not hasattr(self, "thresholds_"):
            raise SwarmtopoError("this RatioClassifier is not fitted yet: call fit() or load one")

    # -- one window --------------------------------------------------------------------
    def betti(self, diagram: Diagram) -> dict[int, int]:
        """The window's own beta_hat_n, for n up to the diagram's maxdim."""
        self._check_fitted()
        return {n: count_above(window_scores(diagram, n, th.q), th.tau)
                for n, th in self.thresholds_.items() if n <= diagram.maxdim}

    def length_thresholds(self, diagram: Diagram) -> dict[int, float]:
        """tau_n l_q: the length a bar of this window must exceed to count in it, seconds."""
        self._check_fitted()
        return {n: th.tau * noise_length(diagram, n, th.q)
                for n, th in self.thresholds_.items() if n <= diagram.maxdim}

    def margin(self, diagram: Diagram, n: int) -> float:
        """How far the window's own count in dimension n is from changing (:func:`score_margin`)."""
        th = self.thresholds_[n]
        return score_margin(window_scores(diagram, n, th.q), th.tau)

    # -- a region: several windows --------------------------------------------------------
    def pooled_betti(self, windows: Sequence[Diagram]) -> dict[int, int]:
        """The region's beta_hat_n: pooled scores (``"mean"``) or the lower median of the
        windows' counts (``"median"``)."""
        self._check_fitted()
        maxdim = windows[0].maxdim
        if self.pooling == "median":
            return {n: median_vote([self.betti(d)[n] for d in windows]) for n in self.thresholds_ if n <= maxdim}
        return {n: count_above(score_matrix(windows, n, th.q).mean(axis=0), th.tau)
                for n, th in self.thresholds_.items() if n <= maxdim}

    def region_features(self, windows: Sequence[Diagram], n: int, voted=None,
                        span: float | None = None) -> dict[str, float]:
        """One region's confidence features for dimension n: z, the resolution ln L and their
        product (module docstring), and ln #windows; given ``span`` (the seconds T its
        windows cover) also ln T and z ln T (SPAN_FEATURES).
        ``voted`` is :func:`vote`'s result for these windows when the caller has it."""
        betti = (voted or vote(self, windows))[0]
        th = self.thresholds_[n]
        z = standardised_margin(score_matrix(windows, n, th.q), betti[n], th.tau)
        ln_l = resolution(windows)
        features = {"z": z, "resolution": ln_l, "z_x_resolution": z * ln_l, "windows": float(np.log(len(windows)))}
        if span is not None:
            ln_t = float(np.log(span))
            features |= {"log_span": ln_t, "z_x_log_span": z * ln_t}
        return features

    def region_confidence(self, windows: Sequence[Diagram], voted=None) -> dict[int, float | None]:
        """P(the region's beta_hat_n is right) from the calibrated model; None if uncalibrated.
        ``voted``: :func:`vote`'s result for these windows, when the caller has it."""
        voted = voted or vote(self, windows)
        out: dict[int, float | None] = {}
        for n in self.thresholds_:
            if n > windows[0].maxdim:
                continue
            model = self.calibration_.get(str(n))
            out[n] = None if model is None else calibrated_probability(model, self.region_features(windows, n, voted))
        return out

    def map_confidence(self, confidences: Sequence[float | None], n: int = 1) -> float | None:
        """P(a map's beta_n is right) from its regions' P(right): the one region's, or for
        several their product raised to the calibration's ``regions_exponent`` a (1 where
        it has none); None if a region has none (module docstring)."""
        model = self.calibration_.get(str(n)) or {}
        return product_confidence(confidences, model.get(REGIONS_EXPONENT, 1.0))

    # -- description and files ------------------------------------------------------------
    def describe(self) -> dict[str, Any]:
        """What map.json says about how its Betti numbers were read."""
        self._check_fitted()
        pooled = ("the number of ranks k whose mean score over the time windows exceeds ln tau, a window's k-th "
                  "score being ln(l / l_q) of its k-th longest dim-n bar (clipped to [0, ln 1000]; l_q = q-quantile "
                  "of the window's dim-n bar lengths)" if self.pooling == "mean" else
                  "the lower median over time windows of the number of dim-n bars longer than tau * l_q "
                  "(l_q = q-quantile of the window's dim-n bar lengths)")
        return {
            "classifier": self.provenance_.get("name", "custom"),
            "definition": f"beta_n = {pooled}",
            "pooling": self.pooling,
            "threshold": "tau_n l_q",
            "theta": {str(n): th.to_json() for n, th in self.thresholds_.items()},
            "confidence": self._confidence_definition(),
        }

    def _confidence_definition(self) -> str:
        model = self.calibration_.get("1")
        if model is None:
            return "uncalibrated"
        if "resolution" in model:
            regional = ("P(correct) from a logistic model of z, how many standard errors (over the windows) the "
                        "pooled scores are from changing the vote, of the windows' resolution ln L (L landmarks, at "
                        f"most {RESOLUTION_CAP}) and of z ln L, fitted on the benchmark's tuning maps and its "
                        "calibration grid")
        else:
            regional = ("P(correct) from a logistic model of z, how many standard errors (over the windows) the "
                        "pooled scores are from changing the vote, fitted on the benchmark's tuning maps")
        return regional + (
            f"; a map of several regions: the product of its regions' to the power {model[REGIONS_EXPONENT]:.3g}, "
            "fitted on the benchmark's two-room tuning maps" if REGIONS_EXPONENT in model else
            "; a map of several regions: the product of its regions'")

    def to_json(self) -> dict[str, Any]:
        self._check_fitted()
        return {
            "format": RATIO_FORMAT,
            "pooling": self.pooling,
            "thresholds": {str(n): th.to_json() for n, th in self.thresholds_.items()},
            "calibration": self.calibration_ or None,
            "provenance": {**self.provenance_, "swarmtopo": self.provenance_.get("swarmtopo", __version__)},
        }

    @classmethod
    def from_json(cls, obj: dict, source: str = "<json>") -> "RatioClassifier":
        """A classifier from a file's object: format RATIO_FORMAT only, every field checked."""
        check_format(obj, RATIO_FORMAT, "swarmtopo ratio classifier", source)
        try:
            thresholds = obj.get("thresholds")
            if not isinstance(thresholds, dict) or not thresholds:
                raise InputError("must be an object of {dimension: {q, tau}}", column="thresholds", value=thresholds)
            parsed = {}
            for n, t in thresholds.items():
                if not isinstance(t, dict) or set(t) != {"q", "tau"}:
                    raise InputError("must be an object of exactly 'q' and 'tau'", column=f"thresholds.{n}", value=t)
                parsed[_dimension(n, f"thresholds.{n}")] = RatioThresholds(
                    _real(t["q"], f"thresholds.{n}.q"), _real(t["tau"], f"thresholds.{n}.tau"))
            provenance = obj.get("provenance") or {}
            if not isinstance(provenance, dict):
                raise InputError("must be an object", column="provenance", value=provenance)
            return cls.from_thresholds(parsed, obj.get("calibration"), provenance, obj.get("pooling"))
        except InputError as exc:
            if exc.file is not None:
                raise
            raise InputError(exc.reason, file=source, row=exc.row, column=exc.column, value=exc.value) from None


def _check_pooling(pooling) -> None:
    if pooling not in POOLINGS:
        raise InputError(f"unknown pooling; expected one of {', '.join(POOLINGS)}", column="pooling", value=pooling)


def _dimension(key, column: str) -> int:
    """A homology dimension n >= 1 from a JSON key ("1") or an int."""
    try:
        n = int(key)
    except (TypeError, ValueError):
        n = 0
    if n < 1 or str(n) != str(key):
        raise InputError("must be a homology dimension n >= 1", column=column, value=key)
    return n


def _real(value, column: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
        raise InputError("must be a finite number", column=column, value=value)
    return float(value)


def _checked_thresholds(thresholds: dict[int, RatioThresholds]) -> dict[int, RatioThresholds]:
    """``thresholds`` sorted by dimension; each dimension >= 1 with 0 <= q <= 1 and 1 <= tau < 1000."""
    if not thresholds:
        raise InputError("a ratio classifier needs thresholds of one dimension or more", column="thresholds", value={})
    for n, th in thresholds.items():
        if not (int(n) >= 1 and 0.0 <= th.q <= 1.0 and 1.0 <= th.tau < np.exp(LOG_RATIO_CAP)):
            raise InputError(f"ratio thresholds of dimension {n} out of range (need 0 <= q <= 1, 1 <= tau < 1000)",
                             column=f"thresholds.{n}", value=th.to_json())
    return {int(n): th for n, th in sorted(thresholds.items())}


def _checked_calibration(calibration, thresholds: dict[int, RatioThresholds]) -> dict:
    """``calibration`` if each entry is a model of a dimension the classifier reads: an
    intercept, z, optionally the resolution and z ln L together, optionally a positive
    ``regions_exponent`` and a count of ``maps``, all finite numbers."""
    if not isinstance(calibration, dict):
        raise InputError("must be an object of {dimension: model}", column="calibration", value=calibration)
    known = {"intercept", "maps", REGIONS_EXPONENT, *CONFIDENCE_FEATURES}
    for n, model in calibration.items():
        column = f"calibration.{n}"
        if str(n) not in {str(d) for d in thresholds}:
            raise InputError(f"a calibration of a dimension the classifier does not read (it reads "
                             f"{', '.join(map(str, thresholds))})", column=column, value=model)
        if not isinstance(model, dict) or "intercept" not in model or "z" not in model:
            raise InputError("a calibration needs 'intercept' and 'z'", column=column, value=model)
        unknown = set(model) - known
        if unknown:
            raise InputError(f"unknown confidence feature(s) {sorted(unknown)}; known: "
                             f"{', '.join(CONFIDENCE_FEATURES)} (and {REGIONS_EXPONENT})", column=column, value=model)
        if ("resolution" in model) != ("z_x_resolution" in model):
            raise InputError("a calibration weighs 'resolution' and 'z_x_resolution' together, or neither",
                             column=column, value=model)
        for key, value in model.items():
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value) or (
                    key == "maps" and value < 0):
                raise InputError("must be a finite number", column=f"{column}.{key}", value=value)
            if key == REGIONS_EXPONENT and value <= 0:
                raise InputError("must be positive", column=f"{column}.{key}", value=value)
    return {str(n): dict(model) for n, model in calibration.items()}
