"""How well each set of confidence features predicts a right beta_1, on the tuning maps only.

Reads the default pipeline's maps from a tuning store written by
``scripts/tune_accuracy.py`` (tuning cases only: the reporting cases are closed to
that script), takes each one-region map's confidence features and outcome read with
thresholds fitted without it (``experiments.tuning.cross_fitted_features``, 5 folds,
as the shipped calibration), and for each feature set fits the logistic P(right) of
``RatioClassifier.calibrate`` (``ratio.confidence_model``), predicting each map from a
model fitted without it (scikit-learn ``cross_val_predict``, 10 folds by position).
Prints the Brier score (against a constant confidence equal to the rate) and log loss
of those predictions, and the reliability table in the bins of the accuracy benchmark.

These are the default (score-only) classifier's maps; the ``gated`` preset's confidence
is fitted the same way, on z, by ``scripts/fit_agreement_gate.py``.

Feature sets: ``z`` (shipped: how many standard errors the pooled scores are from
changing the vote, ``ratio.standardised_margin``); the previous calibration's
agreement of the windows with the vote, log margin and log number of windows; and
both together.

    python benchmarks/calibration.py [--store tuning.duckdb]
"""

from __future__ import annotations

import argparse

import numpy as np
from sklearn.metrics import log_loss
from sklearn.model_selection import KFold, cross_val_predict

from swarmtopo.experiments.accuracy import cell_of, reliability
from swarmtopo.experiments.store import read_jobs
from swarmtopo.experiments.sweep import job_map_config, map_input
from swarmtopo.experiments.tuning import PIPELINE_FIELDS, cross_fitted_features, maps_from_rows
from swarmtopo.pipeline import MapConfig
from swarmtopo.ratio import CONFIDENCE_FEATURES, confidence_design, confidence_model

FEATURE_SETS = {
    "z (shipped)": CONFIDENCE_FEATURES,
    "agreement, margin, ln windows (previous)": ("agreement", "margin", "windows"),
    "z, agreement, margin, ln windows": ("z", "agreement", "margin", "windows"),
}
COLUMNS = ("key", "config", "replicate", "diagrams", "error", "est_betti0", "true_betti0", "true_betti1")


def default_maps(store: str, reading: str = "log"):
    """The tuning maps of the pipeline whose options are MapConfig's defaults, reading the
    whole log folder (``reading`` "log") or its contact trace ("contact-trace"), in job order."""
    defaults = MapConfig()
    rows = [r for r in read_jobs(store, columns=COLUMNS) if map_input(r["config"]["map"]) == reading
            and all(getattr(job_map_config(r["config"]["map"]), k) == getattr(defaults, k) for k in PIPELINE_FIELDS)]
    rows.sort(key=lambda r: (r["replicate"], cell_of(r["config"])))
    return maps_from_rows(rows, cell_of)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--store", default="tuning.duckdb", help="a store written by scripts/tune_accuracy.py")
    args = parser.parse_args()
    maps = default_maps(args.store)
    print(f"at most {max(len(region) for m in maps for region in m.regions)} windows per region")
    features, correct = cross_fitted_features(maps, "mean")
    y = np.array(correct)
    print(f"{args.store}: {len(maps)} default-pipeline tuning maps, {len(y)} with one region; "
          f"{int((~y).sum())} wrong when read with thresholds fitted without them")
    for name, columns in FEATURE_SETS.items():
        X = confidence_design(features, columns)
        p = cross_val_predict(confidence_model(), X, y, cv=KFold(10), method="predict_proba")[:, 1]
        rel = reliability([{"confidence_betti1": pi, "betti1_right": bool(yi)} for pi, yi in zip(p, y)], 1)
        print(f"\n{name}: Brier {rel['brier']:.4f} (constant {rel['brier_constant']:.4f}), "
              f"log loss {log_loss(y, p):.4f}")
        print("| confidence | maps | mean confidence | fraction right |")
        print("|---|---|---|---|")
        for b in rel["bins"]:
            print(f"| {b['low']:.2f}-{b['high']:.2f} | {b['maps']} | {b['mean_confidence']:.3f} | "
                  f"{b['fraction_right']:.3f} |")


if __name__ == "__main__":
    main()
