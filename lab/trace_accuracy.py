"""The accuracy benchmark's reporting cases mapped as contact traces: encounters only.

A real contact trace has no status changes (so no wall following and no stops), no
sensing radius and no speeds: the default pipeline then takes its hop cost, windows and
diffusion time from the encounters themselves (docs/accuracy.md, "Real traces").  This
maps the benchmark's reporting cases that way (``experiments.sweep.contact_trace``) with
the default pipeline, as a Dask sweep into a resumable store.  Read by the shipped
``trace`` classifier (what ``map`` uses for a log without status changes, fitted on
tuning cases only) or by any shipped classifiers named, it prints exact (beta_0,
beta_1) per cell with Wilson 95 % intervals, the held-out family, and the Brier score
of the beta_1 confidence.  Given the store of a ``swarmtopo bench accuracy`` run of the
same cases (``--compare``), it prints the full log folders' figures beside them and the
maps each reading alone gets right.  ``--planning`` also maps the planning grid's cases
(100-800 agents x 15-120 s, beyond the suite's budgets) as contact traces and prints,
per classifier, the beta_1 confidence's reliability there (as ``reclassify.py
--planning``): the trace classifier's confidence is fitted on the calibration grid read
the same way, never on these cases.

``--plan-out`` (with ``--planning``) fits ``swarmtopo plan``'s model on the contact
traces, the reporting and planning-grid maps read by the trace classifier, as the full
``swarmtopo bench accuracy`` fits it on log folders; the shipped
``src/swarmtopo/data/plan-trace.json`` is this file (``plan --input contact-trace``).

    python lab/trace_accuracy.py --store trace.duckdb [--compare full.duckdb] [--quick] [--planning]
                                        [--classifier trace default] [--plan-out plan-trace.json]
"""

from __future__ import annotations

import argparse
import sys
import time

from reclassify import planning_summary
from swarmtopo.readers.registry import load_classifier
from swarmtopo.experiments.accuracy import (CELLS, PIPELINES, PLANNING_CELLS, QUICK_PER_CELL, REPORTING_PER_CELL,
                                            TRACE_PIPELINE, accuracy_table, beta1_misses, most_windows, outcomes,
                                            planning_jobs, rate_text, reliability, reporting_jobs)
from swarmtopo.experiments.store import job_rows
from swarmtopo.experiments.sweep import run_sweep
from swarmtopo.io.logs import write_json
from swarmtopo.experiments.plan import fit_plan


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--store", required=True, help="DuckDB store of this benchmark (resumable)")
    parser.add_argument("--compare", help="store of `swarmtopo bench accuracy` on the same cases")
    parser.add_argument("--quick", action="store_true", help=f"{QUICK_PER_CELL} cases per cell, "
                                                             f"not {REPORTING_PER_CELL}")
    parser.add_argument("--workers", type=int, help="local Dask workers (default: one per core)")
    parser.add_argument("--classifier", nargs="+", default=["trace"],
                        help="shipped classifiers to read the contact traces' maps with (default: trace, what "
                             "`map` uses for a log without status changes)")
    parser.add_argument("--planning", action="store_true",
                        help="also map the planning grid as contact traces and print the confidence's reliability there")
    parser.add_argument("--plan-out", help="with --planning: write the plan model of contact traces, fitted on the "
                                           "reporting and planning-grid traces read by the trace classifier, here "
                                           "(the shipped one is src/swarmtopo/data/plan-trace.json)")
    args = parser.parse_args()
    if args.plan_out and (not args.planning or args.quick):
        parser.error("--plan-out needs --planning (the grid tells swarm size from duration) and the full suite")
    per_cell = QUICK_PER_CELL if args.quick else REPORTING_PER_CELL
    jobs = reporting_jobs(per_cell, pipelines={"contact-trace": TRACE_PIPELINE})
    grid = planning_jobs(reading="contact-trace") if args.planning else []
    start = time.perf_counter()
    summary = run_sweep(jobs + grid, args.store, workers=args.workers, keep="windows")
    print(f"{len(jobs)} contact-trace maps ({per_cell} per cell) and {len(grid)} of the planning grid, "
          f"{summary.run} run in {(time.perf_counter() - start) / 60:.1f} min on {summary.workers} Dask workers")
    rows = job_rows(args.store, jobs)  # each job's stored diagrams, read by each classifier (whatever the job ran)
    print(f"at most {most_windows(rows)} windows per region")
    columns = {f"contact trace, {name} classifier": outcomes(rows, load_classifier(name)) for name in args.classifier}
    if args.compare:
        full = job_rows(args.compare, reporting_jobs(per_cell, pipelines={"default": PIPELINES["default"]}))
        columns["full log folder, default classifier (docs/accuracy.md)"] = outcomes(full, load_classifier("default"))
    tables = {name: accuracy_table(records) for name, records in columns.items()}
    print("\n| cell | " + " | ".join(columns) + " |\n|---|" + "---|" * len(columns))
    for cell in CELLS:
        print(f"| {cell.name} | " + " | ".join(rate_text(t["cells"][cell.name].to_json()) for t in tables.values())
              + " |")
    for key, label in (("overall", "**all reporting cases**"), ("held_out", "held-out family (L-shaped holes)")):
        print(f"| {label} | " + " | ".join(rate_text(t[key].to_json()) for t in tables.values()) + " |")
    for name, records in columns.items():
        rel = reliability(records, 1)
        too_many, too_few = beta1_misses(records)
        failed = sum(r["error"] is not None for r in records)
        print(f"\n{name}: beta_1 too many {too_many}, too few {too_few}, not mapped {failed}; "
              f"Brier {rel['brier']:.4f} (constant {rel['brier_constant']:.4f}); "
              f"mean {sum(r['seconds'] for r in records) / len(records):.2f} s per map")
        print("  reliability (confidence bin: maps, mean confidence said, fraction right): " + "; ".join(
            f"{b['low']:g}-{b['high']:g}: {b['maps']}, {b['mean_confidence']:.3f}, {b['fraction_right']:.3f}"
            for b in rel["bins"]))
    if args.compare:
        *traces, full = columns.values()
        full_right = {(r["cell"], r["index"]) for r in full if r["right"]}
        for name, records in zip(columns, traces):
            trace_right = {(r["cell"], r["index"]) for r in records if r["right"]}
            print(f"{name}: right only as a contact trace {len(trace_right - full_right)}, "
                  f"only with the full log folder {len(full_right - trace_right)}")
    grid_rows = job_rows(args.store, grid) if grid else []
    if grid:
        print(f"\nplanning grid read as contact traces ({len(grid_rows)} maps):")
        for name in args.classifier:
            print(planning_summary(name, outcomes(grid_rows, load_classifier(name), cells=PLANNING_CELLS)))
    if args.plan_out:  # the rows read above, the reporting outcomes too when the trace classifier was asked for
        trace = load_classifier("trace")
        reported = columns.get("contact trace, trace classifier") or outcomes(rows, trace)
        records = reported + outcomes(grid_rows, trace, cells=PLANNING_CELLS)
        command = "python lab/trace_accuracy.py " + " ".join(sys.argv[1:])
        model = fit_plan(records, source=command)
        write_json(model.to_json(), args.plan_out)
        print(f"\nwrote {args.plan_out}: the plan of contact traces, fitted on {model.maps} maps: c0 = "
              f"{model.intercept:.2f}, c1 = {model.density_coef:.2f}, c2 = {model.duration_coef:.2f}, "
              f"c4 = {model.agents_coef:.2f}, c5 = {model.agents_duration_coef:.2f}, c3 = {model.holes_coef:.2f}")


if __name__ == "__main__":
    main()
