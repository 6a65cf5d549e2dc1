"""Choosing the default pipeline and ratio classifier on the benchmark's tuning cases.

``lab/tune_accuracy.py`` runs the tuning jobs of candidate pipelines
(:func:`~.accuracy.tuning_jobs`, inside :func:`~.accuracy.tuning_session`), then for
each candidate fits the :class:`~swarmtopo.readers.ratio.RatioClassifier` thresholds
(q_1, tau_1) by grid search on the stored per-window diagrams -- the thresholds change
only which bars count, so no job is rerun -- for each way of pooling the windows, with
a cross-validated count beside the fitted one (:func:`cross_validated`).  The
confidence model of the chosen candidate is then fitted on the same tuning maps,
cross-fitted (:func:`calibrated_classifier`, :func:`cross_fitted_features`), and on
the calibration grid's maps read the same way (:func:`features_under`), and last the
power of a several-region map's product of regional confidences on the tuning maps of
several rooms (:func:`several_region_products`, :func:`fit_regions_exponent`).

``lab/fit_agreement_gate.py`` fits the ``gated`` preset from the default's q_1: the
agreement gate (:func:`fit_gate`: the score threshold a = ln tau_1 and the agreement
threshold b, on tuning maps whose rows hold every region's A_k) and its confidence the
same way; with ``--veto`` it measures an agreement veto for the default (:func:`fit_veto`:
b alone, the default's (q_1, tau_1) kept: the strongest before the first b that breaks a
tuning map; not adopted, docs/accuracy.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
from scipy.ndimage import uniform_filter, uniform_filter1d
from scipy.optimize import minimize_scalar
from sklearn.metrics import brier_score_loss, log_loss

from ..swarmtopo.topology.persistence import Diagram
from ..swarmtopo.readers.agreement import BARS, agreement_array
from ..swarmtopo.pipeline.map.map import MapConfig, resolve_landmark_bands
from ..swarmtopo.readers.ratio import (CONFIDENCE_FEATURES, REGIONS_EXPONENT, RatioClassifier, RatioThresholds, pooled_scores,
                     region_reader, vote, window_scores, windows_span)
from ..swarmtopo.experiments.sweep import cached_classifier, job_classifier, job_map_config

Q_GRID = (0.5, 0.6, 0.7, 0.8, 0.9)
TAU_GRID = tuple(np.round(np.geomspace(1.2, 12.0, 80), 4))
"""The (q_1, tau_1) grid."""
A_GRID = tuple(np.round(np.arange(1.60, 2.2001, 0.02), 2))
B_GRID = tuple(np.round(np.arange(0.0, 0.9601, 0.02), 2))
"""The agreement gate's grid: score threshold a = ln tau_1 and agreement threshold b."""
REGIONS_EXPONENT_RANGE = (0.05, 20.0)
"""Where :func:`fit_regions_exponent` searches the power a of a several-region map's product."""
PIPELINE_FIELDS = ("metric", "hop_cost", "diffusion_time", "wall_follow_weight", "window_length",
                   "window_encounters", "window_scales", "window_step", "landmark_bands")
"""The MapConfig fields the candidate pipelines of ``lab/tune_accuracy.py`` set: the
chosen candidate's must be MapConfig's defaults."""


def job_pipeline(mapping: dict) -> dict:
    """The ``PIPELINE_FIELDS`` a stored job was mapped with (its ``[map]`` table; unset
    landmark bands resolved by the preset classifier that ran it, as ``run_job`` does)."""
    return pipeline_fields(job_map_config(mapping), cached_classifier(job_classifier(mapping)))


def pipeline_fields(config: MapConfig, classifier) -> dict:
    """``PIPELINE_FIELDS`` of ``config`` as mapped with ``classifier`` (unset bands resolved)."""
    return {k: resolve_landmark_bands(config, classifier) if k == "landmark_bands" else getattr(config, k)
            for k in PIPELINE_FIELDS}


@dataclass(frozen=True)
class TuningMap:
    """One tuning map: its regions' windows, its estimated beta_0 and the truth."""

    regions: tuple[tuple[Diagram, ...], ...]  # each region's windows' diagrams
    est_betti0: int
    true_betti0: int
    true_betti1: int
    cell: str
    agreement: tuple[np.ndarray | None, ...] = ()  # each region's A_1 .. A_BARS, None where not computed
    spans: tuple[float, ...] = ()  # each region's windows' span T in seconds (ratio.windows_span); () unknown


def maps_from_rows(rows: Sequence[dict[str, Any]], cell_of) -> list[TuningMap]:
    """TuningMaps of the finished rows of a store (failed jobs are skipped: they have no map).

    ``cell_of(config) -> str`` names each row's cell.
    """
    maps = []
    for row in rows:
        if row["error"] is not None:
            continue
        regions = tuple(
            tuple(Diagram.from_json(w["diagram"]) for w in region["windows"])
            for region in row["diagrams"])
        agreement = tuple(None if region.get("agreement") is None else agreement_array(region["agreement"])
                          for region in row["diagrams"])
        maps.append(TuningMap(regions, int(row["est_betti0"]), int(row["true_betti0"]), int(row["true_betti1"]),
                              cell_of(row["config"]), agreement,
                              tuple(windows_span(region["windows"]) for region in row["diagrams"])))
    return maps


def exact(maps: Sequence[TuningMap], th: RatioThresholds, pooling: str = "mean") -> np.ndarray:
    """Whether each map's (beta_0, beta_1) is exactly right under thresholds ``th`` (gated
    by agreement if ``th.agreement`` is set), its regions' windows pooled by ``pooling``
    (the literal classifier)."""
    model = RatioClassifier({1: th}, pooling=pooling)
    return np.array([m.est_betti0 == m.true_betti0 and
                     sum(_reader(model, m, r).pooled_betti(region)[1] for r, region in enumerate(m.regions))
                     == m.true_betti1 for m in maps])


def _reader(model: RatioClassifier, m: TuningMap, r: int) -> RatioClassifier:
    """``model`` as it reads region r of map m (:func:`~swarmtopo.readers.ratio.region_reader`)."""
    return region_reader(model, m.regions[r], m.agreement[r] if len(m.agreement) > r else None)


@dataclass(frozen=True)
class Fit:
    """The thresholds chosen, their tuning exact rate, the exact-rate surface and the pooling."""

    thresholds: RatioThresholds
    accuracy: float
    surface: np.ndarray  # (len(Q_GRID), len(TAU_GRID)) exact rate
    pooling: str


def _counts_over_tau(scores: np.ndarray) -> np.ndarray:
    """#{k : scores_k > ln tau} for every tau of TAU_GRID."""
    ascending = np.sort(scores)
    return len(scores) - np.searchsorted(ascending, np.log(TAU_GRID), side="right")


def grid_estimates(maps: Sequence[TuningMap], pooling: str = "mean") -> np.ndarray:
    """beta_hat_1 of every map at every grid point, ``(len(maps), len(Q_GRID), len(TAU_GRID))``:
    :meth:`~swarmtopo.readers.ratio.RatioClassifier.pooled_betti` at once for all tau."""
    est = np.zeros((len(maps), len(Q_GRID), len(TAU_GRID)), np.int64)
    for k, m in enumerate(maps):
        for region in m.regions:
            for i, q in enumerate(Q_GRID):
                if pooling == "mean":
                    est[k, i] += _counts_over_tau(pooled_scores(region, 1, q))
                else:
                    counts = np.sort([_counts_over_tau(window_scores(d, 1, q)) for d in region], axis=0)
                    est[k, i] += counts[(len(region) - 1) // 2]
    return est


def fit_thresholds(maps: Sequence[TuningMap], pooling: str = "mean") -> Fit:
    """(q_1, tau_1) at the grid point whose mean exact rate over itself and its two tau
    neighbours (edges repeated) is highest (ties: the first), so the choice sits inside
    a plateau rather than on a lucky spike.  Neighbours in q are not averaged: l_q grows
    with q, so the same tau means a different length threshold in the next q row."""
    truth = np.array([m.true_betti1 for m in maps])
    beta0 = np.array([m.est_betti0 == m.true_betti0 for m in maps])
    right = (grid_estimates(maps, pooling) == truth[:, None, None]) & beta0[:, None, None]
    surface = right.mean(axis=0)
    smooth = uniform_filter1d(surface, size=3, axis=1, mode="nearest")
    i, j = np.unravel_index(int(np.argmax(smooth + 1e-9 * surface)), surface.shape)
    return Fit(thresholds=RatioThresholds(float(Q_GRID[i]), float(TAU_GRID[j])), accuracy=float(surface[i, j]),
               surface=surface, pooling=pooling)


def cross_validated_exact(maps: Sequence[TuningMap], pooling: str = "mean", folds: int = 4,
                          refit=None) -> np.ndarray:
    """Whether each map is exactly right when its fold (maps split by position) is read
    with the thresholds fitted on the other folds (``refit(maps) -> RatioThresholds``,
    default :func:`fit_thresholds` with ``pooling``)."""
    refit = refit or (lambda subset: fit_thresholds(subset, pooling).thresholds)
    fold = np.arange(len(maps)) % folds
    right = np.zeros(len(maps), bool)
    for k in range(folds):
        held = np.flatnonzero(fold == k)
        right[held] = exact([maps[i] for i in held], refit([m for m, f in zip(maps, fold) if f != k]), pooling)
    return right


def cross_validated(maps: Sequence[TuningMap], pooling: str = "mean", folds: int = 4) -> int:
    """Exact maps, each fold read with the thresholds fitted on the other folds
    (:func:`cross_validated_exact`): the fitted count without its in-sample optimism."""
    return int(cross_validated_exact(maps, pooling, folds).sum())


def gate_estimates(maps: Sequence[TuningMap], q: float, a_values: Sequence[float] = A_GRID) -> np.ndarray:
    """beta_hat_1 of every map at every (a, b) of the gate's grid, ``(len(maps), len(a_values), len(B_GRID))``:
    #{k : S_k > a} minus the ranks k <= BARS among them with A_k <= b (NaN A_k vetoes nothing)."""
    a = np.array(a_values)[:, None, None]
    b = np.array(B_GRID)[None, :, None]
    est = np.zeros((len(maps), len(a_values), len(B_GRID)), np.int64)
    for k, m in enumerate(maps):
        for r, region in enumerate(m.regions):
            scores = pooled_scores(region, 1, q)
            est[k] += (scores[None, :] > a[:, :, 0]).sum(axis=1)[:, None]
            agreement = m.agreement[r] if len(m.agreement) > r else None
            if agreement is None:
                if (scores[:BARS] > min(a_values)).any():
                    raise ValueError("a tuning map without A_k: fit the gate on maps mapped with agreement='always'")
                continue
            top = np.r_[scores[:BARS], np.zeros(BARS)][:BARS][None, None, :]
            est[k] -= ((top > a) & (agreement[None, None, :] <= b)).sum(axis=2)
    return est


def gate_right(maps: Sequence[TuningMap], q: float, a_values: Sequence[float] = A_GRID) -> np.ndarray:
    """Whether each map is exactly right at every (a, b) of :func:`gate_estimates`' grid."""
    truth = np.array([m.true_betti1 for m in maps])
    beta0 = np.array([m.est_betti0 == m.true_betti0 for m in maps])
    return (gate_estimates(maps, q, a_values) == truth[:, None, None]) & beta0[:, None, None]


def veto_right(maps: Sequence[TuningMap], score_only: RatioThresholds) -> np.ndarray:
    """``(len(maps), len(B_GRID))``: whether each map is exactly right with ``score_only``'s
    (q_1, tau_1) and a veto at every b of the grid."""
    return gate_right(maps, score_only.q, (float(np.log(score_only.tau)),))[:, 0, :]


def fit_gate(maps: Sequence[TuningMap], q: float) -> RatioThresholds:
    """The gate (tau_1 = e^a, b) at the grid point whose mean exact rate over itself and
    its neighbours in a and b (3 x 3, edges repeated) is highest (ties: the first)."""
    surface = gate_right(maps, q).mean(axis=0)
    smooth = uniform_filter(surface, size=3, mode="nearest")
    i, j = np.unravel_index(int(np.argmax(smooth + 1e-9 * surface)), surface.shape)
    return RatioThresholds(q, float(np.exp(A_GRID[i])), float(B_GRID[j]))


def fit_veto(maps: Sequence[TuningMap], score_only: RatioThresholds) -> RatioThresholds:
    """The agreement veto alone: ``score_only``'s (q_1, tau_1) kept, b the last of B_GRID
    before the first at which some map that was right (at the b before, or by the score
    alone) turns wrong.

    The strongest veto the tuning maps do not pay for: raising b only drops ranks, so each
    step can only fix maps that count too many or break maps whose holes agree little;
    the gain lies beyond the suite (noise loops that are not the same loop from window to
    window, docs/accuracy.md), where no b is chosen.
    """
    right = veto_right(maps, score_only)
    before = exact(maps, score_only)
    chosen = None
    for j, b in enumerate(B_GRID):
        if np.any(before & ~right[:, j]):
            break
        chosen, before = float(b), right[:, j]
    if chosen is None:
        raise ValueError("even the weakest veto of the grid breaks a tuning map")
    return RatioThresholds(score_only.q, score_only.tau, chosen)


def one_region(maps: Sequence[TuningMap]) -> list[TuningMap]:
    """The maps whose beta_0 is 1 and right: a region's beta_1 outcome is known only when
    the map has one region (the truth is per map)."""
    return [m for m in maps if m.true_betti0 == 1 and m.est_betti0 == 1]


def features_under(maps: Sequence[TuningMap], th: RatioThresholds,
                   pooling: str = "mean") -> tuple[list[dict[str, float]], list[bool]]:
    """Confidence features (:meth:`~swarmtopo.readers.ratio.RatioClassifier.region_features`, with
    the span's where the map knows it) and outcomes of the one-region ``maps`` read with
    thresholds ``th``."""
    single = one_region(maps)
    model = RatioClassifier({1: th}, pooling=pooling)
    return ([_reader(model, m, 0).region_features(m.regions[0], 1, span=m.spans[0] if m.spans else None)
             for m in single],
            [bool(ok) for ok in exact(single, th, pooling)])


def cross_fitted_features(maps: Sequence[TuningMap], pooling: str = "mean",
                          folds: int = 5, refit=None) -> tuple[list[dict[str, float]], list[bool]]:
    """Confidence features and outcomes of the one-region maps, each read with thresholds
    fitted without it.

    The one-region maps (:func:`one_region`) are split into ``folds`` by position; for
    each fold the thresholds are refitted on the other folds, and the fold's regions get
    their features and whether their beta_1 is right from that refit
    (:func:`features_under`).  ``refit(maps) -> RatioThresholds`` (default:
    :func:`fit_thresholds` with ``pooling``) is how the thresholds are refitted.
    """
    refit = refit or (lambda subset: fit_thresholds(subset, pooling).thresholds)
    single = one_region(maps)
    fold = np.arange(len(single)) % folds
    features, correct = [], []
    for k in range(folds):
        held_features, held_correct = features_under([m for m, f in zip(single, fold) if f == k],
                                                     refit([m for m, f in zip(single, fold) if f != k]), pooling)
        features += held_features
        correct += held_correct
    return features, correct


def calibrated_classifier(maps: Sequence[TuningMap], thresholds: RatioThresholds, provenance: dict,
                          pooling: str = "mean", folds: int = 5, refit=None,
                          beyond: Sequence[TuningMap] = ()) -> RatioClassifier:
    """The classifier of the fitted ``thresholds`` with its confidence calibrated by cross-fitting.

    The thresholds were chosen on ``maps``, so their outcomes under them are
    optimistic.  The logistic model is fitted on their out-of-fold features and outcomes
    (:func:`cross_fitted_features`, thresholds refitted by ``refit``) and on those of
    the ``beyond`` maps (the calibration grid: no threshold was chosen on them) read
    with the final thresholds, and then used with the final thresholds.  Its features
    are CONFIDENCE_FEATURES with ``beyond`` maps and z alone without: the suite's maps
    nearly all sit at the resolution cap, so only the grid gives ln L a range to be
    fitted on.
    """
    features, correct = cross_fitted_features(maps, pooling, folds, refit)
    more_features, more_correct = features_under(beyond, thresholds, pooling)
    names, calibration = CONFIDENCE_FEATURES, (f"{folds}-fold cross-fitted on {len(features)} tuning maps and "
                                               f"{len(more_features)} calibration-grid maps")
    if not more_features:
        names, calibration = ("z",), f"{folds}-fold cross-fitted"
    model = RatioClassifier({1: thresholds}, provenance={**provenance, "calibration": calibration}, pooling=pooling)
    model.calibrate(features + more_features, correct + more_correct, names)
    # last, the power of a several-region map's product, on the arenas of several rooms
    # read with the final thresholds (chosen on all the tuning maps, these among them)
    log_products, right = several_region_products(maps, model)
    if len(np.unique(right)) == 2:
        with_regions_exponent(model, fit_regions_exponent(log_products, right), len(right))
    return model


def several_region_products(maps: Sequence[TuningMap], model: RatioClassifier) -> tuple[np.ndarray, np.ndarray]:
    """For the ``maps`` of arenas of several rooms mapped to two regions or more: ln of the
    product of their regions' beta_1 confidences under ``model`` (its ``regions_exponent``
    ignored) and whether their beta_1 (the sum of the regions') is right.  A one-room
    arena split by a sparse log is left out: its beta_0 is wrong, and the power corrects
    how rooms read, which is what ``--regions-only`` maps."""
    several = [m for m in maps if m.true_betti0 >= 2 and len(m.regions) >= 2]
    log_products, right = [], []
    for m in several:
        readers = [_reader(model, m, r) for r in range(len(m.regions))]
        votes = [vote(reader, region) for reader, region in zip(readers, m.regions)]
        log_products.append(sum(np.log(reader.region_confidence(region, voted)[1])
                                for reader, region, voted in zip(readers, m.regions, votes)))
        right.append(sum(voted[0][1] for voted in votes) == m.true_betti1)
    return np.array(log_products, dtype=float), np.array(right, dtype=bool)


def fit_regions_exponent(log_products: np.ndarray, right: np.ndarray) -> float:
    """The maximum-likelihood a of P(right) = exp(a ln prod_r p_r) (:func:`~swarmtopo.readers.ratio.map_confidence`),
    on maps with both outcomes; searched in REGIONS_EXPONENT_RANGE."""
    s, y = np.asarray(log_products, dtype=float), np.asarray(right, dtype=bool)
    if len(np.unique(y)) < 2:
        raise ValueError("the regions' exponent needs maps both right and wrong")

    def negative_log_likelihood(a: float) -> float:
        p = np.clip(np.exp(a * s), 1e-12, 1 - 1e-12)
        return -float(np.sum(np.where(y, np.log(p), np.log1p(-p))))

    return float(minimize_scalar(negative_log_likelihood, bounds=REGIONS_EXPONENT_RANGE, method="bounded",
                                 options={"xatol": 1e-6}).x)


def with_regions_exponent(model: RatioClassifier, a: float, maps: int) -> RatioClassifier:
    """``model`` with its beta_1 calibration's ``regions_exponent`` set to ``a``, fitted on
    ``maps`` several-region maps (which its provenance records)."""
    model.calibration_["1"] = {**model.calibration_["1"], REGIONS_EXPONENT: float(a)}
    model.provenance_["regions_calibration"] = f"fitted on {maps} several-region tuning maps"
    return model


def regions_exponent_scores(log_products: np.ndarray, right: np.ndarray, folds: int = 10,
                            seed: int = 0) -> dict[str, dict[str, float]]:
    """Brier score and log loss of three beta_1 confidences of several-region maps: the
    plain product, the product to a power fitted without the map (``folds`` shuffled
    folds, :func:`fit_regions_exponent`), and a constant equal to the maps' rate."""
    s, y = np.asarray(log_products, dtype=float), np.asarray(right, dtype=bool)
    fold = np.random.default_rng(seed).permutation(len(y)) % folds
    if any(len(np.unique(y[fold != k])) < 2 for k in range(folds)):
        raise ValueError(f"too few maps right or wrong ({int(y.sum())} of {len(y)} right) to cross-fit "
                         f"the regions' exponent over {folds} folds")
    held_out = np.empty(len(y))
    for k in range(folds):
        held_out[fold == k] = np.exp(fit_regions_exponent(s[fold != k], y[fold != k]) * s[fold == k])
    scored = {"product": np.exp(s), "product to the power a (cross-fitted)": held_out,
              "constant": np.full(len(y), y.mean())}
    return {name: {"brier": float(brier_score_loss(y, p)), "log_loss": float(log_loss(y, p, labels=[False, True]))}
            for name, p in scored.items()}
