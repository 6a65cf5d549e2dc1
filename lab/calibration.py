"""How well each set of confidence features predicts a right beta_1, on tuning and calibration-grid maps.

Reads the default pipeline's maps from a store written by ``lab/tune_accuracy.py``
(tuning cases and the calibration grid, ``experiments.accuracy.calibration_jobs``; the
reporting cases are closed to that script): each one-region tuning map's confidence
features and outcome read with thresholds fitted without it
(``experiments.tuning.cross_fitted_features``, 5 folds, as the shipped calibration),
each one-region calibration-grid map's read with the thresholds fitted on all tuning
maps (no threshold is chosen on the grid).  For each feature set it fits the logistic
P(right) of ``RatioClassifier.calibrate`` (``ratio.confidence_model``) on both, predicting
each map from a model fitted without it (scikit-learn ``cross_val_predict``, 10 folds,
shuffled with seed 0: the maps are listed tuning first, grid last), and prints the Brier score (against a constant confidence equal to the rate)
and log loss of those predictions, on the tuning maps and on the grid apart, with each
one's reliability table in the bins of the accuracy benchmark.

These are the default classifier's maps, or with ``--reading contact-trace``
the ``trace`` classifier's (the same cases and grid read as contact traces, thresholds
fitted on those maps).

Feature sets: ``z`` (how many standard errors the pooled scores are from changing the
vote, ``ratio.standardised_margin``); z and the windows' resolution ln L
(``ratio.resolution``); those and z ln L (shipped); those and ln #windows; those and the
region's span ln T (the seconds its windows cover, ``ratio.windows_span``); those and z
ln T (measured, not adopted: docs/accuracy.md).
Each is fitted on both sets; then how often a draw of the reporting suite's size
(390 maps) from the tuning maps shows the shipped features no better than the constant;
last, z fitted on the tuning maps alone, as before the grid.  With ``--planning-store``
(a store of ``swarmtopo bench accuracy``'s full run, which maps the planning grid: the
calibration grid's cells with seeds of their own), each feature set is also fitted on
all tuning and calibration-grid maps at once, as the shipped calibration is, and scored
on the planning grid's one-region maps read with the thresholds fitted on the tuning maps:
a check on maps no model or threshold was fitted on.

    python lab/calibration.py [--store tuning.duckdb] [--reading contact-trace]
                                     [--planning-store full.duckdb]
"""

from __future__ import annotations

import argparse
from functools import partial

import numpy as np
from sklearn.metrics import log_loss
from sklearn.model_selection import KFold, cross_val_predict

from swarmtopo.readers.registry import load_classifier
from swarmtopo.experiments.accuracy import CELLS, PLANNING_CELLS, REPORTING_PER_CELL, brier_gain, cell_of, reliability
from swarmtopo.experiments.store import read_jobs
from swarmtopo.experiments.sweep import INPUTS, map_input
from tuning import (cross_fitted_features, features_under, fit_thresholds, job_pipeline,
                                         maps_from_rows, pipeline_fields)
from swarmtopo.pipeline import MapConfig
from swarmtopo.readers.ratio import CONFIDENCE_FEATURES, SPAN_FEATURES, confidence_design, confidence_model

FEATURE_SETS = {
    "z": ("z",),
    "z, resolution": ("z", "resolution"),
    "z, resolution, z x resolution (shipped)": CONFIDENCE_FEATURES,
    "z, resolution, z x resolution, ln windows": (*CONFIDENCE_FEATURES, "windows"),
    "z, resolution, z x resolution, ln span": (*CONFIDENCE_FEATURES, "log_span"),
    "z, resolution, z x resolution, ln span, z x ln span": (*CONFIDENCE_FEATURES, *SPAN_FEATURES),
}
COLUMNS = ("key", "sweep", "config", "replicate", "diagrams", "error", "est_betti0", "true_betti0", "true_betti1")


def default_maps(store: str, reading: str = "log", split: str = "tuning"):
    """The maps of the pipeline whose options are MapConfig's defaults, reading the whole
    log folder (``reading`` "log") or its contact trace ("contact-trace"), in job order:
    the tuning cases (``split`` "tuning"), the calibration grid ("calibration") or the
    planning grid ("planning")."""
    defaults = pipeline_fields(MapConfig(), load_classifier("trace" if reading == "contact-trace" else "default"))
    rows = [r for r in read_jobs(store, columns=COLUMNS) if map_input(r["config"]["map"]) == reading
            and r["sweep"].startswith(f"accuracy-{split}-") and job_pipeline(r["config"]["map"]) == defaults]
    cells = CELLS if split == "tuning" else PLANNING_CELLS
    name = partial(cell_of, cells=cells)
    rows.sort(key=lambda r: (r["replicate"], name(r["config"])))
    return maps_from_rows(rows, name)


def _scores(name: str, y: np.ndarray, p: np.ndarray) -> None:
    rel = reliability([{"confidence_betti1": pi, "betti1_right": bool(yi)} for pi, yi in zip(p, y)], 1)
    print(f"{name}: Brier {rel['brier']:.4f} (constant {rel['brier_constant']:.4f}), log loss {log_loss(y, p, labels=[0, 1]):.4f}")
    print("| confidence | maps | mean confidence | fraction right |")
    print("|---|---|---|---|")
    for b in rel["bins"]:
        print(f"| {b['low']:.2f}-{b['high']:.2f} | {b['maps']} | {b['mean_confidence']:.3f} | "
              f"{b['fraction_right']:.3f} |")


def suite_sized_draws(y: np.ndarray, p: np.ndarray, size: int, draws: int = 4000) -> str:
    """How often a draw of ``size`` of these maps (the reporting suite's size; with
    replacement, seed 0) shows the confidences ``p`` no better than a constant equal to
    the draw's rate: how much one suite-sized sample can say about the Brier gain."""
    rows = np.random.default_rng(0).integers(0, len(y), (draws, size))
    gains = brier_gain(p[rows], y[rows])
    return (f"shipped features, draws of {size} tuning maps ({draws}): the Brier gain over the constant is "
            f"<= 0 in {np.mean(gains <= 0):.1%} of them (median gain {np.median(gains):+.4f})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--store", default="tuning.duckdb", help="a store written by lab/tune_accuracy.py")
    parser.add_argument("--reading", choices=INPUTS, default="log",
                        help="the maps of log folders (default classifier) or of contact traces (trace classifier)")
    parser.add_argument("--planning-store", help="a store of swarmtopo bench accuracy's full run: score each feature "
                                                 "set, fitted on every tuning and calibration-grid map, on its "
                                                 "planning grid")
    args = parser.parse_args()
    maps, grid = default_maps(args.store, args.reading), default_maps(args.store, args.reading, split="calibration")
    print(f"at most {max(len(region) for m in maps for region in m.regions)} windows per region")
    features, correct = cross_fitted_features(maps, "mean")
    thresholds = fit_thresholds(maps, "mean").thresholds
    grid_features, grid_correct = features_under(grid, thresholds, "mean")
    y = np.array(correct + grid_correct)
    on_grid = np.arange(len(y)) >= len(correct)
    print(f"{args.store}: {len(maps)} default-pipeline tuning maps ({args.reading}), {len(correct)} with one region, "
          f"{int((~y[~on_grid]).sum())} wrong when read with thresholds fitted without them; {len(grid)} "
          f"calibration-grid maps, {len(grid_correct)} with one region, {int((~y[on_grid]).sum())} wrong")
    folds = KFold(10, shuffle=True, random_state=0)
    predictions = {}
    for name, columns in FEATURE_SETS.items():
        X = confidence_design(features + grid_features, columns)
        p = predictions[name] = cross_val_predict(confidence_model(), X, y, cv=folds, method="predict_proba")[:, 1]
        print(f"\n## {name}")
        _scores("tuning maps", y[~on_grid], p[~on_grid])
        _scores("calibration grid", y[on_grid], p[on_grid])
    shipped = predictions[next(name for name, columns in FEATURE_SETS.items() if columns == CONFIDENCE_FEATURES)]
    print("\n" + suite_sized_draws(y[~on_grid], shipped[~on_grid], REPORTING_PER_CELL * len(CELLS)))
    alone = cross_val_predict(confidence_model(), confidence_design(features, ("z",)), y[~on_grid], cv=folds,
                              method="predict_proba")[:, 1]
    print("\n## z fitted on the tuning maps alone (the calibration before the grid)")
    _scores("tuning maps", y[~on_grid], alone)
    if args.planning_store:
        planning = default_maps(args.planning_store, args.reading, split="planning")
        held_features, held_correct = features_under(planning, thresholds, "mean")
        print(f"\n## fitted on all {len(y)} maps above, scored on {args.planning_store}'s planning grid "
              f"({len(planning)} maps, {len(held_correct)} with one region, {held_correct.count(False)} wrong)")
        for name, columns in FEATURE_SETS.items():
            model = confidence_model().fit(confidence_design(features + grid_features, columns), y)
            p = model.predict_proba(confidence_design(held_features, columns))[:, 1]
            _scores(name, np.array(held_correct), p)


if __name__ == "__main__":
    main()
