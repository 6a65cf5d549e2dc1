"""Fit ``swarmtopo plan``'s model on the benchmark's reporting maps and its planning grid.

The reporting cases' budgets raise swarm size and duration together (200 x 30 s,
300 x 40 s, 400 x 60 s), so on them alone a model cannot tell what more agents buy
from what more time buys; fitted there, the previous model put nearly all of it on
time and promised 100 % to 100 agents x 120 s, which maps right about 60 % of the
time (``benchmarks/outside_suite.py``).  The planning grid
(``experiments.accuracy.PLANNING_CELLS``: 0-3 holes x 100-800 agents x 15-120 s,
scales 0.75-2) varies each on its own.  This runs the grid's default-pipeline maps on
Dask into ``--planning-store`` (resumable), reads the default pipeline's reporting
maps from ``--store`` (a full ``swarmtopo bench accuracy`` run), fits the model on both
(``plan.fit_plan``) and writes it (default: the shipped ``src/swarmtopo/data/plan.json``;
``tests/test_plan.py``'s check of the shipped model's map count and ranges then needs
the grid's figures).

Printed: the log loss and Brier score of the previous form (no swarm-size term) fitted
on the reporting maps, scored on the grid; the 10-fold cross-validated scores of the
previous form and of the form with ln N, each fitted on all the maps; then per budget of the grid the maps right beside
what the fitted model expects.

    python scripts/fit_plan.py --store full.duckdb [--planning-store planning.duckdb] [--per-cell 3] [--workers 2]
"""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path

import numpy as np

from swarmtopo.classify import load_classifier
from swarmtopo.experiments.accuracy import (PIPELINES, PLANNING_BUDGETS, PLANNING_CELLS, PLANNING_PER_CELL,
                                            REPORTING_PER_CELL, outcomes, planning_jobs, reporting_jobs)
from swarmtopo.experiments.store import job_rows
from swarmtopo.experiments.sweep import run_sweep
from swarmtopo.io import write_json
from swarmtopo.plan import fit_plan

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "src" / "swarmtopo" / "data" / "plan.json"
FOLDS = 10


def _scores(model, records) -> tuple[float, float]:
    """(mean log loss, Brier score) of a plan model's P(right) on records."""
    p = np.clip([model.accuracy(r["area"], r["agents"], r["duration"], r["true_betti1"]) for r in records],
                1e-6, 1 - 1e-6)
    y = np.array([r["right"] for r in records], dtype=float)
    return float(-np.mean(y * np.log(p) + (1 - y) * np.log(1 - p))), float(np.mean((p - y) ** 2))


def _cross_validated(records, fit, rng) -> tuple[float, float]:
    """Each record scored by a model fitted without its fold (``FOLDS`` random folds)."""
    fold = rng.permutation(len(records)) % FOLDS
    losses, briers = [], []
    for k in range(FOLDS):
        train = [r for r, f in zip(records, fold) if f != k]
        test = [r for r, f in zip(records, fold) if f == k]
        loss, brier = _scores(fit(train), test)
        losses.append(loss * len(test))
        briers.append(brier * len(test))
    return sum(losses) / len(records), sum(briers) / len(records)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--store", required=True, help="store of a full swarmtopo bench accuracy run")
    parser.add_argument("--planning-store", default="planning.duckdb", help="store of the planning grid (resumable)")
    parser.add_argument("--per-cell", type=int, default=PLANNING_PER_CELL)
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args()
    command = "python scripts/fit_plan.py " + " ".join(shlex.quote(a) for a in sys.argv[1:])

    classifier = load_classifier(PIPELINES["default"]["classifier"])
    reporting = reporting_jobs(REPORTING_PER_CELL, {"default": PIPELINES["default"]})
    reported = outcomes(job_rows(args.store, reporting), classifier)
    if len(reported) != len(reporting):
        sys.exit(f"{args.store}: {len(reported)} of the {len(reporting)} default-pipeline reporting maps "
                 "(run swarmtopo bench accuracy --store on it first)")
    jobs = planning_jobs(args.per_cell)
    summary = run_sweep(jobs, args.planning_store, workers=args.workers)
    planned = outcomes(job_rows(args.planning_store, jobs), classifier, cells=PLANNING_CELLS)
    print(f"planning grid: {len(planned)} maps ({summary.run} run now, {summary.seconds / 60:.1f} min), "
          f"{sum(r['right'] for r in planned)} right; reporting maps: {len(reported)}, "
          f"{sum(r['right'] for r in reported)} right")

    both = reported + planned
    previous = fit_plan(reported, "previous", swarm_size=False)  # what bench accuracy fits
    loss, brier = _scores(previous, planned)
    print(f"previous form (no ln N), reporting maps only: log loss {loss:.4f}, Brier {brier:.4f} "
          "(on the planning grid, which it never saw)")
    for name, swarm_size in (("previous form (no ln N), both", False), ("with ln N, both", True)):
        loss, brier = _cross_validated(both, lambda rs: fit_plan(rs, "cv", swarm_size=swarm_size),
                                       np.random.default_rng(0))
        print(f"{name}: log loss {loss:.4f}, Brier {brier:.4f} ({FOLDS}-fold cross-validated)")

    model = fit_plan(both, source=command)
    print(f"fitted: c0 {model.intercept:.3f}, c1 (ln N/A) {model.density_coef:.3f}, c2 (ln T) "
          f"{model.duration_coef:.3f}, c4 (ln N) {model.agents_coef:.3f}, c3 (H) {model.holes_coef:.3f}; "
          f"{model.maps} maps")
    print("| budget | planning maps right | fitted model expects | previous model expected |")
    print("|---|---|---|---|")
    for n, t in PLANNING_BUDGETS:
        rows = [r for r in planned if r["agents"] == n and r["duration"] == t]
        expected = [np.mean([m.accuracy(r["area"], n, t, r["true_betti1"]) for r in rows]) for m in (model, previous)]
        print(f"| {n} x {t:g} s | {sum(r['right'] for r in rows)}/{len(rows)} | {expected[0]:.2f} | {expected[1]:.2f} |")
    write_json(model.to_json(), args.out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
