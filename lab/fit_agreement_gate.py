"""Fit the ``gated`` classifier (the default gated by cross-window cycle agreement) on the benchmark's tuning cases.

``lab/tune_accuracy.py`` fits the default classifier's score threshold (q_1, tau_1)
on stored per-window diagrams.  The gate (:mod:`swarmtopo.readers.ratio`, "Agreement gate")
also needs each region's cross-window cycle agreement A_k, which those rows do not
hold, so this script runs its own tuning jobs (``swarmtopo.experiments.accuracy.tuning_jobs``
inside ``tuning_session``: tuning seeds only, never the held-out hole family): the
default pipeline with ``agreement = "always"`` (every region's A_1 .. A_5 stored), on
Dask with a resumable store, ``--sparse-per-cell`` cases of each cell of the smallest
budget (where the score alone is least sure) and ``--per-cell`` of every other cell.

On those maps, with q_1 the default classifier's, it fits (a = ln tau_1, b) on a grid
(``experiments.tuning.fit_gate``: the best 3 x 3 neighbourhood mean), prints the
exact count per cell against the default's score-only rule (its tau_1, kept in the
file's provenance as ``score_only``) and the 4-fold cross-validated count, fits the
confidence model on the same maps cross-fitted (gate refitted without each fold) and,
where its maps hold two-room arenas both right and wrong, the power of a several-region
map's product (``experiments.tuning.calibrated_classifier``; the shipped file predates it
and has none, so it reads such maps by the plain product), and
writes ``src/swarmtopo/data/classifier-gated.json`` (the ``gated`` preset).  Measured,
it is not better than the default on the suite, which reads the score alone (docs/accuracy.md).

``--veto`` measures an agreement veto for the default classifier instead, and writes
nothing: the default's score threshold (q_1, tau_1) is kept and b alone is fitted on the
same maps (``experiments.tuning.fit_veto``: the strongest veto before the first b that
breaks a tuning map), printed with the per-cell counts against the score alone, the
4-fold cross-validated count (b refitted without each fold) and the tuning count at every
b from 0.6 up.  Measured on the reporting suite and beyond it, the veto is not the
default (docs/accuracy.md).

``--rule A [B]`` (repeatable) also prints, per cell, the count of a fixed rule: S_k > A
(and A_k > B) on the same maps, without writing anything for it.

Usage::

    python lab/fit_agreement_gate.py [--store gate.duckdb] [--per-cell 24] [--sparse-per-cell 96] [--workers N]
                                         [--rule 1.84 0.72 --rule 1.84] [--veto]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from swarmtopo import __version__
from swarmtopo.readers.paper import load_classifier
from swarmtopo.experiments.accuracy import (CELLS, HELD_OUT_FAMILY, PIPELINES, SUITE, cell_of, tuning_jobs,
                                            tuning_session)
from swarmtopo.experiments.store import job_rows
from swarmtopo.experiments.sweep import run_sweep
from tuning import (B_GRID, calibrated_classifier, cross_validated_exact, exact, fit_gate,
                                         fit_veto, maps_from_rows, veto_right)
from swarmtopo.readers.ratio import RatioThresholds

ROOT = Path(__file__).resolve().parent.parent
TARGET = ROOT / "src" / "swarmtopo" / "data" / "classifier-gated.json"
FOLDS = 4


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--store", default="gate.duckdb")
    parser.add_argument("--per-cell", type=int, default=24)
    parser.add_argument("--sparse-per-cell", type=int, default=96)
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--scheduler", default=None)
    parser.add_argument("--rule", nargs="+", type=float, action="append", default=[], metavar="A [B]",
                        help="also print the per-cell counts of the rule S_k > A (and A_k > B)")
    parser.add_argument("--veto", action="store_true",
                        help="measure an agreement veto b for the default classifier (its tau_1 kept); writes nothing")
    args = parser.parse_args()
    if any(len(rule) > 2 for rule in args.rule):
        parser.error("--rule takes A, or A and B")
    started = time.perf_counter()
    shipped = load_classifier("default")
    score_only = RatioThresholds(shipped.thresholds_[1].q, shipped.thresholds_[1].tau)
    pipeline = {**PIPELINES["default"], "classifier": "paper-form", "agreement": "always"}
    sparse = min(c.agents for c in CELLS)
    with tuning_session():
        jobs = list({j.key: j for j in
                     tuning_jobs({"gate": pipeline}, args.sparse_per_cell, [c for c in CELLS if c.agents == sparse])
                     + tuning_jobs({"gate": pipeline}, args.per_cell, [c for c in CELLS if c.agents != sparse])
                     }.values())
        summary = run_sweep(jobs, args.store, scheduler=args.scheduler, workers=args.workers,
                            progress=lambda done, total, failed: print(f"\r{done}/{total} jobs", end="", flush=True))
    print(f"\n{summary}")
    rows = job_rows(args.store, jobs)
    maps = maps_from_rows(rows, cell_of)
    if args.veto:
        report_veto(score_only, maps)
        return
    gate = fit_gate(maps, score_only.q)
    before, after = exact(maps, score_only), exact(maps, gate)
    print(f"{len(maps)} tuning maps ({len(rows) - len(maps)} refused); score only (q {score_only.q:g}, tau "
          f"{score_only.tau:g}, a = {np.log(score_only.tau):.3f}): {before.sum()}; gate a = {np.log(gate.tau):.2f} "
          f"(tau {gate.tau:g}), b = {gate.agreement:g}: {after.sum()} ({np.sum(after & ~before)} fixed, "
          f"{np.sum(before & ~after)} broken)")
    chosen = []  # the gate each fold's refit chose

    def refit(subset):
        chosen.append(fit_gate(subset, score_only.q))
        return chosen[-1]

    cv = cross_validated_exact(maps, folds=FOLDS, refit=refit)
    print(f"{FOLDS}-fold cross-validated (gate refitted without each fold): {cv.sum()}/{len(maps)}; the folds chose "
          + ", ".join(f"({np.log(g.tau):.2f}, {g.agreement:g})" for g in chosen))
    rules = {f"S > {rule[0]:g}" + (f" and A > {rule[1]:g}" if len(rule) == 2 else ""):
             exact(maps, RatioThresholds(score_only.q, float(np.exp(rule[0])), rule[1] if len(rule) == 2 else None))
             for rule in args.rule}
    for cell in CELLS:
        inside = np.array([m.cell == cell.name for m in maps])
        print(f"  {cell.name}: score only {before[inside].sum()}/{inside.sum()}, gate {after[inside].sum()}, "
              f"cross-validated {cv[inside].sum()}"
              + "".join(f", {label} {right[inside].sum()}" for label, right in rules.items()))
    for label, right in rules.items():
        print(f"{label}: {right.sum()}/{len(maps)} ({np.sum(right & ~before)} fixed, {np.sum(before & ~right)} broken)")
    provenance = {"name": "gated", "script": "lab/fit_agreement_gate.py", "suite": SUITE,
                  "pipeline": shipped.provenance_.get("pipeline"), "held_out_family": HELD_OUT_FAMILY,
                  "score_only": {"q": score_only.q, "tau": score_only.tau},
                  "tuning_cases_per_cell": args.per_cell, "sparse_tuning_cases_per_cell": args.sparse_per_cell,
                  "tuning_maps": len(maps), "tuning_exact": float(after.mean()),
                  "score_only_tuning_exact": float(before.mean()), "cross_validated_exact": float(cv.mean()),
                  "swarmtopo": __version__}
    model = calibrated_classifier(maps, gate, provenance, refit=lambda subset: fit_gate(subset, score_only.q))
    model.save(TARGET)
    print(f"confidence: {json.dumps(model.calibration_['1'])}")
    print(f"wrote {TARGET.relative_to(ROOT)} in {(time.perf_counter() - started) / 60:.1f} min")


def report_veto(score_only: RatioThresholds, maps) -> None:
    """``--veto``: fit b with the default's (q_1, tau_1) and print it against the score alone."""
    veto = fit_veto(maps, score_only)
    before, after = exact(maps, score_only), exact(maps, veto)
    chosen = []

    def refit(subset):
        chosen.append(fit_veto(subset, score_only))
        return chosen[-1]

    cv = cross_validated_exact(maps, folds=FOLDS, refit=refit)
    print(f"{len(maps)} tuning maps; score only (q {score_only.q:g}, tau {score_only.tau:g}): {before.sum()}; "
          f"veto b = {veto.agreement:g}: {after.sum()} ({np.sum(after & ~before)} fixed, {np.sum(before & ~after)} "
          f"broken); {FOLDS}-fold cross-validated {cv.sum()}; the folds chose "
          + ", ".join(f"{g.agreement:g}" for g in chosen))
    for cell in CELLS:
        inside = np.array([m.cell == cell.name for m in maps])
        print(f"  {cell.name}: score only {before[inside].sum()}/{inside.sum()}, veto {after[inside].sum()}, "
              f"cross-validated {cv[inside].sum()}")
    counts = veto_right(maps, score_only).sum(axis=0)
    print("tuning count by b: " + ", ".join(f"{b:g}: {n}" for b, n in zip(B_GRID, counts) if b >= 0.6))


if __name__ == "__main__":
    main()
