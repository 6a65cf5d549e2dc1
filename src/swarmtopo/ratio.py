r"""Scale- and density-free Betti classifier, voted across time windows (swarmtopo's default).

The paper's classifier compares bar lengths l with l_q + Delta, l_q the q-quantile of
the diagram's lengths and Delta in seconds; in our benchmark thresholds in seconds did
not transfer between swarm densities, durations or arena sizes (docs/accuracy.md).
This classifier uses only ratios, which do not change when every distance is
multiplied by a constant:

* the **length over the noise scale** l / l_q (the paper's form with Delta = 0): l_q,
  a quantile of the window's own bar lengths, measures how long the noise loops of
  this sample are;
* the **death/birth ratio** pi = d / b: in a Vietoris-Rips filtration of a dense
  sample a noise loop is filled soon after it is born, while a loop round an obstacle
  lives until the scale of the obstacle;
* the **length in covering radii** l / r_cover: subsampling moves no bar by more than
  2 r_cover, so a bar much shorter than r_cover may be a subsampling artefact.

A bar of dimension n is a *candidate* when it passes all three (rho_n = 1 and kappa_n
= 0 switch the last two off)::

    C_n = { i : l_i > tau_n l_q  and  d_i / b_i > rho_n  and  l_i > kappa_n r_cover }

(an infinite bar always counts; b = 0 gives pi = inf; l_q is over the finite bars).
With gamma_n = 0 every candidate counts: beta_hat_n(window) = |C_n|.  With gamma_n >= 1
the **largest gap** decides: sort the finite bars by length, l_(1) >= l_(2) >= ...,
let g_k = ln(l_(k) / l_(k+1)) (g = 0 after the last bar: a bar with none below it
shows no gap), and among the ranks k of candidates take k* = argmax g_k; the
candidates among the k* longest bars count if g_k* >= ln gamma_n, none otherwise (the
noise bars' top end moves from sample to sample; a loop round an obstacle may stand
above it by a gap).  Tuning keeps the gap rule only where it is right more often; for
the shipped default it was not (docs/tuning.md), so its gamma_1 is 0.

A region's log is cut into time windows (``MapConfig.window_length``), each window is
mapped on its own, and the region's beta_hat_n is the **median** of the windows'
counts (the lower median for an even number of windows).

Confidence.  For each region the features are the *agreement* a (fraction of
windows whose count equals the vote) and the *margin* m of the window that represents
the region: how far, in log units, its count is from changing (without the gap rule:
its nearest bar's distance to a threshold -- a counted bar flips when any test fails,
an uncounted one needs every failing test to pass; with it: how much the largest gap
exceeds the next largest and ln gamma_n), capped at MAX_MARGIN.  P(correct | a, m,
number of windows) is a logistic regression fitted on the benchmark's tuning maps (:meth:`RatioClassifier.calibrate`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
from scipy.special import expit
from sklearn.linear_model import LogisticRegression

from . import __version__
from ._validate import check_format
from .errors import InputError, SwarmtopoError
from .persistence import Diagram

RATIO_FORMAT = "swarmtopo-ratio-classifier/2"
READ_FORMATS = ("swarmtopo-ratio-classifier/1", RATIO_FORMAT)
"""Readable formats: /1 files have no gamma (the gap rule off)."""
MAX_MARGIN = 3.0
"""Cap of the log margin of a window's nearest bar (a bar e^3 = 20 times off both
thresholds is as sure as it gets)."""


@dataclass(frozen=True)
class WindowBars:
    """What the classifier reads from one window of one region: its diagram and r_cover."""

    diagram: Diagram
    cover_radius: float


@dataclass(frozen=True)
class RatioThresholds:
    """(q_n, tau_n, rho_n, kappa_n, gamma_n) of one dimension (module docstring)."""

    q: float
    tau: float
    rho: float = 1.0
    kappa: float = 0.0
    gamma: float = 0.0

    def to_json(self) -> dict[str, float]:
        return {"q": self.q, "tau": self.tau, "rho": self.rho, "kappa": self.kappa, "gamma": self.gamma}


def _log_tests(diagram: Diagram, dim: int, cover_radius: float, th: RatioThresholds) -> np.ndarray:
    """(m, 3) log-ratios of each bar of ``diagram[dim]`` to its three thresholds (> 0:
    passes); a switched-off test and an infinite bar pass by MAX_MARGIN."""
    pairs = diagram[dim]
    birth, death = pairs[:, 0], pairs[:, 1]
    length = death - birth
    finite = np.isfinite(death)
    lq = float(np.quantile(length[finite], th.q)) if finite.any() else 0.0
    out = np.full((len(pairs), 3), MAX_MARGIN)
    with np.errstate(divide="ignore", invalid="ignore"):
        if lq > 0:
            out[finite, 0] = np.log(length[finite] / (th.tau * lq))
        if th.rho > 1.0:
            out[finite, 1] = np.log(death[finite] / (th.rho * birth[finite]))  # b = 0: +inf
        if th.kappa > 0.0 and cover_radius > 0:
            out[finite, 2] = np.log(length[finite] / (th.kappa * cover_radius))
    return out


def counted_bars(diagram: Diagram, dim: int, cover_radius: float, th: RatioThresholds) -> np.ndarray:
    """Indices into ``diagram[dim]`` of the bars that count (module docstring)."""
    if dim > diagram.maxdim or not len(diagram[dim]):
        return np.empty(0, np.int64)
    candidate = (_log_tests(diagram, dim, cover_radius, th) > 0).all(axis=1)
    if th.gamma <= 0:
        return np.flatnonzero(candidate)
    finite, order, gaps = ranked_gaps(diagram[dim])
    out = np.flatnonzero(candidate & ~finite)
    ranks = np.flatnonzero(candidate[order])
    if len(ranks):
        k = ranks[int(np.argmax(gaps[ranks]))]
        if gaps[k] >= np.log(th.gamma):
            out = np.union1d(out, order[:k + 1][candidate[order[:k + 1]]])
    return out


def ranked_gaps(pairs: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(finite mask, indices of the finite bars by decreasing length, g_k = ln(l_(k) /
    l_(k+1)) capped at MAX_MARGIN, 0 after the last)."""
    length = pairs[:, 1] - pairs[:, 0]
    finite = np.isfinite(length)
    index = np.flatnonzero(finite)
    order = index[np.argsort(-length[index], kind="stable")]
    ranked = length[order]
    with np.errstate(divide="ignore"):
        gaps = np.r_[np.log(ranked[:-1] / ranked[1:]), 0.0] if len(ranked) else np.empty(0)
    return finite, order, np.minimum(gaps, MAX_MARGIN)


def window_margin(diagram: Diagram, dim: int, cover_radius: float, th: RatioThresholds) -> float:
    """m: how far, in log units, the window's count is from changing (module docstring)."""
    if dim > diagram.maxdim or not len(diagram[dim]):
        return MAX_MARGIN
    tests = _log_tests(diagram, dim, cover_radius, th)
    counted = (tests > 0).all(axis=1)
    # a counted bar flips when its weakest test fails; an uncounted one needs every failing test to pass
    flip = np.where(counted, tests.min(axis=1), (-np.minimum(tests, 0)).max(axis=1))
    if th.gamma > 0:  # with the gap rule: how far the largest gap is from losing its place
        _, order, gaps = ranked_gaps(diagram[dim])
        ranks = np.flatnonzero(counted[order])
        if len(ranks):
            ranked = np.sort(gaps[ranks])[::-1]
            runner_up = ranked[1] if len(ranked) > 1 else -np.inf
            return float(min(MAX_MARGIN, ranked[0] - runner_up, ranked[0] - np.log(th.gamma)))
    return float(min(MAX_MARGIN, flip.min()))


def median_vote(counts: Sequence[int]) -> int:
    """The lower median of the windows' counts."""
    ordered = sorted(int(c) for c in counts)
    return ordered[(len(ordered) - 1) // 2]


def vote(classifier, windows: Sequence[WindowBars]) -> tuple[dict[int, int], int, dict[int, list[int]]]:
    """A region's beta_hat from its windows: (vote, representative window, counts per window).

    ``classifier`` is a :class:`RatioClassifier` or the paper-form
    :class:`~swarmtopo.classify.BettiClassifier` (both have ``betti(diagram,
    cover_radius)`` and ``margin(diagram, cover_radius, n)``).  The vote is the lower
    median of the windows' counts in each dimension; the representative window is,
    among those whose count equals the vote in the lowest dimension, the one whose
    nearest bar is farthest from the threshold (the first on ties).
    """
    if not windows:
        raise SwarmtopoError("no window of this region has enough events to map")
    per_window = [classifier.betti(w.diagram, w.cover_radius) for w in windows]
    counts = {n: [c[n] for c in per_window] for n in per_window[0]}
    betti = {n: median_vote(c) for n, c in counts.items()}
    if not counts:
        return betti, 0, counts
    key = min(counts)
    agreeing = [i for i, c in enumerate(counts[key]) if c == betti[key]]
    margins = [classifier.margin(windows[i].diagram, windows[i].cover_radius, key) for i in agreeing]
    return betti, agreeing[int(np.argmax(margins))], counts


class RatioClassifier:
    """beta_hat_n from death/birth ratios and covering radii, voted over windows.

    Parameters
    ----------
    thresholds
        ``{n: RatioThresholds(rho_n, kappa_n)}`` for each homology dimension n >= 1.
    calibration
        Per dimension ``{"intercept", "agreement", "margin", "windows"}`` of the
        logistic P(correct), and ``"0": {"rate": ...}`` for beta_0; None = uncalibrated.
    provenance
        Free-form record of how it was fitted (name, data, script).
    """

    def __init__(self, thresholds: dict[int, RatioThresholds], calibration: dict | None = None,
                 provenance: dict | None = None):
        for n, th in thresholds.items():
            if not (int(n) >= 1 and 0.0 <= th.q <= 1.0 and th.tau > 0 and th.rho >= 1.0 and th.kappa >= 0.0
                    and (th.gamma == 0.0 or th.gamma >= 1.0)):
                raise InputError(f"ratio thresholds of dimension {n} out of range "
                                 "(need 0 <= q <= 1, tau > 0, rho >= 1, kappa >= 0, gamma 0 or >= 1)",
                                 column=f"thresholds.{n}", value=th.to_json())
        self.thresholds_ = {int(n): th for n, th in sorted(thresholds.items())}
        self.calibration_ = dict(calibration or {})
        self.provenance_ = dict(provenance or {})

    # -- one window --------------------------------------------------------------------
    def betti(self, diagram: Diagram, cover_radius: float) -> dict[int, int]:
        """beta_hat_n of one window, for n up to the diagram's maxdim."""
        return {n: int(len(counted_bars(diagram, n, cover_radius, th)))
                for n, th in self.thresholds_.items() if n <= diagram.maxdim}

    def counted(self, diagram: Diagram, cover_radius: float) -> dict[int, np.ndarray]:
        """Indices of the counted bars of each dimension (what the loops are drawn round)."""
        return {n: counted_bars(diagram, n, cover_radius, th)
                for n, th in self.thresholds_.items() if n <= diagram.maxdim}

    def length_thresholds(self, diagram: Diagram, cover_radius: float) -> dict[int, float]:
        """max(tau_n l_q, kappa_n r_cover): the length a counted bar must exceed, seconds
        (it must also pass the death/birth test)."""
        out = {}
        for n, th in self.thresholds_.items():
            if n > diagram.maxdim:
                continue
            lengths = diagram.lengths(n)
            finite = lengths[np.isfinite(lengths)]
            lq = float(np.quantile(finite, th.q)) if len(finite) else 0.0
            out[n] = max(th.tau * lq, th.kappa * cover_radius)
        return out

    def margin(self, diagram: Diagram, cover_radius: float, n: int) -> float:
        """m of one window in dimension n (:func:`window_margin`)."""
        return window_margin(diagram, n, cover_radius, self.thresholds_[n])

    # -- a region: several windows --------------------------------------------------------
    def region_features(self, windows: Sequence[WindowBars], n: int, voted=None) -> np.ndarray:
        """(agreement a, margin m, number of windows) of one region for dimension n;
        ``voted`` is :func:`vote`'s result for these windows when the caller has it."""
        betti, rep, counts = voted or vote(self, windows)
        agreement = float(np.mean(np.asarray(counts[n]) == betti[n]))
        margin = window_margin(windows[rep].diagram, n, windows[rep].cover_radius, self.thresholds_[n])
        return np.array([agreement, margin, float(len(windows))])

    def region_confidence(self, windows: Sequence[WindowBars], voted=None) -> dict[int, float | None]:
        """P(the region's beta_hat_n is right) from the calibrated model; None if uncalibrated.
        ``voted``: :func:`vote`'s result for these windows, when the caller has it."""
        voted = voted or vote(self, windows)
        out: dict[int, float | None] = {}
        for n in self.thresholds_:
            if n > windows[0].diagram.maxdim:
                continue
            model = self.calibration_.get(str(n))
            if model is None:
                out[n] = None
                continue
            a, m, k = self.region_features(windows, n, voted)
            out[n] = float(expit(model["intercept"] + model["agreement"] * a + model["margin"] * m
                                 + model["windows"] * np.log(k)))
        return out

    def beta0_confidence(self) -> float | None:
        """Tuning-set rate of a correct beta_0 (Laplace-smoothed); None if uncalibrated."""
        model = self.calibration_.get("0")
        return None if model is None else float(model["rate"])

    # -- fitting -------------------------------------------------------------------------
    def calibrate(self, features: np.ndarray, correct, beta0_correct=None) -> "RatioClassifier":
        """Fit P(correct | a, m, ln #windows) for dimension 1.

        ``features[k]`` is (a, m, #windows) of region k (:meth:`region_features`, of
        this or of another classifier when the outcomes are cross-fitted) and
        ``correct[k]`` whether its vote was right; ``beta0_correct`` (one bool per map)
        gives the beta_0 rate.
        """
        X = np.array(features, dtype=float).reshape(-1, 3)
        X[:, 2] = np.log(X[:, 2])
        y = np.asarray(correct, dtype=bool)
        calibration: dict[str, Any] = {}
        if len(np.unique(y)) == 2:
            model = LogisticRegression(C=1.0).fit(X, y)
            calibration["1"] = {"intercept": float(model.intercept_[0]), "agreement": float(model.coef_[0, 0]),
                                "margin": float(model.coef_[0, 1]), "windows": float(model.coef_[0, 2]),
                                "maps": int(len(y))}
        else:  # all right (or all wrong): the smoothed rate, whatever the features
            rate = (y.sum() + 1) / (len(y) + 2)
            calibration["1"] = {"intercept": float(np.log(rate / (1 - rate))), "agreement": 0.0,
                                "margin": 0.0, "windows": 0.0, "maps": int(len(y))}
        if beta0_correct is not None:
            ok = np.asarray(beta0_correct, dtype=bool)
            calibration["0"] = {"rate": float((ok.sum() + 1) / (len(ok) + 2)), "maps": int(len(ok))}
        self.calibration_ = calibration
        return self

    # -- description and files ------------------------------------------------------------
    def describe(self) -> dict[str, Any]:
        """What map.json says about how its Betti numbers were read."""
        return {
            "classifier": self.provenance_.get("name", "custom"),
            "definition": "beta_n = lower median over time windows of the count of candidate bars of dim n "
                          "(length > tau * l_q, death/birth > rho, length > kappa * r_cover; l_q = q-quantile of "
                          "the window's dim-n bar lengths); with gamma >= 1 only the candidates down to the "
                          "largest log gap between consecutive bar lengths count, if that gap is >= ln gamma",
            "theta": {str(n): th.to_json() for n, th in self.thresholds_.items()},
            "confidence": "P(correct) from a logistic model of the windows' agreement with the vote, the "
                          "nearest bar's log margin and the number of windows, fitted on the benchmark's "
                          "tuning maps; beta_0: tuning-set rate",
        }

    def to_json(self) -> dict[str, Any]:
        return {
            "format": RATIO_FORMAT,
            "thresholds": {str(n): th.to_json() for n, th in self.thresholds_.items()},
            "calibration": self.calibration_ or None,
            "provenance": {**self.provenance_, "swarmtopo": self.provenance_.get("swarmtopo", __version__)},
        }

    def save(self, path) -> None:
        from .io import write_json

        write_json(self.to_json(), path)

    @classmethod
    def from_json(cls, obj: dict, source: str = "<json>") -> "RatioClassifier":
        check_format(obj, READ_FORMATS, "swarmtopo ratio classifier", source)
        try:
            thresholds = {int(n): RatioThresholds(float(t["q"]), float(t["tau"]), float(t["rho"]), float(t["kappa"]),
                                                  float(t.get("gamma", 0.0)))
                          for n, t in obj["thresholds"].items()}
            return cls(thresholds, obj.get("calibration") or None, obj.get("provenance") or {})
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise InputError(f"malformed ratio classifier: {exc!r}", file=source) from None
