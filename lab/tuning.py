"""Choosing the default pipeline and ratio classifier on the benchmark's tuning cases.

``lab/tune_accuracy.py`` runs the tuning jobs of candidate pipelines
(:func:`~swarmtopo.experiments.accuracy.tuning_jobs`, inside
:func:`~swarmtopo.experiments.accuracy.tuning_session`), reads each candidate's maps
from the store (:func:`maps_from_rows`) and fits the
:class:`~swarmtopo.readers.ratio.RatioClassifier` thresholds (q_1, tau_1) on their
stored per-window diagrams (:func:`fit_thresholds`: :meth:`RatioClassifier.fit
<swarmtopo.readers.ratio.RatioClassifier.fit>` on :func:`training_set`) -- the
thresholds change only which bars count, so no job is rerun -- for each way of pooling
the windows, with a cross-validated count beside the fitted one
(:func:`cross_validated`).  The confidence model of the chosen candidate is then fitted
on the same tuning maps, cross-fitted (:func:`calibrated_classifier`,
:func:`cross_fitted_features`), and on the calibration grid's maps read the same way
(:func:`features_under`), and last the power of a several-region map's product of
regional confidences on the tuning maps of several rooms
(:func:`several_region_products`, :func:`fit_regions_exponent`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
from scipy.optimize import minimize_scalar
from sklearn.metrics import brier_score_loss, log_loss

from swarmtopo.experiments.sweep import cached_classifier, job_classifier, job_map_config
from swarmtopo.pipeline import MapConfig
from swarmtopo.readers.ratio import (CONFIDENCE_FEATURES, REGIONS_EXPONENT, RatioClassifier, RatioThresholds,
                                     windows_span)
from swarmtopo.topology.persistence import Diagram

REGIONS_EXPONENT_RANGE = (0.05, 20.0)
"""Where :func:`fit_regions_exponent` searches the power a of a several-region map's product."""
PIPELINE_FIELDS = ("metric", "hop_cost", "diffusion_time", "wall_follow_weight", "window_length",
                   "window_encounters", "window_scales", "window_step", "landmark_bands")
"""The MapConfig fields the candidate pipelines of ``lab/tune_accuracy.py`` set: the
chosen candidate's must be MapConfig's defaults."""


def job_pipeline(mapping: dict) -> dict:
    """The ``PIPELINE_FIELDS`` a stored job was mapped with (its ``[map]`` table; unset
    landmark bands resolved by the preset classifier that ran it, as the map does)."""
    return pipeline_fields(job_map_config(mapping), cached_classifier(job_classifier(mapping)))


def pipeline_fields(config: MapConfig, classifier) -> dict:
    """``PIPELINE_FIELDS`` of ``config`` as mapped with ``classifier``: unset landmark bands
    are the classifier's (``landmark_bands``) with maxmin, else (1,)."""
    bands = config.landmark_bands
    if bands is None:
        bands = classifier.landmark_bands if config.subsample == "maxmin" else (1.0,)
    return {k: tuple(bands) if k == "landmark_bands" else getattr(config, k) for k in PIPELINE_FIELDS}


@dataclass(frozen=True)
class TuningMap:
    """One tuning map: its regions' windows, its estimated beta_0 and the truth."""

    regions: tuple[tuple[Diagram, ...], ...]  # each region's windows' diagrams
    est_betti0: int
    true_betti0: int
    true_betti1: int
    cell: str
    spans: tuple[float, ...] = ()  # each region's windows' span T in seconds (ratio.windows_span); () unknown


def maps_from_rows(rows: Sequence[dict[str, Any]], cell_of) -> list[TuningMap]:
    """TuningMaps of the finished rows of a store (failed jobs are skipped: they have no map).

    ``cell_of(config) -> str`` names each row's cell.
    """
    return [TuningMap(tuple(tuple(w["diagram"] for w in region["windows"])
                            for region in row["diagrams"]),
                      int(row["est_betti0"]), int(row["true_betti0"]), int(row["true_betti1"]), cell_of(row["config"]),
                      tuple(windows_span(region["windows"]) for region in row["diagrams"]))
            for row in rows if row["error"] is None]


def training_set(maps: Sequence[TuningMap]) -> tuple[list, np.ndarray, np.ndarray]:
    """(X, y, beta0_right) of :meth:`RatioClassifier.fit` from tuning maps: each map's
    regions' window diagrams, its true beta_1, and whether its beta_0 is right."""
    return ([m.regions for m in maps], np.array([m.true_betti1 for m in maps]),
            np.array([m.est_betti0 == m.true_betti0 for m in maps]))


def exact(maps: Sequence[TuningMap], th: RatioThresholds, pooling: str = "mean") -> np.ndarray:
    """Whether each map's (beta_0, beta_1) is exactly right under thresholds ``th``, its
    regions' windows pooled by ``pooling`` (the literal classifier)."""
    model = RatioClassifier.from_thresholds({1: th}, pooling=pooling)
    return np.array([m.est_betti0 == m.true_betti0 and
                     sum(model.pooled_betti(region)[1] for region in m.regions) == m.true_betti1 for m in maps])


@dataclass(frozen=True)
class Fit:
    """The thresholds chosen, their tuning exact rate, the exact-rate surface and the pooling."""

    thresholds: RatioThresholds
    accuracy: float
    surface: np.ndarray  # (len(Q_GRID), len(TAU_GRID)) exact rate
    pooling: str


def fit_thresholds(maps: Sequence[TuningMap], pooling: str = "mean") -> Fit:
    """(q_1, tau_1) of :meth:`RatioClassifier.fit` on ``maps`` (its default grid)."""
    model = RatioClassifier(pooling=pooling).fit(*training_set(maps))
    return Fit(model.thresholds_[1], model.accuracy_, model.surface_, pooling)


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
    model = RatioClassifier.from_thresholds({1: th}, pooling=pooling)
    return ([model.region_features(m.regions[0], 1, span=m.spans[0] if m.spans else None) for m in single],
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
    model = RatioClassifier.from_thresholds({1: thresholds}, provenance={**provenance, "calibration": calibration},
                                            pooling=pooling)
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
        readings = [model.read(region) for region in m.regions]
        log_products.append(sum(np.log(reading.confidence[1]) for reading in readings))
        right.append(sum(reading.betti[1] for reading in readings) == m.true_betti1)
    return np.array(log_products, dtype=float), np.array(right, dtype=bool)


def fit_regions_exponent(log_products: np.ndarray, right: np.ndarray) -> float:
    """The maximum-likelihood a of P(right) = exp(a ln prod_r p_r)
    (:meth:`~swarmtopo.readers.ratio.RatioClassifier.map_confidence`), on maps with both
    outcomes; searched in REGIONS_EXPONENT_RANGE."""
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
