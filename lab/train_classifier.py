"""Train the paper's classifier form the paper's way (``load_classifier("paper")``).

The shipped default is the ratio classifier of ``lab/tune_accuracy.py``; this
script trains the paper's form on random environments, which ``map --paper`` and the
accuracy benchmark's paper pipeline read with.

Runs the training sweep ``swarmtopo.experiments.training.DEFAULT_TRAINING`` and its
held-out twin on Dask (resumable: finished jobs stay in the store), fits Theta_1 with
the grid and the sigmoid optimizer, keeps the one with the lower held-out F,
calibrates its confidence on the held-out maps, and writes

* ``src/swarmtopo/data/classifier-paper.json`` (the winner), and
* ``docs/classifier.md`` (the table below, with the paper's published Theta* on the
  same held-out maps, regenerated).

Usage::

    python lab/train_classifier.py [--store training.duckdb] [--workers N] [--scheduler ADDR]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from swarmtopo import __version__
from swarmtopo.readers.paper import detection_scores, published_paper_classifier
from swarmtopo.experiments.grid import expand_grid
from swarmtopo.experiments.store import read_jobs
from swarmtopo.experiments.sweep import run_sweep
from swarmtopo.experiments.training import DEFAULT_TRAINING, examples_from_rows, fit_and_select, heldout_sweep

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "src" / "swarmtopo" / "data"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--store", default="classifier-training.duckdb", help="DuckDB result store")
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--scheduler", default=None)
    args = parser.parse_args()

    started = time.perf_counter()
    sweeps = {"train": expand_grid(DEFAULT_TRAINING), "heldout": expand_grid(heldout_sweep(DEFAULT_TRAINING))}
    summary = run_sweep([job for s in sweeps.values() for job in s.jobs], args.store,
                        scheduler=args.scheduler, workers=args.workers,
                        progress=lambda done, total, failed: print(f"\r{done}/{total} jobs", end="", flush=True))
    print(f"\n{summary}")
    rows = {name: read_jobs(args.store, sweep=s.name) for name, s in sweeps.items()}
    examples = {name: examples_from_rows(r) for name, r in rows.items()}
    provenance = {
        "name": "paper",
        "script": "lab/train_classifier.py",
        "training_sweep": DEFAULT_TRAINING,
        "heldout_sweep": heldout_sweep(DEFAULT_TRAINING),
        "seeds": "each job's seed is the SHA-256 of its config, replicate and salt "
                 "(salts 'classifier-train' and 'classifier-heldout')",
        "training_maps": len(examples["train"]),
        "heldout_maps": len(examples["heldout"]),
        "excluded": {name: ex.excluded for name, ex in examples.items()},
        "swarmtopo": __version__,
    }
    selection = fit_and_select(examples["train"], examples["heldout"], provenance)
    selection.classifier.save(DATA / "classifier-paper.json")

    heldout = examples["heldout"]
    paper_scores = detection_scores(published_paper_classifier().predict(heldout.diagrams), heldout.truth)
    job_seconds = sum(r["t_total"] for sweep_rows in rows.values() for r in sweep_rows)
    write_doc(selection, paper_scores, examples, time.perf_counter() - started, summary, job_seconds)


def write_doc(selection, paper_scores, examples, seconds, summary, job_seconds) -> None:
    lines = [
        "# The paper classifier (the benchmark's baseline)",
        "",
        "Made by `python lab/train_classifier.py` (this file is its output; "
        f"{summary.run} jobs run in this invocation, {summary.skipped} reused from the store, "
        f"{seconds / 60:.1f} min wall time; the jobs took {job_seconds / 60:.1f} CPU-min in all, "
        "as recorded in the store).",
        "",
        "Training sweep (`swarmtopo.experiments.training.DEFAULT_TRAINING`):",
        "",
        "```json",
        json.dumps(DEFAULT_TRAINING),
        "```",
        "",
        f"Training maps: {len(examples['train'])}; held-out maps (same grid, other salt): "
        f"{len(examples['heldout'])}.  Excluded: {json.dumps({k: v.excluded for k, v in examples.items()})}.",
        "",
        "| optimizer | q | Delta (s) | tau | F train | F held-out | SE held-out | false holes held-out | exact held-out |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for row in selection.table():
        mark = " (kept)" if row["winner"] else ""
        lines.append(f"| {row['optimizer']}{mark} | {row['q']:.3g} | {row['delta']:.3g} | {row['tau']:.3g} | "
                     f"{row['train_F']:.3f} | {row['heldout_F']:.3f} | {row['heldout_SE']:.3f} | "
                     f"{row['heldout_false_holes']:.3f} | {row['heldout_exact']:.3f} |")
    lines.append(f"| paper's Theta* | 0.5 | 0.7 | 3.7 | - | {paper_scores.mean_absolute_error:.3f} | "
                 f"{paper_scores.sensitivity:.3f} | {paper_scores.false_hole_rate:.3f} | {paper_scores.exact:.3f} |")
    calib = selection.classifier.calibration_
    heldout = examples["heldout"]
    beta0_rate = (heldout.beta0_correct.sum() + 1) / (len(heldout.beta0_correct) + 2)
    model = selection.classifier
    confidence = np.array([model.confidence(d)[1] for d in heldout.diagrams])
    right = model.predict(heldout.diagrams) == heldout.truth
    brier, constant = np.mean((confidence - right) ** 2), np.mean((right.mean() - right) ** 2)
    lines += [
        "",
        f"Confidence model of the kept classifier (held-out maps): P(beta_1 right) = "
        f"sigmoid({calib['1']['intercept']:.3f} + {calib['1']['margin']:.3f} m + {calib['1']['gap']:.3f} g), "
        "m the log-ratio margin of the nearest bar to the threshold, g the log-ratio gap between the shortest "
        f"counted and the longest uncounted bar; beta_0 right in {beta0_rate:.3f} of held-out maps "
        "(Laplace-smoothed).",
        "",
        f"On the held-out maps (the ones it was fitted on) the beta_1 confidence ranges "
        f"{confidence.min():.2f}-{confidence.max():.2f} (median {np.median(confidence):.2f}); Brier score "
        f"{brier:.4f} against {constant:.4f} for a constant equal to the accuracy. The features barely predict "
        "when this classifier is right: the confidence is honest about the average and says little about a "
        "single map.",
        "",
    ]
    (ROOT / "docs" / "classifier.md").write_text("\n".join(lines), encoding="utf-8")


if __name__ == "__main__":
    main()
