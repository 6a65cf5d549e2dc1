"""Fit the beta_1 confidence of the shipped readers on logs whose contacts flicker
(``swarmtopo.readers.recalibrated``): Platt scaling p' = sigmoid(a + b logit p).

    python lab/calibrate_flicker.py --store flicker.duckdb --per-cell 12 --workers 2 [--write]

Runs (resumably, windows' diagrams kept) the motion benchmark's *tuning* cases of the
flickering models (Brownian and flocking swarms, 0-3 holes) twice: read as contact
traces (the ``trace`` reader) and as log folders (the ``default`` reader).  On the maps
the map reads as flickering and finds one region in (the map's confidence is then
the region's, to which the recalibration applies) it reads the windows again with the
raw preset, fits (a, b) by logistic regression of "beta_1 right" on logit p, and prints the 5-fold
cross-validated Brier score against the raw confidence and a constant, and the wrong
maps said at 0.9 or more.  ``--write`` writes swarmtopo/data/flicker-confidence.json.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from sklearn.linear_model import LogisticRegression
from sklearn.model_selection import cross_val_predict

from swarmtopo.experiments.accuracy import PIPELINES, TRACE_PIPELINE, tuning_session
from swarmtopo.experiments.motion_models import CELLS, SUITE, jobs
from swarmtopo.experiments.store import read_jobs
from swarmtopo.experiments.sweep import run_sweep
from swarmtopo.readers.recalibrated import FLICKER_FORMAT
from swarmtopo.readers.registry import load_classifier

MODELS = ("brownian", "flocking")
READINGS = {"trace": TRACE_PIPELINE, "default": PIPELINES["default"]}
OUT = Path(__file__).resolve().parent.parent / "src" / "swarmtopo" / "data" / "flicker-confidence.json"
COLUMNS = ("key", "config", "diagrams", "error", "est_betti0", "true_betti0", "true_betti1", "motion_estimate")


def clipped_logit(p: np.ndarray) -> np.ndarray:
    p = np.clip(p, 1e-9, 1 - 1e-9)
    return np.log(p / (1 - p))


def platt_fit(p: np.ndarray, y: np.ndarray, what: str, confident: float) -> tuple[dict, str]:
    """Platt scaling of the confidences ``p`` on the outcomes ``y``: the fit (intercept a,
    slope b, maps) and a line with its 5-fold cross-validated Brier score against the raw
    confidence and a constant, and the wrong maps said at ``confident`` or more."""
    x = clipped_logit(p)[:, None]
    model = LogisticRegression(C=1e6)
    folds = cross_val_predict(model, x, y, cv=5, method="predict_proba")[:, 1]
    model.fit(x, y)
    fit = {"intercept": float(model.intercept_[0]), "slope": float(model.coef_[0, 0]), "maps": int(len(y))}
    line = (f"{len(y)} {what} maps, {int(y.sum())} right; Brier raw {np.mean((p - y) ** 2):.4f}, "
            f"recalibrated (5-fold) {np.mean((folds - y) ** 2):.4f}, constant {np.mean((y.mean() - y) ** 2):.4f}; "
            f"wrong maps said >= {confident:g}: raw {int(((p >= confident) & (y == 0)).sum())}, recalibrated "
            f"{int(((folds >= confident) & (y == 0)).sum())}; a = {fit['intercept']:.3f}, b = {fit['slope']:.3f}")
    return fit, line


def raw_confidences(rows, preset: str) -> tuple[np.ndarray, np.ndarray]:
    """(raw map confidence of beta_1, beta_1 right) of the flickering maps among ``rows``."""
    reader = load_classifier(preset)
    p, right = [], []
    for row in rows:
        if (row["error"] is not None or (row["motion_estimate"] or {}).get("regime") != "flickering"
                or len(row["diagrams"]) != 1):  # one region: the map's confidence is the region's, as it is applied
            continue
        readings = [reader.read([w["diagram"] for w in r["windows"]]) for r in row["diagrams"]]
        confidence = reader.map_confidence([r.confidence.get(1) for r in readings], 1)
        if confidence is None:
            continue
        p.append(confidence)
        right.append(sum(r.betti.get(1, 0) for r in readings) == row["true_betti1"])
    return np.array(p), np.array(right, dtype=float)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--store", required=True)
    parser.add_argument("--per-cell", type=int, default=12)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--write", action="store_true")
    args = parser.parse_args()
    cells = [c for c in CELLS if c.model in MODELS]
    fits = {}
    for preset, pipeline in READINGS.items():
        with tuning_session():
            todo = jobs("tuning", args.per_cell, cells, pipeline)
        run_sweep(todo, args.store, workers=args.workers, keep="windows")
        rows = read_jobs(args.store, columns=COLUMNS, keys=[job.key for job in todo])
        p, y = raw_confidences(rows, preset)
        fits[preset], line = platt_fit(p, y, "flickering", 0.9)
        print(f"{preset}: {line}")
    if args.write:
        doc = {"format": FLICKER_FORMAT, "presets": fits, "script": "lab/calibrate_flicker.py",
               "fitted_on": f"{SUITE} tuning cases, {args.per_cell} per cell of {', '.join(MODELS)} (0-3 holes)"}
        OUT.write_text(json.dumps(doc, indent=2, sort_keys=True) + "\n", encoding="utf-8")
        print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
