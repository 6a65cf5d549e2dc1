"""Reading Betti numbers off persistence diagrams: the paper's scale-invariant classifier.

Paper, "Robust Classification of Persistence Intervals".  For the bar lengths
l^i_n of dgm_n, the n-th Betti function is::

    beta_hat_n(q_n, Delta_n, tau_n) = #{ i : l^i_n / (l_q + Delta_n) > tau_n }

with l_q the q_n-quantile of the lengths.  With Delta_n = 0 it is scale invariant
(multiplying every length by c changes nothing); Delta_n (in the metric's unit,
seconds) guards against l_q ~ 0.  Theta_n = (q_n, Delta_n, tau_n) is fitted on
(diagram, true beta_n) pairs of random environments by minimising the mean absolute
error F(Theta_n) = (1/m) sum_k |beta_hat^k_n - beta^k_n|, either

* ``optimizer="grid"``: exact in tau_n -- F is piecewise constant in tau_n, changing
  only at the ratios r^i_k = l^i_k / (l^k_q + Delta_n), so one sorted sweep over all
  ratios finds every optimal tau_n interval -- and a grid over (q_n, Delta_n); among
  ties the widest optimal tau_n interval wins and tau_n is its geometric middle
  (largest margin); or
* ``optimizer="sigmoid"``: the paper's smoothed objective, the indicator replaced
  by sigma_alpha(r - tau_n) = 1 / (1 + exp(-alpha (r - tau_n))), minimised by
  Nelder-Mead from several starts with alpha raised step by step (continuation).

Which optimizer wins is decided on held-out environments (see
``swarmtopo.experiments.training``), never on the training F.

Conventions: infinite bars (only with a Rips threshold) always count and are left out
of the quantile; a dimension with no bars gives beta_hat_n = 0.

Confidence.  Two features of one diagram's ratios r^i = l^i / (l_q + Delta_n), both
in log-ratio units and capped (:func:`confidence_features`): the margin
m = min_i |ln(r^i / tau_n)|, how far the nearest bar sits from the threshold, and the
gap g = ln(r_above / r_below) between the shortest counted bar and the longest
uncounted one, how cleanly the counted bars stand apart from the rest wherever tau
falls.  :meth:`BettiClassifier.calibrate` fits P(beta_hat_n correct | m, g) by
logistic regression on held-out maps; :meth:`BettiClassifier.confidence` returns it.
beta_0 is counted from graph components by the pipeline, not by this classifier; its
confidence is the pipeline's (:mod:`swarmtopo.readers.beta0`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
from scipy.optimize import minimize
from scipy.special import expit
from sklearn.base import BaseEstimator
from sklearn.linear_model import LogisticRegression

from .. import __version__
from .._validate import check_format
from ..errors import InputError, SwarmtopoError
from ..topology.persistence import Diagram
from .base import WindowReader, median_vote, product_confidence, vote

CLASSIFIER_FORMAT = "swarmtopo-classifier/1"
CALIBRATION_KEYS = ("intercept", "margin", "gap")
"""The coefficients of a dimension's confidence model (:meth:`BettiClassifier.confidence`)."""
MAX_MARGIN = 5.0
"""Cap of the log-ratio margin (a bar e^5 ~ 150 times off the threshold is as sure as it gets)."""
PAPER_THETA = {1: (0.5, 0.7, 3.7)}
"""The paper's published Theta*_1 = (q_1, Delta_1, tau_1), F = 0.03 on its training set
(:func:`published_paper_classifier`; the ``paper`` preset is this form trained on our random
environments the paper's way)."""

Q_GRID = tuple(np.round(np.arange(0.05, 0.951, 0.05), 2))
DELTA_GRID = (0.0,) + tuple(np.round(np.geomspace(0.01, 10.0, 16), 4))
SIGMOID_ALPHAS = (1.0, 3.0, 10.0, 30.0, 100.0)
SIGMOID_STARTS = 16
UNBOUNDED_WIDTH = 2.0
"""Log-width credited to an optimal tau interval with no upper (or lower) end; tau is
then placed UNBOUNDED_WIDTH / 2 e-folds beyond the extreme ratio."""


def bar_lengths(diagram: Diagram, dim: int) -> np.ndarray:
    """|l^i_n| of dgm_dim (decreasing; inf for infinite bars); empty if dim > maxdim."""
    return diagram.lengths(dim) if dim <= diagram.maxdim else np.empty(0)


def quantile_scale(lengths: np.ndarray, q: float, delta: float) -> float:
    """l_q + Delta: the q-quantile of the finite lengths plus Delta (Delta if none)."""
    finite = lengths[np.isfinite(lengths)]
    return (float(np.quantile(finite, q)) if len(finite) else 0.0) + delta


def betti_function(lengths: np.ndarray, q: float, delta: float, tau: float) -> int:
    """beta_hat_n(q, Delta, tau) = #{ i : l_i / (l_q + Delta) > tau }."""
    scale = quantile_scale(lengths, q, delta)
    if scale <= 0:  # every finite bar has length 0 and Delta = 0: only infinite bars count
        return int(np.count_nonzero(~np.isfinite(lengths)))
    return int(np.count_nonzero(lengths / scale > tau))


def confidence_features(lengths: np.ndarray, q: float, delta: float, tau: float) -> tuple[float, float]:
    """(m, g): the margin min_i |ln(r_i / tau)| and the gap ln(r_above / r_below) around
    tau (module docstring), over finite bars; a missing side counts as MAX_MARGIN away
    from tau, and both are capped (m at MAX_MARGIN, g at 2 MAX_MARGIN)."""
    scale = quantile_scale(lengths, q, delta)
    finite = lengths[np.isfinite(lengths) & (lengths > 0)]
    if scale <= 0 or not len(finite):
        return MAX_MARGIN, 2 * MAX_MARGIN
    log_r = np.log(finite / scale / tau)  # > 0: counted
    above = log_r[log_r > 0].min(initial=MAX_MARGIN)
    below = -log_r[log_r <= 0].max(initial=-MAX_MARGIN)
    return float(min(MAX_MARGIN, above, below)), float(min(2 * MAX_MARGIN, above + below))


@dataclass(frozen=True)
class Theta:
    """Theta_n = (q_n, Delta_n, tau_n) of one homology dimension."""

    q: float
    delta: float
    tau: float

    def to_json(self) -> dict[str, float]:
        return {"q": self.q, "delta": self.delta, "tau": self.tau}


class BettiClassifier(WindowReader, BaseEstimator):
    """The paper's Betti function beta_hat_n(q_n, Delta_n, tau_n), fitted by minimising F.

    scikit-learn conventions: ``__init__`` only stores, :meth:`fit` returns self,
    learned attributes end in ``_``.  ``X`` is a sequence of :class:`Diagram`; ``y``
    the true beta_n, shape (m,) for one dimension or (m, len(dims)).

    Parameters
    ----------
    dims
        Homology dimensions n >= 1 to classify.
    optimizer
        ``"grid"`` or ``"sigmoid"`` (module docstring).
    q_grid, delta_grid
        Search grid of the grid optimizer (q in (0, 1); Delta >= 0 seconds).
    alphas
        Sigmoid steepness schedule of the sigmoid optimizer.
    n_starts
        Starts of the sigmoid optimizer (the paper's Theta* and random points).
    random_state
        Seed of the sigmoid optimizer's random starts.

    Attributes
    ----------
    theta_ : dict[int, Theta]
    train_error_ : dict[int, float]
        F(Theta*_n) on the training set (hard indicator).
    calibration_ : dict
        Confidence model (:meth:`calibrate`); absent until calibrated.
    provenance_ : dict
        Where the parameters come from (script, data, seeds, version).
    """

    def __init__(self, dims: Sequence[int] = (1,), optimizer: str = "grid", q_grid=Q_GRID,
                 delta_grid=DELTA_GRID, alphas=SIGMOID_ALPHAS, n_starts: int = SIGMOID_STARTS,
                 random_state=0):
        self.dims = dims
        self.optimizer = optimizer
        self.q_grid = q_grid
        self.delta_grid = delta_grid
        self.alphas = alphas
        self.n_starts = n_starts
        self.random_state = random_state

    # -- fitting ---------------------------------------------------------------------
    def fit(self, X: Sequence[Diagram], y, provenance: dict | None = None) -> "BettiClassifier":
        """Theta*_n = argmin F(Theta_n) for each n in ``dims``."""
        if self.optimizer not in ("grid", "sigmoid"):
            raise SwarmtopoError(f"unknown optimizer {self.optimizer!r}; expected 'grid' or 'sigmoid'")
        dims = _check_dims(self.dims)
        truth = _truth_matrix(y, len(X), dims)
        self.theta_, self.train_error_ = {}, {}
        for j, n in enumerate(dims):
            lengths = [bar_lengths(d, n) for d in X]
            fit_one = _fit_grid if self.optimizer == "grid" else _fit_sigmoid
            theta = fit_one(lengths, truth[:, j], self)
            self.theta_[n] = theta
            self.train_error_[n] = mean_absolute_error(lengths, truth[:, j], theta)
        self.provenance_ = dict(provenance or {})
        self.provenance_.setdefault("swarmtopo", __version__)
        self.provenance_["optimizer"] = self.optimizer
        self.provenance_["training_maps"] = len(X)
        return self

    def calibrate(self, X: Sequence[Diagram], y) -> "BettiClassifier":
        """Fit the confidence model on held-out maps (module docstring)."""
        self._check_fitted()
        truth = _truth_matrix(y, len(X), list(self.theta_))
        calibration: dict[str, Any] = {"maps": len(X)}
        for j, (n, th) in enumerate(self.theta_.items()):
            lengths = [bar_lengths(d, n) for d in X]
            correct = np.array([betti_function(l, th.q, th.delta, th.tau) == t
                                for l, t in zip(lengths, truth[:, j])])
            features = np.array([confidence_features(l, th.q, th.delta, th.tau) for l in lengths])
            if correct.all() or not correct.any():  # logistic regression needs both outcomes
                rate = (correct.sum() + 1) / (len(correct) + 2)
                calibration[str(n)] = {"intercept": float(np.log(rate / (1 - rate))), "margin": 0.0, "gap": 0.0,
                                       "accuracy": float(correct.mean())}
            else:
                model = LogisticRegression(C=1.0).fit(features, correct)
                calibration[str(n)] = {"intercept": float(model.intercept_[0]), "margin": float(model.coef_[0, 0]),
                                       "gap": float(model.coef_[0, 1]), "accuracy": float(correct.mean())}
        self.calibration_ = calibration
        return self

    # -- using -----------------------------------------------------------------------
    def predict(self, X: Sequence[Diagram]) -> np.ndarray:
        """beta_hat_n of each diagram: shape (m,) for one dimension, else (m, len(dims))."""
        self._check_fitted()
        out = np.array([[betti_function(bar_lengths(d, n), th.q, th.delta, th.tau)
                         for n, th in self.theta_.items()] for d in X], dtype=np.int64)
        out = out.reshape(len(X), len(self.theta_))
        return out[:, 0] if len(self.theta_) == 1 else out

    def betti(self, diagram: Diagram) -> dict[int, int]:
        """beta_hat_n of one diagram, for n in dims up to the diagram's maxdim."""
        self._check_fitted()
        return {n: betti_function(bar_lengths(diagram, n), th.q, th.delta, th.tau)
                for n, th in self.theta_.items() if n <= diagram.maxdim}

    def thresholds(self, diagram: Diagram) -> dict[int, float]:
        """The bar length above which a bar counts: tau_n (l_q + Delta_n), seconds."""
        self._check_fitted()
        return {n: th.tau * quantile_scale(bar_lengths(diagram, n), th.q, th.delta)
                for n, th in self.theta_.items() if n <= diagram.maxdim}

    def margin(self, diagram: Diagram, n: int) -> float:
        """The log-ratio margin m of the bar nearest the threshold (:func:`confidence_features`)."""
        th = self.theta_[n]
        return confidence_features(bar_lengths(diagram, n), th.q, th.delta, th.tau)[0]

    def length_thresholds(self, diagram: Diagram) -> dict[int, float]:
        """Same as :meth:`thresholds` (the interface shared with the ratio classifier)."""
        return self.thresholds(diagram)

    def pooled_betti(self, windows: Sequence[Diagram]) -> dict[int, int]:
        """A region's beta_hat_n over its windows' diagrams: the lower median of their counts."""
        counts = [self.betti(d) for d in windows]
        return {n: median_vote([c[n] for c in counts]) for n in counts[0]}

    def region_confidence(self, windows: Sequence[Diagram], voted=None) -> dict[int, float | None]:
        """Confidence of a region mapped in windows: that of its representative window
        (``voted``: :func:`swarmtopo.readers.base.vote`'s result, when the caller has it)."""
        _, rep, _ = voted or vote(self, windows)
        return self.confidence(windows[rep])

    def map_confidence(self, confidences: Sequence[float | None], n: int = 1) -> float | None:
        """P(a map's beta_n is right): the product of its regions' P(right); None if one has none."""
        return product_confidence(confidences)

    def confidence(self, diagram: Diagram) -> dict[int, float | None]:
        """P(beta_hat_n is right) from the calibrated (margin, gap) model; None if uncalibrated."""
        self._check_fitted()
        calibration = getattr(self, "calibration_", {})
        out: dict[int, float | None] = {}
        for n, th in self.theta_.items():
            if n > diagram.maxdim:
                continue
            model = calibration.get(str(n))
            if model is None:
                out[n] = None
                continue
            m, g = confidence_features(bar_lengths(diagram, n), th.q, th.delta, th.tau)
            out[n] = float(expit(model["intercept"] + model["margin"] * m + model["gap"] * g))
        return out

    def score(self, X: Sequence[Diagram], y) -> float:
        """-F(Theta*) averaged over dims (higher is better, scikit-learn convention)."""
        self._check_fitted()
        truth = _truth_matrix(y, len(X), list(self.theta_))
        return -float(np.mean([mean_absolute_error([bar_lengths(d, n) for d in X], truth[:, j], th)
                               for j, (n, th) in enumerate(self.theta_.items())]))

    def describe(self) -> dict[str, Any]:
        """What map.json says about how its Betti numbers were read."""
        self._check_fitted()
        return {
            "classifier": self.provenance_.get("name", "custom"),
            "definition": "beta_n = #{bars of dim n with length / (l_q + Delta) > tau}, "
                          "l_q = q-quantile of the dim-n bar lengths",
            "threshold": "tau_n (l_q + Delta_n)",
            "theta": {str(n): th.to_json() for n, th in self.theta_.items()},
            "confidence": "P(correct) from a logistic model of the log-ratio margin of the nearest bar to "
                          "the threshold and the gap around it, fitted on held-out maps",
        }

    # -- persistence -----------------------------------------------------------------
    def to_json(self) -> dict[str, Any]:
        self._check_fitted()
        return {
            "format": CLASSIFIER_FORMAT,
            "params": {"dims": list(self.dims), "optimizer": self.optimizer},
            "theta": {str(n): th.to_json() for n, th in self.theta_.items()},
            "train_error": {str(n): float(v) for n, v in self.train_error_.items()},
            "calibration": getattr(self, "calibration_", None),
            "provenance": self.provenance_,
        }

    @classmethod
    def from_json(cls, obj: dict, source: str = "<json>") -> "BettiClassifier":
        check_format(obj, CLASSIFIER_FORMAT, "swarmtopo classifier", source)
        try:
            params = obj["params"]
            model = cls(dims=tuple(int(n) for n in params["dims"]), optimizer=params["optimizer"])
            model.theta_ = {int(n): Theta(float(t["q"]), float(t["delta"]), float(t["tau"]))
                            for n, t in obj["theta"].items()}
            model.train_error_ = {int(n): float(v) for n, v in obj.get("train_error", {}).items()}
            model.provenance_ = dict(obj.get("provenance") or {})
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed classifier: {exc!r}", file=source) from None
        for n, th in model.theta_.items():
            if not (0 <= th.q <= 1 and th.delta >= 0 and th.tau > 0):
                raise InputError(f"Theta_{n} out of range (need 0 <= q <= 1, Delta >= 0, tau > 0)",
                                 file=source, column=f"theta.{n}", value=th.to_json())
        if obj.get("calibration"):
            model.calibration_ = _checked_calibration(obj["calibration"], model.theta_, source)
        return model

    @classmethod
    def from_theta(cls, theta: dict[int, tuple[float, float, float]], provenance: dict) -> "BettiClassifier":
        """A classifier with given Theta_n (e.g. the paper's), not fitted by us."""
        model = cls(dims=tuple(sorted(theta)))
        model.theta_ = {n: Theta(*map(float, t)) for n, t in sorted(theta.items())}
        model.train_error_ = {}
        model.provenance_ = dict(provenance)
        return model

    def _check_fitted(self):
        if not hasattr(self, "theta_"):
            raise SwarmtopoError("this BettiClassifier is not fitted yet: call fit() or load one")


# -- evaluation ------------------------------------------------------------------------
def mean_absolute_error(lengths: Sequence[np.ndarray], truth, theta: Theta) -> float:
    """F(Theta_n) = (1/m) sum_k |beta_hat^k_n - beta^k_n|."""
    truth = np.asarray(truth)
    estimates = np.array([betti_function(l, theta.q, theta.delta, theta.tau) for l in lengths])
    return float(np.mean(np.abs(estimates - truth)))


@dataclass(frozen=True)
class DetectionScores:
    """Hole-level scores of Betti estimates against the truth.

    Per map, min(beta_hat, beta) true holes are found (TP), beta - TP missed (FN) and
    beta_hat - TP are false holes (FP).  sensitivity SE = TP / (TP + FN) (paper);
    false_hole_rate = FP / (TP + FP), the share of reported holes that are not there
    (SE alone would reward over-counting); F = mean |beta_hat - beta|; exact = share
    of maps with beta_hat = beta.
    """

    maps: int
    true_positives: int
    false_negatives: int
    false_positives: int
    sensitivity: float
    false_hole_rate: float
    mean_absolute_error: float
    exact: float


def detection_scores(estimated, truth) -> DetectionScores:
    """:class:`DetectionScores` of estimated vs true beta_n (one entry per map)."""
    est = np.asarray(estimated, dtype=np.int64)
    true = np.asarray(truth, dtype=np.int64)
    if est.shape != true.shape or est.ndim != 1:
        raise SwarmtopoError(f"estimated and true Betti numbers must be 1-D of equal length, "
                             f"got {est.shape} and {true.shape}")
    tp = int(np.minimum(est, true).sum())
    fn = int(true.sum()) - tp
    fp = int(est.sum()) - tp
    return DetectionScores(
        maps=len(est), true_positives=tp, false_negatives=fn, false_positives=fp,
        sensitivity=tp / (tp + fn) if tp + fn else float("nan"),
        false_hole_rate=fp / (tp + fp) if tp + fp else 0.0,
        mean_absolute_error=float(np.mean(np.abs(est - true))) if len(est) else float("nan"),
        exact=float(np.mean(est == true)) if len(est) else float("nan"),
    )


# -- files and the published Theta* ---------------------------------------------------
def _checked_calibration(calibration, theta: dict[int, Theta], source: str) -> dict:
    """A file's calibration: "maps", a count, and for each dimension of ``theta`` a model
    of the finite numbers it is applied with (CALIBRATION_KEYS)."""
    if not isinstance(calibration, dict):
        raise InputError("must be an object of {dimension: model}", file=source, column="calibration",
                         value=calibration)
    dims = {str(n) for n in theta}
    for n, model in calibration.items():
        if n == "maps":
            ok = isinstance(model, int) and not isinstance(model, bool) and model >= 0
        else:
            ok = n in dims and isinstance(model, dict) and all(
                isinstance(model.get(key), (int, float)) and not isinstance(model.get(key), bool)
                and np.isfinite(model[key]) for key in CALIBRATION_KEYS)
        if not ok:
            raise InputError("a calibration maps 'maps' to a count and each dimension of theta to finite numbers "
                             f"{', '.join(map(repr, CALIBRATION_KEYS))}", file=source, column=f"calibration.{n}",
                             value=model)
    return dict(calibration)


def published_paper_classifier() -> BettiClassifier:
    """The paper's published Theta*_1 = (0.5, 0.7, 3.7) (PAPER_THETA), uncalibrated."""
    return BettiClassifier.from_theta(PAPER_THETA, {
        "name": "paper-theta", "source": "paper, section 'Robust Classification of Persistence Intervals': "
                                         "Theta*_1 = (0.5, 0.7, 3.7), F = 0.03 on 100 two-hole environments"})


# -- optimizers ------------------------------------------------------------------------
def _fit_grid(lengths: list[np.ndarray], truth: np.ndarray, model: BettiClassifier) -> Theta:
    """Exact in tau, grid over (q, Delta); ties -> widest optimal tau interval."""
    best = (np.inf, -np.inf, None)  # (F, -log width, Theta): minimise F, maximise width
    for q in model.q_grid:
        for delta in model.delta_grid:
            error, log_width, tau = _best_tau(lengths, truth, float(q), float(delta))
            if (error, -log_width) < best[:2]:
                best = (error, -log_width, Theta(float(q), float(delta), tau))
    return best[2]


def _best_tau(lengths, truth, q, delta) -> tuple[float, float, float]:
    """(F*, log width, tau*) for fixed (q, Delta): sweep tau down through the sorted ratios.

    At tau above every ratio, beta_hat^k = (infinite bars of k).  Each ratio crossed
    raises one map's beta_hat by 1, changing its error by +1 (already >= beta) or -1.
    """
    m = len(lengths)
    ratios, owner, n_inf = [], [], np.zeros(m, dtype=np.int64)
    for k, l in enumerate(lengths):
        scale = quantile_scale(l, q, delta)
        finite = l[np.isfinite(l)]
        n_inf[k] = len(l) - len(finite)
        if scale > 0 and len(finite):
            r = finite / scale
            r = r[r > 0]
            ratios.append(r)
            owner.append(np.full(len(r), k))
    base_error = np.abs(n_inf - truth).sum()
    if not ratios:
        return base_error / m, 0.0, 1.0
    ratios = np.concatenate(ratios)
    owner = np.concatenate(owner)
    order = np.argsort(-ratios, kind="stable")
    ratios, owner = ratios[order], owner[order]
    # rank of each crossing within its own map (0 for its largest ratio, ...)
    by_owner = np.argsort(owner, kind="stable")
    starts = np.searchsorted(owner[by_owner], np.arange(m))
    rank = np.empty(len(owner), dtype=np.int64)
    rank[by_owner] = np.arange(len(owner)) - starts[owner[by_owner]]
    count_before = n_inf[owner] + rank
    step = np.where(count_before >= truth[owner], 1, -1)
    errors = base_error + np.cumsum(step)  # F * m just below ratios[j]
    # interval j of tau: [lower[j], upper[j]) with error err[j]; tied ratios give empty ones
    upper = np.concatenate([[np.inf], ratios])
    lower = np.concatenate([ratios, [0.0]])
    err = np.concatenate([[base_error], errors])
    candidates = np.flatnonzero(upper > lower)
    bounded = np.isfinite(upper[candidates]) & (lower[candidates] > 0)
    with np.errstate(divide="ignore"):
        width = np.where(bounded, np.log(upper[candidates] / lower[candidates]), UNBOUNDED_WIDTH)
    best_err = err[candidates].min()
    tied = np.flatnonzero(err[candidates] == best_err)
    pick = tied[np.argmax(width[tied])]
    j = candidates[pick]
    if not np.isfinite(upper[j]):
        tau = lower[j] * np.exp(UNBOUNDED_WIDTH / 2)
    elif lower[j] <= 0:
        tau = upper[j] * np.exp(-UNBOUNDED_WIDTH / 2)
    else:
        tau = float(np.sqrt(lower[j] * upper[j]))
    return best_err / m, float(width[pick]), float(tau)


def _fit_sigmoid(lengths: list[np.ndarray], truth: np.ndarray, model: BettiClassifier) -> Theta:
    """Minimise the sigmoid-smoothed F by Nelder-Mead with a rising alpha, from several
    starts (the paper's Theta* and random points); tau is then set exactly for the
    (q, Delta) found (the smoothed optimum sits near, not on, a hard one)."""
    rng = np.random.default_rng(model.random_state)
    padded, counts, n_inf = _padded_finite(lengths)
    starts = [np.array([0.5, 0.7, 3.7])] + [
        np.array([rng.uniform(0.05, 0.95), rng.uniform(0.0, 3.0), rng.uniform(1.0, 20.0)])
        for _ in range(max(0, model.n_starts - 1))]
    bounds = [(0.01, 0.99), (0.0, 10.0), (0.05, 200.0)]

    def smooth_error(x, alpha):
        q, delta, tau = x
        scale = _padded_quantile(padded, counts, q) + delta
        with np.errstate(divide="ignore", invalid="ignore"):
            soft = np.where(np.isfinite(padded) & (scale[:, None] > 0),
                            expit(alpha * (padded / scale[:, None] - tau)), 0.0)
        return float(np.mean(np.abs(soft.sum(axis=1) + n_inf - truth)))

    best = None
    for x in starts:
        for alpha in model.alphas:
            x = minimize(smooth_error, x, args=(alpha,), method="Nelder-Mead", bounds=bounds,
                         options={"xatol": 1e-4, "fatol": 1e-6, "maxiter": 1000}).x
        q, delta = float(x[0]), float(x[1])
        error, _, tau = _best_tau(lengths, truth, q, delta)
        if best is None or error < best[0]:
            best = (error, Theta(q, delta, tau))
    return best[1]


def _padded_finite(lengths: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Finite lengths of each map, sorted increasing, in an (m, max) array padded with
    NaN; their counts; the number of infinite bars of each map."""
    finite = [np.sort(l[np.isfinite(l)]) for l in lengths]
    counts = np.array([len(f) for f in finite])
    padded = np.full((len(finite), max(1, counts.max(initial=0))), np.nan)
    for k, f in enumerate(finite):
        padded[k, : len(f)] = f
    return padded, counts, np.array([len(l) for l in lengths]) - counts


def _padded_quantile(padded: np.ndarray, counts: np.ndarray, q: float) -> np.ndarray:
    """np.quantile(..., q) (linear interpolation) of every row's first counts[k] values; 0 if none."""
    pos = q * np.maximum(counts - 1, 0)
    lo = np.floor(pos).astype(np.int64)
    hi = np.minimum(lo + 1, np.maximum(counts - 1, 0))
    rows = np.arange(len(counts))
    value = padded[rows, lo] + (pos - lo) * (padded[rows, hi] - padded[rows, lo])
    return np.where(counts > 0, value, 0.0)


def _check_dims(dims) -> list[int]:
    dims = [int(n) for n in dims]
    if not dims or any(n < 1 for n in dims) or len(set(dims)) != len(dims):
        raise SwarmtopoError(f"dims must be distinct homology dimensions >= 1, got {dims}")
    return dims


def _truth_matrix(y, m: int, dims: list[int]) -> np.ndarray:
    truth = np.asarray(y, dtype=np.int64)
    if truth.ndim == 1:
        truth = truth[:, None]
    if truth.shape != (m, len(dims)):
        raise SwarmtopoError(f"y must have shape ({m},) or ({m}, {len(dims)}), got {np.shape(y)}")
    if (truth < 0).any():
        raise SwarmtopoError("true Betti numbers must be >= 0")
    return truth
