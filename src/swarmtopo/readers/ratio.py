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

``"mean"`` (format /3, the default)
    the mean score of each rank over the W windows, S_k = (1/W) sum_w s^w_(k), and
    beta_hat_n = #{k : S_k > ln tau_n}.  S is non-increasing (a mean of non-increasing
    sequences), so the counted ranks are the first ones.  The lower median of the
    windows' counts (below) throws away how far each window's bars are from the
    threshold and, with two windows, is their minimum; on the benchmark's tuning cases
    the mean scored higher (docs/accuracy.md).
``"median"`` (format /1 and /2 files)
    the lower median of the windows' own counts.

Either way the counted bars of a window drawn for the user are its beta_hat_n longest.

Agreement gate (format /4; mean pooling, dimension 1).  With ``agreement`` b set, a rank
k <= ``agreement.BARS`` whose pooled score passes (S_k > ln tau_1) is *vetoed* when its
cross-window cycle agreement A_k (:mod:`swarmtopo.readers.agreement`: is the k-th loop the same
loop in overlapping windows?) is at most b; a region without A_k (no two of its
windows overlap) vetoes nothing.  A vetoed rank is dropped from every window's score sequence
(:meth:`RatioClassifier.with_agreement`), so beta_hat_1 = #{k : S_k > ln tau_1 and not
vetoed}, and the windows' own counts, the representative window, the drawn bars and z
below are those of the sequences without it.

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
alone are applied so.  Files calibrated before z existed carry coefficients of the
windows' *agreement* with the vote, the vote's log *margin* (capped at MAX_MARGIN) and
the log number of *windows*; they are applied as they were fitted (:data:`REGION_FEATURES`).

A map of several regions (beta_0 >= 2) is right when every region is, and its
confidence is the product of its regions' raised to a power a, ``regions_exponent`` of
the calibration (:func:`map_confidence`; 1, the plain product, where a file has none).
The regional model is fitted on one-region maps, whose landmarks cover a whole arena; a
region of a two-room arena has fewer (ln L lower) and its confidence is lower than how
often it is right.  a is fitted by maximum likelihood on the benchmark's two-room tuning
maps (``lab/tune_accuracy.py``; docs/accuracy.md, "Confidence").

Earlier files (/1, /2) could also gate bars by death/birth ratio, length in covering
radii and a largest-gap rule; measured over three tuning rounds they never raised the
rate and the shipped classifiers had them off.  Such files are read when the gates are
off (as median pooling) and refused otherwise.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
from scipy.special import expit
from sklearn.linear_model import LogisticRegression

from .. import __version__
from .._validate import check_format, file_calibration
from .agreement import BARS, agreement_array
from ..errors import InputError, SwarmtopoError
from ..topology.persistence import Diagram

RATIO_FORMAT = "swarmtopo-ratio-classifier/4"
READ_FORMATS = ("swarmtopo-ratio-classifier/1", "swarmtopo-ratio-classifier/2", "swarmtopo-ratio-classifier/3",
                RATIO_FORMAT)
"""Readable formats: /1 and /2 files pool by the median of the windows' counts; only /4 files gate by agreement."""
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
"""The features :meth:`RatioClassifier.calibrate` fits."""
SPAN_FEATURES = ("log_span", "z_x_log_span")
"""ln T and z ln T, T the seconds a region's windows cover (:func:`windows_span`): candidate
features ``lab/calibration.py`` measures (not adopted, docs/accuracy.md); no
calibration file weighs them."""
OLD_FEATURES = ("agreement", "margin", "windows")
"""The features of files calibrated before z existed."""
REGION_FEATURES = (*CONFIDENCE_FEATURES, *OLD_FEATURES)
"""Every feature :meth:`RatioClassifier.region_features` gives: a calibration weighs z, the
resolution and their product, z alone, or (files calibrated before z) the other three."""
REGIONS_EXPONENT = "regions_exponent"
"""The calibration key of a, the power of the product of a several-region map's regional
confidences (:func:`map_confidence`)."""

LOG_RATIO_CAP = float(np.log(1e3))
"""Cap of a bar's score: a bar 1000 times the typical noise loop (or infinite) is as long as it gets."""


@dataclass(frozen=True)
class RatioThresholds:
    """(q_n, tau_n) of one dimension: a bar counts in its window when l > tau_n l_q; and the
    agreement gate b (None: no gate), which vetoes a passing rank with A_k <= b (module docstring)."""

    q: float
    tau: float
    agreement: float | None = None

    def to_json(self) -> dict[str, float]:
        return {"q": self.q, "tau": self.tau, **({} if self.agreement is None else {"agreement": self.agreement})}


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


def map_confidence(classifier, confidences: Sequence[float | None], n: int = 1) -> float | None:
    """P(a map's beta_n is right) from its regions' P(right) ``confidences``: the one
    region's, or for several the product raised to the calibration's ``regions_exponent``
    a (1 where a :class:`RatioClassifier` has none, and for classifiers of other kinds);
    None if a region has none."""
    if not len(confidences) or any(p is None for p in confidences):
        return None
    product = float(np.prod(confidences))
    if len(confidences) == 1 or not isinstance(classifier, RatioClassifier):
        return product
    model = classifier.calibration_.get(str(n)) or {}
    return product ** float(model.get(REGIONS_EXPONENT, 1.0))


def confidence_model() -> LogisticRegression:
    """The (unfitted) logistic model :meth:`RatioClassifier.calibrate` fits on :func:`confidence_design`."""
    return LogisticRegression(C=1.0)


def confidence_design(features: Sequence[dict[str, float]], names: Sequence[str] = CONFIDENCE_FEATURES) -> np.ndarray:
    """(regions, len(names)) matrix of the named features (:meth:`RatioClassifier.region_features`) of each region."""
    return np.array([[f[name] for name in names] for f in features], dtype=float).reshape(-1, len(names))


def score_matrix(diagrams: Sequence[Diagram], dim: int, q: float) -> np.ndarray:
    """(W, K) scores s^w_(k) of the W windows, a rank a window has no bar for scoring 0."""
    return _padded([window_scores(d, dim, q) for d in diagrams])


def _padded(ranked: Sequence[np.ndarray]) -> np.ndarray:
    """The windows' decreasing score sequences as rows of one matrix, missing ranks 0."""
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


def longest_bars(diagram: Diagram, dim: int, count: int, skip: Sequence[int] = ()) -> np.ndarray:
    """Indices into ``diagram[dim]`` of its ``count`` longest bars (infinite first; ties by position),
    the bars of the 0-based length ranks in ``skip`` (vetoed ranks) left out."""
    if dim > diagram.maxdim or count <= 0:
        return np.empty(0, np.int64)
    return np.delete(np.argsort(-diagram.lengths(dim), kind="stable"),
                     [k for k in skip if k < len(diagram[dim])])[:count]


def median_vote(counts: Sequence[int]) -> int:
    """The lower median of the windows' counts."""
    ordered = sorted(int(c) for c in counts)
    return ordered[(len(ordered) - 1) // 2]


def vote(classifier, windows: Sequence[Diagram], events: Sequence[int] | None = None
         ) -> tuple[dict[int, int], int, dict[int, list[int]]]:
    """A region's beta_hat from its windows' diagrams: (vote, representative window, counts per window).

    ``classifier`` is a :class:`RatioClassifier` (pooled as its ``pooling`` says) or the
    paper-form :class:`~swarmtopo.readers.paper.BettiClassifier` (the lower median of the
    windows' counts): its ``pooled_betti``.  The representative window is, among those
    whose own count equals the vote in the lowest dimension (or, if none does, is
    nearest it) and that hold at least half the ``events`` of the fullest of them (all
    of them without ``events``: a near-empty window of a bursty trace is no picture of
    the region), the one whose nearest bar is farthest from the threshold (the first on
    ties).
    """
    if not windows:
        raise SwarmtopoError("no window of this region has enough events to map")
    per_window = [classifier.betti(d) for d in windows]  # a classifier with_agreement: without its vetoed ranks
    counts = {n: [c[n] for c in per_window] for n in per_window[0]}
    betti = classifier.pooled_betti(windows)
    if not counts:
        return betti, 0, counts
    key = min(counts)
    off = [abs(c - betti[key]) for c in counts[key]]
    nearest = [i for i, x in enumerate(off) if x == min(off)]
    if events is not None:
        fullest = max(events[i] for i in nearest)
        nearest = [i for i in nearest if 2 * events[i] >= fullest]
    margins = [classifier.margin(windows[i], key) for i in nearest]
    return betti, nearest[int(np.argmax(margins))], counts


def region_reader(classifier, windows: Sequence[Diagram], agreement) -> Any:
    """How ``classifier`` reads one region: :meth:`RatioClassifier.with_agreement` if it gates
    by agreement, else itself.  ``agreement``: the region's A_k (array, or a JSON list with
    null for NaN), None if not computed."""
    if not (isinstance(classifier, RatioClassifier) and classifier.gated):
        return classifier
    return classifier.with_agreement(windows, None if agreement is None else agreement_array(agreement))


class RatioClassifier:
    """beta_hat_n from bar lengths over their window's noise scale, pooled over windows.

    Parameters
    ----------
    thresholds
        ``{n: RatioThresholds(q_n, tau_n)}`` for each homology dimension n >= 1.
    calibration
        Per dimension the logistic P(correct): ``{"intercept", "z", "resolution",
        "z_x_resolution"}``, ``{"intercept", "z"}`` or (older files) ``{"intercept",
        "agreement", "margin", "windows"}`` (:meth:`region_features`), any of them with
        ``"regions_exponent"`` (:func:`map_confidence`); None = uncalibrated.
        (beta_0's confidence is the pipeline's: :mod:`swarmtopo.readers.beta0`.)
    provenance
        Free-form record of how it was fitted (name, data, script).
    pooling
        ``"mean"`` (pooled scores) or ``"median"`` (lower median of the windows' counts).

    Attributes
    ----------
    vetoed_
        ``{n: 0-based ranks}`` dropped from every window's scores; empty except on the
        region view :meth:`with_agreement` returns.
    """

    def __init__(self, thresholds: dict[int, RatioThresholds], calibration: dict | None = None,
                 provenance: dict | None = None, pooling: str = "mean"):
        for n, th in thresholds.items():
            if not (int(n) >= 1 and 0.0 <= th.q <= 1.0 and 1.0 <= th.tau < np.exp(LOG_RATIO_CAP)):
                raise InputError(f"ratio thresholds of dimension {n} out of range (need 0 <= q <= 1, "
                                 "1 <= tau < 1000)",
                                 column=f"thresholds.{n}", value=th.to_json())
        if pooling not in POOLINGS:
            raise InputError(f"unknown pooling; expected one of {', '.join(POOLINGS)}", column="pooling",
                             value=pooling)
        for n, th in thresholds.items():
            if th.agreement is not None and (int(n) != 1 or pooling != "mean" or isinstance(th.agreement, bool) or
                                             not isinstance(th.agreement, (int, float)) or
                                             not 0.0 <= th.agreement < 1.0):
                raise InputError("an agreement gate needs dimension 1, mean pooling and 0 <= agreement < 1",
                                 column=f"thresholds.{n}.agreement", value=th.agreement)
        for n, model in (calibration or {}).items():
            unknown = (set(model) - {"intercept", "maps", REGIONS_EXPONENT, *REGION_FEATURES}
                       if isinstance(model, dict) else ())
            if unknown:
                raise InputError(f"unknown confidence feature(s) {sorted(unknown)}; known: "
                                 f"{', '.join(REGION_FEATURES)} (and {REGIONS_EXPONENT})", column=f"calibration.{n}",
                                 value=model)
            if isinstance(model, dict) and ("resolution" in model) != ("z_x_resolution" in model):
                raise InputError("a calibration weighs 'resolution' and 'z_x_resolution' together, or neither",
                                 column=f"calibration.{n}", value=model)
            if not isinstance(model, dict) or "intercept" not in model or not (
                    "z" in model or set(OLD_FEATURES) <= set(model)):
                raise InputError(f"a calibration needs 'intercept' and 'z' (older files: 'intercept', "
                                 f"{', '.join(map(repr, OLD_FEATURES))})", column=f"calibration.{n}", value=model)
            for key, value in model.items():
                if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value) or (
                        key == "maps" and value < 0):
                    raise InputError("must be a finite number", column=f"calibration.{n}.{key}", value=value)
                if key == REGIONS_EXPONENT and value <= 0:
                    raise InputError("must be positive", column=f"calibration.{n}.{key}", value=value)
        self.thresholds_ = {int(n): th for n, th in sorted(thresholds.items())}
        self.calibration_ = dict(calibration or {})
        self.provenance_ = dict(provenance or {})
        self.pooling = pooling
        self.vetoed_: dict[int, tuple[int, ...]] = {}

    # -- the agreement gate ----------------------------------------------------------------
    @property
    def gated(self) -> bool:
        """Whether some dimension's count is gated by cross-window cycle agreement."""
        return any(th.agreement is not None for th in self.thresholds_.values())

    def _candidates(self, windows: Sequence[Diagram]) -> np.ndarray:
        """0-based ranks k < agreement.BARS of dimension 1 that pass the score test (S_k > ln tau_1)."""
        th = self.thresholds_.get(1)
        if th is None or th.agreement is None or windows[0].maxdim < 1:
            return np.empty(0, np.int64)
        scores = pooled_scores(windows, 1, th.q)[:BARS]
        return np.flatnonzero(scores > np.log(th.tau))

    def needs_agreement(self, windows: Sequence[Diagram]) -> bool:
        """Whether the region's vote depends on its A_k: gated, and some rank k <= BARS passes."""
        return len(self._candidates(windows)) > 0

    def with_agreement(self, windows: Sequence[Diagram], agreement: np.ndarray | None) -> "RatioClassifier":
        """This classifier for one region: its passing ranks with A_k <= b vetoed (module docstring).

        ``agreement`` is the region's A_1 .. A_BARS (:func:`swarmtopo.readers.agreement.rank_agreement`;
        NaN: no two windows overlap, nothing vetoed); None only if :meth:`needs_agreement` is False.
        """
        candidates = self._candidates(windows)
        view = copy.copy(self)
        view.vetoed_ = {}
        if len(candidates):
            if agreement is None:
                raise SwarmtopoError("this region's vote needs its cross-window cycle agreement, which was not "
                                     "computed: map it with this classifier, or with agreement 'always'")
            b = self.thresholds_[1].agreement
            vetoed = tuple(int(k) for k in candidates if agreement[k] <= b)
            view.vetoed_ = {1: vetoed} if vetoed else {}
        return view

    def scores(self, diagram: Diagram, n: int) -> np.ndarray:
        """The window's decreasing dim-n scores (:func:`window_scores`) without the vetoed ranks."""
        scores = window_scores(diagram, n, self.thresholds_[n].q)
        return np.delete(scores, [k for k in self.vetoed_.get(n, ()) if k < len(scores)])

    def score_matrix(self, windows: Sequence[Diagram], n: int) -> np.ndarray:
        """(W, K) scores of the windows (:func:`score_matrix`) without the vetoed ranks."""
        return _padded([self.scores(d, n) for d in windows])

    def counted_bars(self, diagram: Diagram, n: int, count: int) -> np.ndarray:
        """Indices into ``diagram[n]`` of the bars counted in a window: its ``count`` longest not vetoed."""
        return longest_bars(diagram, n, count, self.vetoed_.get(n, ()))

    # -- one window --------------------------------------------------------------------
    def betti(self, diagram: Diagram) -> dict[int, int]:
        """The window's own beta_hat_n, for n up to the diagram's maxdim."""
        return {n: count_above(self.scores(diagram, n), th.tau)
                for n, th in self.thresholds_.items() if n <= diagram.maxdim}

    def length_thresholds(self, diagram: Diagram) -> dict[int, float]:
        """tau_n l_q: the length a bar of this window must exceed to count in it, seconds."""
        return {n: th.tau * noise_length(diagram, n, th.q)
                for n, th in self.thresholds_.items() if n <= diagram.maxdim}

    def margin(self, diagram: Diagram, n: int) -> float:
        """How far the window's own count in dimension n is from changing (:func:`score_margin`)."""
        return score_margin(self.scores(diagram, n), self.thresholds_[n].tau)

    # -- a region: several windows --------------------------------------------------------
    def pooled_betti(self, windows: Sequence[Diagram]) -> dict[int, int]:
        """The region's beta_hat_n: pooled scores (``"mean"``) or the lower median of the
        windows' counts (``"median"``)."""
        maxdim = windows[0].maxdim
        if self.pooling == "median":
            return {n: median_vote([self.betti(d)[n] for d in windows]) for n in self.thresholds_ if n <= maxdim}
        return {n: count_above(self.score_matrix(windows, n).mean(axis=0), th.tau)
                for n, th in self.thresholds_.items() if n <= maxdim}

    def region_features(self, windows: Sequence[Diagram], n: int, voted=None,
                        span: float | None = None) -> dict[str, float]:
        """One region's confidence features for dimension n: z, the resolution ln L and their
        product (module docstring), and the agreement, capped log margin and ln #windows that
        older calibrations use; given ``span`` (the seconds T its windows cover) also the
        measured candidates ln T and z ln T (SPAN_FEATURES).
        ``voted`` is :func:`vote`'s result for these windows when the caller has it."""
        betti, rep, counts = voted or vote(self, windows)
        th = self.thresholds_[n]
        matrix = self.score_matrix(windows, n)
        if self.pooling == "median":
            margin = self.margin(windows[rep], n)
        else:
            margin = score_margin(matrix.mean(axis=0), th.tau)
        z, ln_l = standardised_margin(matrix, betti[n], th.tau), resolution(windows)
        features = {"z": z, "resolution": ln_l, "z_x_resolution": z * ln_l,
                    "agreement": float(np.mean(np.asarray(counts[n]) == betti[n])),
                    "margin": margin, "windows": float(np.log(len(windows)))}
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
            if model is None:
                out[n] = None
                continue
            out[n] = calibrated_probability(model, self.region_features(windows, n, voted))
        return out

    # -- fitting -------------------------------------------------------------------------
    def calibrate(self, features: Sequence[dict[str, float]], correct,
                  names: Sequence[str] = CONFIDENCE_FEATURES) -> "RatioClassifier":
        """Fit P(correct | the ``names`` features) for dimension 1.

        ``features[k]`` are region k's (:meth:`region_features`, of this or of another
        classifier when the outcomes are cross-fitted) and ``correct[k]`` whether its
        vote was right.
        """
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

    # -- description and files ------------------------------------------------------------
    def describe(self) -> dict[str, Any]:
        """What map.json says about how its Betti numbers were read."""
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
            **({"agreement_gate": "a rank whose mean score passes is not counted when its cross-window cycle "
                "agreement A_k (the correlation of its loop's circular coordinates in overlapping windows, on the "
                "events they share) is at most theta.1.agreement"} if self.gated else {}),
            "confidence": self._confidence_definition(),
        }

    def _confidence_definition(self) -> str:
        model = self.calibration_.get("1")
        if model is None:
            return "uncalibrated"
        return self._region_confidence_definition(model) + (
            f"; a map of several regions: the product of its regions' to the power {model[REGIONS_EXPONENT]:.3g}, "
            "fitted on the benchmark's two-room tuning maps" if REGIONS_EXPONENT in model else
            "; a map of several regions: the product of its regions'")

    @staticmethod
    def _region_confidence_definition(model: dict[str, float]) -> str:
        if "resolution" in model:
            return ("P(correct) from a logistic model of z, how many standard errors (over the windows) the pooled "
                    "scores are from changing the vote, of the windows' resolution ln L (L landmarks, at most "
                    f"{RESOLUTION_CAP}) and of z ln L, fitted on the benchmark's tuning maps and its calibration grid")
        if "z" in model:
            return ("P(correct) from a logistic model of z, how many standard errors (over the windows) the pooled "
                    "scores are from changing the vote, fitted on the benchmark's tuning maps")
        return ("P(correct) from a logistic model of the windows' agreement with the vote, the vote's log margin and "
                "the number of windows, fitted on the benchmark's tuning maps")

    def to_json(self) -> dict[str, Any]:
        return {
            "format": RATIO_FORMAT,
            "pooling": self.pooling,
            "thresholds": {str(n): th.to_json() for n, th in self.thresholds_.items()},
            "calibration": self.calibration_ or None,
            "provenance": {**self.provenance_, "swarmtopo": self.provenance_.get("swarmtopo", __version__)},
        }

    def save(self, path) -> None:
        from ..io.logs import write_json

        write_json(self.to_json(), path)

    @classmethod
    def from_json(cls, obj: dict, source: str = "<json>") -> "RatioClassifier":
        check_format(obj, READ_FORMATS, "swarmtopo ratio classifier", source)
        try:
            thresholds = {}
            for n, t in obj["thresholds"].items():
                gates = {"rho": float(t.get("rho", 1.0)), "kappa": float(t.get("kappa", 0.0)),
                         "gamma": float(t.get("gamma", 0.0))}
                if gates != {"rho": 1.0, "kappa": 0.0, "gamma": 0.0}:
                    raise InputError("this ratio classifier uses the death/birth, covering-radius or gap tests "
                                     "of earlier swarmtopo versions, which are no longer applied; refit it "
                                     "(lab/tune_accuracy.py)", file=source, column=f"thresholds.{n}",
                                     value=gates)
                gate = t.get("agreement") if obj["format"] == RATIO_FORMAT else None  # checked by __init__
                thresholds[int(n)] = RatioThresholds(float(t["q"]), float(t["tau"]), gate)
            pooling = obj.get("pooling", "mean") if obj["format"] in READ_FORMATS[2:] else "median"
            calibration = file_calibration(obj.get("calibration"), source)
            return cls(thresholds, calibration or None, obj.get("provenance") or {}, pooling)
        except InputError as exc:
            if exc.file is not None:
                raise
            raise InputError(exc.reason, file=source, row=exc.row, column=exc.column, value=exc.value) from None
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise InputError(f"malformed ratio classifier: {exc!r}", file=source) from None
