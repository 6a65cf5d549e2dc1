"""Choosing the default pipeline and ratio classifier on the benchmark's tuning cases.

``scripts/tune_accuracy.py`` runs the tuning jobs of candidate pipelines
(:func:`~.accuracy.tuning_jobs`, inside :func:`~.accuracy.tuning_session`), then for
each candidate fits the :class:`~swarmtopo.ratio.RatioClassifier` thresholds
(q_1, tau_1, gamma_1) by grid search on the stored per-window diagrams -- the
thresholds change only which bars count, so no job is rerun -- and keeps the
candidate with the most exact (beta_0, beta_1) maps.  The confidence model is then
fitted on the same tuning maps, cross-fitted (:func:`calibrated_classifier`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
from scipy.ndimage import uniform_filter

from ..persistence import Diagram
from ..ratio import RatioClassifier, RatioThresholds, WindowBars, ranked_gaps, counted_bars, median_vote

Q_GRID = (0.5, 0.6, 0.7, 0.8, 0.9)
TAU_GRID = tuple(np.round(np.geomspace(1.2, 12.0, 80), 4))
GAMMA_GRID = (0.0,) + tuple(np.round(np.geomspace(1.0, 2.0, 16), 4))
"""The (q_1, tau_1, gamma_1) grid; gamma 0 is the gap rule off.  The gates rho_1 and
kappa_1 stay off: the first tuning round measured that they never raised the rate."""


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
    """The thresholds chosen, their tuning exact rate, and the exact-rate surface."""

    thresholds: RatioThresholds
    accuracy: float
    surface: np.ndarray  # (len(Q_GRID), len(TAU_GRID), len(GAMMA_GRID)) exact rate
    no_gap: RatioThresholds  # the best point with the gap rule off (what the gap rule is weighed against)


def window_counts(diagram: Diagram) -> np.ndarray:
    """beta_hat_1 of one window at every grid point, ``(len(Q_GRID), len(TAU_GRID),
    len(GAMMA_GRID))``: :func:`~swarmtopo.ratio.counted_bars` with the gates off, at once.

    Without gates the candidates are the m(q, tau) longest finite bars, so the gap
    rule's k* is the first argmax of g over ranks < m: a running maximum of g.
    """
    out = np.zeros((len(Q_GRID), len(TAU_GRID), len(GAMMA_GRID)), np.int64)
    if diagram.maxdim < 1 or not len(diagram[1]):
        return out
    finite, order, gaps = ranked_gaps(diagram[1])
    ranked = (diagram[1][:, 1] - diagram[1][:, 0])[order]
    out += int((~finite).sum())
    if not len(ranked):
        return out
    best = np.maximum.accumulate(gaps)
    # k* - 1 over the first i + 1 ranks: the last rank where the running maximum rose
    # (strictly, so ties keep the first argmax)
    rose = np.r_[True, gaps[1:] > best[:-1]]
    first = np.maximum.accumulate(np.where(rose, np.arange(len(gaps)), 0))
    ascending = ranked[::-1]
    log_gamma = np.log(np.maximum(GAMMA_GRID[1:], 1.0))
    for i, q in enumerate(Q_GRID):
        lq = float(np.quantile(ranked, q))
        m = (len(ranked) - np.searchsorted(ascending, np.asarray(TAU_GRID) * lq, side="right")
             if lq > 0 else np.full(len(TAU_GRID), len(ranked)))
        out[i, :, 0] += m
        has = m > 0
        top = np.where(has, m - 1, 0)
        out[i, :, 1:] += np.where(has[:, None] & (best[top][:, None] >= log_gamma[None, :]),
                                  first[top][:, None] + 1, 0)
    return out


def grid_estimates(maps: Sequence[TuningMap]) -> np.ndarray:
    """beta_hat_1 of every map at every grid point, regions' windows voted by lower median."""
    est = np.zeros((len(maps), len(Q_GRID), len(TAU_GRID), len(GAMMA_GRID)), np.int64)
    for k, m in enumerate(maps):
        for region in m.regions:
            counts = np.sort(np.stack([window_counts(w.diagram) for w in region]), axis=0)
            est[k] += counts[(len(region) - 1) // 2]
    return est


def fit_thresholds(maps: Sequence[TuningMap]) -> Fit:
    """(q_1, tau_1) with the gap rule off, and (q_1, tau_1, gamma_1 >= 1) with it on,
    each at the grid point whose 3 x 3 (x 3) neighbourhood (edges repeated) has the
    highest mean exact rate (ties: the first), so the choice sits inside a plateau
    rather than on a lucky spike; the gap rule is kept only if its point is right on
    more maps."""
    truth = np.array([m.true_betti1 for m in maps])
    beta0 = np.array([m.est_betti0 == m.true_betti0 for m in maps])
    right = (grid_estimates(maps) == truth[:, None, None, None]) & beta0[:, None, None, None]
    surface = right.mean(axis=0)
    off = (*_plateau(surface[:, :, 0]), 0)
    on = _plateau(surface[:, :, 1:])
    on = (on[0], on[1], on[2] + 1)
    best = on if surface[on] > surface[off] else off
    return Fit(thresholds=_thresholds(best), accuracy=float(surface[best]), surface=surface,
               no_gap=_thresholds(off))


def _thresholds(point: tuple[int, int, int]) -> RatioThresholds:
    i, j, k = point
    return RatioThresholds(float(Q_GRID[i]), float(TAU_GRID[j]), gamma=float(GAMMA_GRID[k]))


def _plateau(surface: np.ndarray) -> tuple[int, ...]:
    smooth = uniform_filter(surface, size=3, mode="nearest")
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
