"""Which form of ``swarmtopo plan``'s model to fit: with or without swarm-size terms.

The reporting cases' budgets raise swarm size and duration together (200 x 30 s,
300 x 40 s, 400 x 60 s), so on them alone a model cannot tell what more agents buy
from what more time buys; fitted there, the /2 model (no ln N) put nearly all of it on
time and promised 100 % to 100 agents x 120 s, which maps right about half the time
(``lab/outside_suite.py``).  The planning grid
(``experiments.accuracy.PLANNING_CELLS``: 0-3 holes x 100-800 agents x 15-120 s,
scales 0.75-2) varies each on its own; the full ``swarmtopo bench accuracy`` maps it
and fits plan.json on both with the ln N and ln N ln T terms (the /4 form).  This reads
the default pipeline's reporting and planning maps from that run's store and prints
the evidence for the form: the log loss and Brier score of the /2 form fitted on the
reporting maps alone, scored on the grid; the 10-fold cross-validated scores of the
/2 (no swarm-size term), /3 (ln N) and /4 (ln N, ln N ln T) forms fitted on all the
maps; then per budget of the grid the maps right beside what the /4 and /3 models on
all maps and the /2 model on the reporting maps expect.

With ``--reading contact-trace`` it reads the same cases mapped as contact traces
(``lab/trace_accuracy.py --planning``'s store) by the ``trace`` classifier:
the evidence for ``plan --input contact-trace``'s model.

    python lab/plan_forms.py --store full.duckdb
    python lab/plan_forms.py --store trace.duckdb --reading contact-trace
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from swarmtopo.readers.registry import load_classifier
from swarmtopo.experiments.accuracy import (PIPELINES, PLANNING_BUDGETS, PLANNING_CELLS, PLANNING_PER_CELL,
                                            REPORTING_PER_CELL, TRACE_PIPELINE, outcomes, planning_jobs,
                                            reporting_jobs)
from swarmtopo.experiments.store import job_rows_each
from swarmtopo.experiments.sweep import INPUTS
from swarmtopo.experiments.plan import fit_plan

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
    parser.add_argument("--store", required=True, help="store of a full swarmtopo bench accuracy run "
                                                           "(or of trace_accuracy.py --planning)")
    parser.add_argument("--reading", choices=INPUTS, default="log",
                        help="the cases mapped as log folders (default) or as contact traces")
    args = parser.parse_args()

    trace = args.reading == "contact-trace"
    classifier = load_classifier("trace" if trace else PIPELINES["default"]["classifier"])
    reporting = reporting_jobs(REPORTING_PER_CELL, {"contact-trace": TRACE_PIPELINE} if trace
                               else {"default": PIPELINES["default"]})
    planning = planning_jobs(PLANNING_PER_CELL, reading=args.reading)
    reporting_rows, planning_rows = job_rows_each(args.store, reporting, planning)
    reported = outcomes(reporting_rows, classifier)
    planned = outcomes(planning_rows, classifier, cells=PLANNING_CELLS)
    if (len(reported), len(planned)) != (len(reporting), len(planning)):
        sys.exit(f"{args.store}: {len(reported)} of {len(reporting)} reporting and {len(planned)} of "
                 f"{len(planning)} planning maps (run the full swarmtopo bench accuracy --store on it first)")
    print(f"planning grid: {len(planned)} maps, {sum(r['right'] for r in planned)} right; reporting maps: "
          f"{len(reported)}, {sum(r['right'] for r in reported)} right")

    both = reported + planned
    previous = fit_plan(reported, "/2, reporting", swarm_terms=0)
    loss, brier = _scores(previous, planned)
    print(f"/2 form (no ln N), reporting maps only: log loss {loss:.4f}, Brier {brier:.4f} "
          "(on the planning grid, which it never saw)")
    for name, terms in (("/2 form (no ln N), all maps", 0), ("/3 form (ln N), all maps", 1),
                        ("/4 form (ln N, ln N ln T), all maps", 2)):
        loss, brier = _cross_validated(both, lambda rs: fit_plan(rs, "cv", swarm_terms=terms),
                                       np.random.default_rng(0))
        print(f"{name}: log loss {loss:.4f}, Brier {brier:.4f} ({FOLDS}-fold cross-validated)")

    model, form3 = fit_plan(both, "/4, all"), fit_plan(both, "/3, all", swarm_terms=1)
    shipper = "trace_accuracy.py --plan-out" if trace else "bench accuracy"
    print(f"/4 on all maps (what {shipper} ships): c0 {model.intercept:.3f}, c1 (ln N/A) {model.density_coef:.3f}, "
          f"c2 (ln T) {model.duration_coef:.3f}, c4 (ln N) {model.agents_coef:.3f}, c5 (ln N ln T) "
          f"{model.agents_duration_coef:.3f}, c3 (H) {model.holes_coef:.3f}; {model.maps} maps")
    print("| budget | planning maps right | /4 on all maps expects | /3 on all maps | /2 on reporting maps |")
    print("|---|---|---|---|---|")
    for n, t in PLANNING_BUDGETS:
        rows = [r for r in planned if r["agents"] == n and r["duration"] == t]
        expected = " | ".join(f"{np.mean([m.accuracy(r['area'], n, t, r['true_betti1']) for r in rows]):.2f}"
                              for m in (model, form3, previous))
        print(f"| {n} x {t:g} s | {sum(r['right'] for r in rows)}/{len(rows)} | {expected} |")


if __name__ == "__main__":
    main()
