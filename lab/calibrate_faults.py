"""Fit the beta_1 confidence of the shipped readers on logs with faulty sensing
(``swarmtopo.readers.recalibrated``): Platt scaling p' = sigmoid(a + b logit p).

    python lab/calibrate_faults.py --store faults-cal.duckdb --per-cell 3 --workers 2 [--features] [--write]

Runs (resumably, windows' diagrams kept) the fault benchmark's *tuning* cases at every
fault level twice: read as contact traces (the ``trace`` reader) and as log folders
(the ``default`` reader).  On the maps whose log the fault screen reads as faulty
(``swarmtopo.pipeline.faults``: far share above CLEAN_FAR_SHARE or uncorroborated share
above POOR_SHARE) and that find one region (the map's confidence is then the region's,
to which the recalibration applies), it reads the windows again with the raw preset,
fits (a, b) by logistic regression of "beta_1 right" on logit p, and prints the 5-fold
cross-validated Brier score against the raw confidence and a constant, and the wrong
maps said at 0.95 or more.  ``--features`` also prints the cross-validated Brier score
with the screen's shares u (uncorroborated) and f (far) as more terms.  ``--write``
writes swarmtopo/data/fault-confidence.json.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from sklearn.linear_model import LogisticRegression
from sklearn.model_selection import cross_val_predict

from calibrate_flicker import clipped_logit, platt_fit
from swarmtopo.experiments.accuracy import PIPELINES, TRACE_PIPELINE
from swarmtopo.experiments.faults import SUITE, jobs
from swarmtopo.experiments.store import read_jobs
from swarmtopo.experiments.sweep import run_sweep
from swarmtopo.readers.recalibrated import FAULT_FORMAT
from swarmtopo.readers.registry import load_classifier

READINGS = {"trace": TRACE_PIPELINE, "default": PIPELINES["default"]}
OUT = Path(__file__).resolve().parent.parent / "src" / "swarmtopo" / "data" / "fault-confidence.json"
COLUMNS = ("key", "config", "diagrams", "error", "est_betti0", "true_betti0", "true_betti1", "sensing")
CONFIDENT = 0.95


def raw_confidences(rows, preset: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(features [logit p, u, f], beta_1 right, raw p) of the faulty one-region maps among ``rows``."""
    reader = load_classifier(preset)
    x, right, raw = [], [], []
    for row in rows:
        sensing = row["sensing"] or {}
        if row["error"] is not None or not sensing.get("suspected") or len(row["diagrams"]) != 1:
            continue
        readings = [reader.read([w["diagram"] for w in r["windows"]]) for r in row["diagrams"]]
        confidence = reader.map_confidence([r.confidence.get(1) for r in readings], 1)
        if confidence is None:
            continue
        raw.append(confidence)
        x.append([float(clipped_logit(np.array(confidence))), sensing["uncorroborated_share"], sensing["far_share"]])
        right.append(sum(r.betti.get(1, 0) for r in readings) == row["true_betti1"])
    return np.array(x), np.array(right, dtype=float), np.array(raw)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--store", required=True)
    parser.add_argument("--per-cell", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--features", action="store_true", help="also score the fit with u and f as terms")
    parser.add_argument("--write", action="store_true")
    args = parser.parse_args()
    fits = {}
    for preset, pipeline in READINGS.items():
        todo = jobs("tuning", pipeline=pipeline, cases=args.per_cell)
        run_sweep(todo, args.store, workers=args.workers, keep="windows")
        rows = read_jobs(args.store, columns=COLUMNS, keys=[job.key for job in todo])
        x, y, p = raw_confidences(rows, preset)
        fits[preset], line = platt_fit(p, y, "faulty", CONFIDENT)
        print(f"{preset}: {line}")
        if args.features:
            for name, columns in (("logit p, f", [0, 2]), ("logit p, u, f", [0, 1, 2])):
                more = cross_val_predict(LogisticRegression(C=1e6, max_iter=1000), x[:, columns], y, cv=5,
                                         method="predict_proba")[:, 1]
                print(f"  {name}: Brier (5-fold) {np.mean((more - y) ** 2):.4f}")
    if args.write:
        doc = {"format": FAULT_FORMAT, "presets": fits, "script": "lab/calibrate_faults.py",
               "fitted_on": f"{SUITE} tuning cases, {args.per_cell} per hole count and fault level (0-3 holes)"}
        OUT.write_text(json.dumps(doc, indent=2, sort_keys=True) + "\n", encoding="utf-8")
        print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
