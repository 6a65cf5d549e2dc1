"""Choosing the default pipeline and ratio classifier on the benchmark's tuning cases.

``scripts/tune_accuracy.py`` runs the tuning jobs of candidate pipelines
(:func:`~.accuracy.tuning_jobs`, inside :func:`~.accuracy.tuning_session`), then for
each candidate fits the :class:`~swarmtopo.ratio.RatioClassifier` thresholds
(q_1, tau_1, rho_1, kappa_1) by grid search on the stored per-window diagrams -- the
thresholds change only which bars count, so no job is rerun -- and keeps the
candidate with the most exact (beta_0, beta_1) maps.  The confidence model is then
fitted on the same tuning maps, cross-fitted (:func:`calibrated_classifier`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from ..persistence import Diagram
from ..ratio import RatioClassifier, RatioThresholds, WindowBars, counted_bars, median_vote

Q_GRID = (0.5, 0.6, 0.7, 0.8, 0.9)
TAU_GRID = tuple(np.round(np.geomspace(1.2, 8.0, 60), 4))
RHO_GRID = (1.0,) + tuple(np.round(np.geomspace(1.5, 3.0, 12), 4))
KAPPA_GRID = tuple(np.round(np.arange(0.0, 3.01, 0.25), 2))


@dataclass(frozen=True)
class TuningMap:
    """One tuning map: its regions' windows, its estimated beta_0 and the truth."""

    regions: tuple[tuple[WindowBars, ...], ...]
    est_betti0: int
    true_betti0: int
    true_betti1: int
    cell: str


def maps_from_rows(rows: Sequence[dict[str, Any]], cell_of) -> list[TuningMap]:
    """TuningMaps of the finished rows of a store (failed jobs are skipped: they have no map).

    ``cell_of(config) -> str`` names each row's cell.
    """
    maps = []
    for row in rows:
        if row["error"] is not None:
            continue
        regions = tuple(
            tuple(WindowBars(Diagram.from_json(w["diagram"]), float(w["cover_radius"])) for w in region["windows"])
            for region in row["diagrams"])
        maps.append(TuningMap(regions, int(row["est_betti0"]), int(row["true_betti0"]), int(row["true_betti1"]),
                              cell_of(row["config"])))
    return maps


def exact(maps: Sequence[TuningMap], th: RatioThresholds) -> np.ndarray:
    """Whether each map's (beta_0, beta_1) is exactly right under thresholds ``th``."""
    return np.array([m.est_betti0 == m.true_betti0 and
                     sum(median_vote([len(counted_bars(w.diagram, 1, w.cover_radius, th)) for w in region])
                         for region in m.regions) == m.true_betti1
                     for m in maps])


@dataclass(frozen=True)
class Fit:
    """The thresholds chosen, their tuning exact rate, and the (q, tau) surface."""

    thresholds: RatioThresholds
    accuracy: float
    surface: np.ndarray  # (len(Q_GRID), len(TAU_GRID)) exact rate with the gates off


def fit_thresholds(maps: Sequence[TuningMap]) -> Fit:
    """(q_1, tau_1) on a grid with the other two tests off, then the gates (rho_1, kappa_1).

    Each stage keeps the grid point whose neighbourhood (3 x 3, edges repeated) has
    the highest mean exact rate (ties: the first), so the choice sits inside a plateau
    rather than on a lucky spike; a gate is switched on only if it raises the rate.
    """
    surface = np.array([[exact(maps, RatioThresholds(q, tau)).mean() for tau in TAU_GRID] for q in Q_GRID])
    i, j = _plateau(surface)
    q, tau = Q_GRID[i], TAU_GRID[j]
    gates = np.array([[exact(maps, RatioThresholds(q, tau, rho, kappa)).mean() for kappa in KAPPA_GRID]
                      for rho in RHO_GRID])
    k, m = _plateau(gates)
    th = RatioThresholds(q, tau, RHO_GRID[k], KAPPA_GRID[m]) if gates[k, m] > surface[i, j] else RatioThresholds(q, tau)
    return Fit(thresholds=th, accuracy=float(exact(maps, th).mean()), surface=surface)


def _plateau(surface: np.ndarray) -> tuple[int, int]:
    padded = np.pad(surface, 1, mode="edge")
    smooth = sum(padded[i:i + surface.shape[0], j:j + surface.shape[1]] for i in range(3) for j in range(3)) / 9
    return tuple(int(x) for x in np.unravel_index(int(np.argmax(smooth + 1e-9 * surface)), surface.shape))


def calibrated_classifier(maps: Sequence[TuningMap], fit: Fit, provenance: dict, folds: int = 5) -> RatioClassifier:
    """The fitted classifier with its confidence calibrated by cross-fitting.

    The thresholds were chosen on these very maps, so their outcomes under them are
    optimistic.  Instead the maps are split into ``folds`` (by position); for each
    fold the thresholds are refitted on the other folds and the fold's regions get
    their features and outcomes from that refit.  The logistic model is fitted on
    those out-of-fold pairs and then used with the final thresholds.  A region's
    outcome is known only when the map has one region (the truth is per map): maps
    whose beta_0 is 1 and right; beta_0's rate uses all maps.
    """
    single = [m for m in maps if m.true_betti0 == 1 and m.est_betti0 == 1]
    fold = np.arange(len(single)) % folds
    features, correct = [], []
    for k in range(folds):
        held = [m for m, f in zip(single, fold) if f == k]
        th = fit_thresholds([m for m, f in zip(single, fold) if f != k]).thresholds
        refit = RatioClassifier({1: th})
        features += [refit.region_features(m.regions[0], 1) for m in held]
        correct += list(exact(held, th))
    model = RatioClassifier({1: fit.thresholds}, provenance={**provenance, "calibration": f"{folds}-fold cross-fitted"})
    return model.calibrate(np.array(features), correct, beta0_correct=[m.est_betti0 == m.true_betti0 for m in maps])
