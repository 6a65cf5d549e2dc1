"""Fit swarmtopo's default classifier on the benchmark's tuning cases, and record the candidates.

Runs the tuning cases (``swarmtopo.experiments.accuracy.tuning_jobs``: the suite's
tuning seeds, never the held-out hole family, never a reporting seed -- the whole
script runs inside ``tuning_session``) under every candidate pipeline of
``CANDIDATES`` on Dask (resumable store), fits the ratio classifier's (q_1,
tau_1) for each candidate and each way of pooling windows (``POOLINGS``: mean scores,
or the lower median of the windows' counts) on its stored per-window diagrams, and
writes

* ``src/swarmtopo/data/classifier-default.json``: the classifier of the ``CHOSEN``
  candidate and pooling, its confidence calibrated on the tuning maps (cross-fitted)
  and on the calibration grid (``experiments.accuracy.calibration_jobs``: the planning
  grid's swarm sizes, durations and arenas with seeds of their own, mapped by the
  default pipeline), so that it holds beyond the suite's budgets;
* ``src/swarmtopo/data/classifier-trace.json``: the same for ``CHOSEN_TRACE``, the
  chosen pipeline reading the tuning cases as contact traces (encounters only), which
  ``map`` uses for a log without status changes; its confidence is calibrated on the
  calibration grid read as contact traces too;
* ``docs/tuning.md``: every candidate's tuning accuracy (ratio classifier and the
  ``paper`` classifier), so what did not help is on record.

The chosen candidate is declared, not the highest count of this run: each job's maps
come from one landmark draw (its seed derives from the job), and on the sparsest cells
one draw moves the count of a candidate by several maps.  The choice rests on
``lab/levers.py`` with several draws per tuning case (docs/accuracy.md); this
run fits the chosen classifier and puts the rest on record.  The chosen pipeline's
options are the defaults of ``MapConfig``; the script stops with an error if they differ.

``--calibrate-only [default] [trace]`` maps only the named classifiers' candidates
(both when none is named) on the tuning cases and the calibration grid, stops unless
they give the shipped thresholds, and rewrites those classifiers' confidence alone.

``--regions-only [default] [trace]`` maps only the tuning cases of the cells whose arenas
have several regions (two rooms) and refits only the named classifiers'
``regions_exponent`` (:meth:`~swarmtopo.readers.ratio.RatioClassifier.map_confidence`), reading those maps with
the shipped thresholds and regional model: what the full and ``--calibrate-only`` runs
fit last.  Either way the script prints the several-region maps' Brier score and log
loss under the plain product, the power a cross-fitted over 10 folds, and a constant.

Usage::

    python lab/tune_accuracy.py [--store tuning.duckdb] [--per-cell 20] [--workers N] [--scheduler ADDR]
                                    [--calibrate-only [default] [trace] | --regions-only [default] [trace]]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from swarmtopo import __version__
from swarmtopo.readers.registry import load_classifier
from swarmtopo.experiments.accuracy import (CELLS, HELD_OUT_FAMILY, PLANNING_CELLS, SUITE, TUNING_PER_CELL, calibration_jobs,
                                           cell_of, tuning_jobs, tuning_session)
from swarmtopo.experiments.store import job_rows
from swarmtopo.experiments.sweep import job_map_config, map_input, run_sweep
from tuning import (PIPELINE_FIELDS, calibrated_classifier, cross_validated, exact, fit_regions_exponent,
                    fit_thresholds, maps_from_rows, regions_exponent_scores, several_region_products,
                    with_regions_exponent)
from swarmtopo.pipeline import MapConfig
from swarmtopo.readers.ratio import POOLINGS, Q_GRID, REGIONS_EXPONENT, TAU_GRID, confidence_readout

ROOT = Path(__file__).resolve().parent.parent

OURS = {"hop_cost": "auto", "diffusion_time": "auto", "wall_follow_weight": 2.0, "window_length": "auto",
        "window_encounters": 20.0, "window_step": "auto"}
THREE_LENGTHS = {**OURS, "window_scales": [0.75, 1.0, 1.25]}
BANDED = "the first, landmarks also from each window's middle half (landmark bands 1 and 0.5)"
CANDIDATES = {
    "h auto, diffusive, wall following x 2, windows of 15, 20 and 25 encounters per agent": THREE_LENGTHS,
    BANDED: {**THREE_LENGTHS, "landmark_bands": [1.0, 0.5]},
    "the first, reading a contact trace (encounters only: h from the data, no wall following)": {
        **THREE_LENGTHS, "input": "contact-trace"},
}
"""Candidate pipelines (hybrid metric, maxmin, automatic landmarks); "auto" h is
r_d / v_c = 2 s for the simulated swarms; "diffusive" is the automatic diffusion time
(``DIFFUSION_GAP_FACTOR`` x the mean time between an agent's encounters; the factor was
chosen on tuning cases with ``lab/levers.py``); "wall following x 2" charges an
agent's wall-following time 2 s per second outside the diffusive weights
(``MapConfig.wall_follow_weight``).  "Landmark bands 1 and 0.5" maps every window twice,
its landmarks drawn from the whole window and from its middle half
(``MapConfig.landmark_bands``; the others draw from the whole window only, the
contact-trace one too, so its classifier reads traces so).  Windows of K encounters
per agent are K times the mean time between an agent's encounters long (``MapConfig.window_encounters``); windows
of several K are pooled together (``MapConfig.window_scales``: K = 20 x each scale).
Candidates of earlier rounds (wall-following weights 1.5 and none, K = 25, fixed 20 s
windows, the whole log with h, h = 0 with windows, windows of 20 encounters per agent
only, the paper's metric on the whole log) are in docs/tuning.md's git history and in
docs/accuracy.md."""


CHOSEN = (BANDED, "mean")
"""The default pipeline and pooling (chosen on tuning cases: docs/accuracy.md)."""
CHOSEN_TRACE = ("the first, reading a contact trace (encounters only: h from the data, no wall following)", "mean")
"""The default pipeline on logs without status changes (real contact traces): its own
thresholds and calibration, the ``trace`` classifier, fitted on the same tuning cases
read as contact traces (``experiments.sweep.contact_trace``)."""
SHIPPED = {"default": CHOSEN, "trace": CHOSEN_TRACE}
"""The classifier files this script writes, and the candidate and pooling each is fitted on."""
CV_FOLDS = 4
"""Folds of the cross-validated count printed beside each fitted one (thresholds refitted without each fold)."""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--store", default="tuning.duckdb")
    parser.add_argument("--per-cell", type=int, default=TUNING_PER_CELL)
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--scheduler", default=None)
    parser.add_argument("--calibrate-only", nargs="*", choices=tuple(SHIPPED), metavar="CLASSIFIER",
                        help="map only these classifiers' candidates (default and trace when none is named) on the "
                             "tuning cases and the calibration grid, check that they give the shipped thresholds "
                             "and rewrite the classifiers' confidence (docs/tuning.md is left as it is)")
    parser.add_argument("--regions-only", nargs="*", choices=tuple(SHIPPED), metavar="CLASSIFIER",
                        help="map only the several-region tuning cells for these classifiers (default and trace when "
                             "none is named) and refit only their regions_exponent")
    args = parser.parse_args()
    if args.regions_only is not None:
        if args.calibrate_only is not None:
            parser.error("--regions-only and --calibrate-only exclude each other")
        _refit_regions_exponent(args)
        return

    started = time.perf_counter()
    calibrate_only = args.calibrate_only is not None
    shipping = tuple(dict.fromkeys(args.calibrate_only or SHIPPED))  # the classifier files written
    candidates = [SHIPPED[n][0] for n in shipping] if calibrate_only else list(CANDIDATES)
    with tuning_session():
        pipelines = {name: _candidate_pipeline(name) for name in candidates}
        jobs = {name: tuning_jobs({name: p}, per_cell=args.per_cell) for name, p in pipelines.items()}
        # each classifier's grid is read as its candidate reads the tuning cases (log folder or contact trace)
        grids = {n: calibration_jobs(reading=map_input(CANDIDATES[SHIPPED[n][0]])) for n in shipping}
        every = [j for js in (*jobs.values(), *grids.values()) for j in js]
        summary = run_sweep(every, args.store, scheduler=args.scheduler, workers=args.workers, keep="windows",
                            progress=lambda done, total, failed: print(f"\r{done}/{total} jobs", end="", flush=True))
        print(f"\n{summary}")
        stored = {row["key"]: row for row in job_rows(args.store, every)}
        rows = {name: [stored[j.key] for j in sorted(js, key=lambda j: j.key) if j.key in stored]
                for name, js in jobs.items()}
        grid_maps = {n: maps_from_rows([stored[j.key] for j in sorted(grid, key=lambda j: j.key) if j.key in stored],
                                       lambda config: cell_of(config, PLANNING_CELLS))
                     for n, grid in grids.items()}
        results = {}
        for name, candidate_rows in rows.items():
            maps = maps_from_rows(candidate_rows, cell_of)
            paper = [r["error"] is None and r["est_betti0"] == r["true_betti0"]
                          and r["est_betti1"] == r["true_betti1"] for r in candidate_rows]
            for pooling in [SHIPPED[n][1] for n in shipping if SHIPPED[n][0] == name] if calibrate_only else POOLINGS:
                fit = fit_thresholds(maps, pooling)
                right = exact(maps, fit.thresholds, pooling)
                cv = None if calibrate_only else cross_validated(maps, pooling, CV_FOLDS)
                per_cell = {c.name: _rate([ok for m, ok in zip(maps, right) if m.cell == c.name]) for c in CELLS}
                results[(name, pooling)] = {
                    "fit": fit, "maps": maps, "right": int(right.sum()), "cv": cv, "total": len(candidate_rows),
                    "failed": len(candidate_rows) - len(maps), "per_cell": per_cell,
                    "paper": int(sum(paper)),
                    "seconds": float(np.mean([r["t_total"] for r in candidate_rows]))}
                cv_text = "" if cv is None else f" ({CV_FOLDS}-fold CV {cv})"
                print(f"{name}, {pooling} pooling: {fit.thresholds}: {right.sum()}/{len(candidate_rows)}{cv_text}; "
                      f"paper classifier {sum(paper)}/{len(candidate_rows)}")
    defaults, chosen_config = MapConfig(), job_map_config(jobs[SHIPPED[shipping[0]][0]][0].config["map"])
    # landmark_bands None: the bands the shipped classifier was fitted with, which this script writes
    resolved = {"landmark_bands": chosen_config.landmark_bands} if defaults.landmark_bands is None else {}
    mismatch = {k: (getattr(defaults, k), getattr(chosen_config, k)) for k in PIPELINE_FIELDS
                if resolved.get(k, getattr(defaults, k)) != getattr(chosen_config, k)}
    if mismatch:
        raise SystemExit(f"MapConfig defaults differ from the chosen pipeline: {mismatch}; update swarmtopo/pipeline.py")
    for name in shipping if calibrate_only else ():
        fitted, shipped = results[SHIPPED[name]]["fit"].thresholds, load_classifier(name).thresholds_[1]
        if fitted != shipped:
            raise SystemExit(f"the tuning maps give {fitted} for {name}, the shipped classifier has {shipped}: "
                             "run without --calibrate-only to refit the classifiers")
    for name in shipping:
        key = SHIPPED[name]
        chosen = results[key]
        model = calibrated_classifier(chosen["maps"], chosen["fit"].thresholds, provenance={
            "name": name, "script": "lab/tune_accuracy.py", "suite": SUITE, "pipeline": CANDIDATES[key[0]],
            "tuning_cases_per_cell": args.per_cell, "held_out_family": HELD_OUT_FAMILY,
            "tuning_maps": chosen["total"], "tuning_exact": chosen["right"] / chosen["total"], "swarmtopo": __version__},
            pooling=chosen["fit"].pooling, beyond=grid_maps[name])
        model.save(ROOT / "src" / "swarmtopo" / "data" / f"classifier-{name}.json")
        print(f"classifier-{name}.json: confidence {model.calibration_['1']} "
              f"({len(grid_maps[name])} calibration-grid maps); {confidence_readout(model)}")
        _print_regions_scores(name, *several_region_products(chosen["maps"], model), model)
    if calibrate_only:
        print(f"wrote the confidence of {', '.join(f'classifier-{n}.json' for n in shipping)} "
              f"({(time.perf_counter() - started) / 60:.1f} min)")
        return
    job_minutes = sum(r["t_total"] for candidate_rows in rows.values() for r in candidate_rows) / 60
    trace, default_thresholds = results[CHOSEN_TRACE], results[CHOSEN]["fit"].thresholds
    transfer = exact(trace["maps"], default_thresholds, CHOSEN_TRACE[1])
    print(f"contact traces read with the default's thresholds {default_thresholds}: {transfer.sum()}/{trace['total']}")
    _write_doc(results, (CHOSEN, CHOSEN_TRACE), args, time.perf_counter() - started, summary, job_minutes,
               transfer=(default_thresholds, int(transfer.sum()), trace["total"]))
    print(f"chosen: {CHOSEN[0]}, {CHOSEN[1]} pooling; for contact traces: {CHOSEN_TRACE[0]}, {CHOSEN_TRACE[1]} "
          "pooling; wrote classifier-default.json, classifier-trace.json and docs/tuning.md")


def _refit_regions_exponent(args) -> None:
    """``--regions-only``: map the several-region tuning cells and refit the named shipped
    classifiers' regions_exponent alone."""
    started = time.perf_counter()
    shipping = tuple(dict.fromkeys(args.regions_only or SHIPPED))
    several = [c for c in CELLS if c.generator == "two_rooms"]
    with tuning_session():
        jobs = {n: tuning_jobs({SHIPPED[n][0]: _candidate_pipeline(SHIPPED[n][0])}, per_cell=args.per_cell,
                               cells=several)
                for n in shipping}
        every = [j for js in jobs.values() for j in js]
        summary = run_sweep(every, args.store, scheduler=args.scheduler, workers=args.workers, keep="windows",
                            progress=lambda done, total, failed: print(f"\r{done}/{total} jobs", end="", flush=True))
        print(f"\n{summary}")
        stored = {row["key"]: row for row in job_rows(args.store, every)}
        for name in shipping:
            maps = maps_from_rows([stored[j.key] for j in sorted(jobs[name], key=lambda j: j.key) if j.key in stored],
                                  cell_of)
            model = load_classifier(name)
            log_products, right = several_region_products(maps, model)
            try:
                a = fit_regions_exponent(log_products, right)
            except ValueError as exc:
                raise SystemExit(f"{len(right)} several-region tuning maps for {name}, {int(right.sum())} of them "
                                 f"right: {exc}") from None
            with_regions_exponent(model, a, len(right))
            model.save(ROOT / "src" / "swarmtopo" / "data" / f"classifier-{name}.json")
            _print_regions_scores(name, log_products, right, model)
    print(f"wrote the regions_exponent of {', '.join(f'classifier-{n}.json' for n in shipping)} "
          f"({(time.perf_counter() - started) / 60:.1f} min)")


def _candidate_pipeline(name: str) -> dict:
    """The job pipeline of candidate ``name`` (CANDIDATES): hybrid metric, the ``paper`` classifier's readings."""
    return {"metric": "hybrid", "classifier": "paper", **CANDIDATES[name]}


def _print_regions_scores(name: str, log_products, right, model) -> None:
    """The several-region maps' confidence scores (:func:`regions_exponent_scores` of
    :func:`several_region_products`' output), as docs/accuracy.md quotes them."""
    try:
        scores = regions_exponent_scores(log_products, right)
    except ValueError as exc:
        print(f"classifier-{name}.json: {exc}")
        return
    print(f"classifier-{name}.json: regions_exponent {model.calibration_['1'][REGIONS_EXPONENT]:.4f} on "
          f"{len(right)} several-region maps ({int(right.sum())} right; the plain product says "
          f"{np.exp(log_products).mean():.3f} on average); "
          + "; ".join(f"{k}: Brier {v['brier']:.4f}, log loss {v['log_loss']:.4f}" for k, v in scores.items()))


def _rate(flags) -> tuple[int, int]:
    return int(sum(flags)), len(flags)


def _write_doc(results, chosen, args, seconds, summary, job_minutes, transfer) -> None:
    lines = [
        "# Tuning the default pipeline",
        "",
        "Generated by `python lab/tune_accuracy.py"
        + (f" --per-cell {args.per_cell}" if args.per_cell != TUNING_PER_CELL else "") + "` "
        f"({seconds / 60:.1f} min; {summary.run} jobs run now, {summary.skipped} reused from the store; the jobs took "
        f"{job_minutes:.0f} CPU-min in all, as recorded in the store). "
        f"Tuning cases only (suite `{SUITE}`, {args.per_cell} per cell, no {HELD_OUT_FAMILY}-shaped holes); "
        "the reporting cases are closed to this script (`tuning_session`). "
        "For every candidate pipeline and each way of pooling its windows (mean: the mean over windows of each "
        "rank's score ln(l / l_q); median: the lower median of the windows' counts) the ratio classifier's "
        f"(q_1, tau_1) is fitted on that candidate's maps, q in {list(Q_GRID)} x {len(TAU_GRID)} tau from "
        f"{TAU_GRID[0]} to {TAU_GRID[-1]}, at the best grid point after averaging each with its two tau "
        f"neighbours; the {CV_FOLDS}-fold column refits the thresholds without each fold and counts the fold's "
        "maps. The paper column is the same maps read by the paper's classifier form trained the paper's way "
        "(`paper` preset), windows voted by the lower median. The chosen row is declared in the script "
        "(`CHOSEN`), not this run's highest count: each map here is one landmark draw, and the choice was made "
        "on tuning cases over three draws each (docs/accuracy.md). The same pipeline reading the cases as contact "
        "traces (`CHOSEN_TRACE`: encounters only, so h from the data and no wall following) gives the classifier "
        "of logs without status changes (`trace`).",
        "",
        "| candidate | pooling | q_1 | tau_1 | exact | exact, 4-fold cross-validated | exact, paper classifier "
        "| worst cell | s per map |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    ranked = sorted(results, key=lambda key: (-results[key]["right"], -results[key]["cv"]))
    for key in ranked:
        r = results[key]
        worst = min(r["per_cell"].items(), key=lambda item: item[1][0] / max(item[1][1], 1))
        mark = ({chosen[0]: " **(chosen)**", chosen[1]: " **(chosen for contact traces)**"}).get(key, "")
        th = r["fit"].thresholds
        lines.append(f"| {key[0]}{mark} | {key[1]} | {th.q:g} | {th.tau:g} | {r['right']}/{r['total']} = "
                     f"{r['right'] / r['total']:.2f} | {r['cv']}/{r['total']} = {r['cv'] / r['total']:.2f} | "
                     f"{r['paper']}/{r['total']} = {r['paper'] / r['total']:.2f} | "
                     f"{worst[0]}: {worst[1][0]}/{worst[1][1]} | {r['seconds']:.2f} |")
    th, right, total = transfer
    lines += ["", f"The contact-trace candidate's maps read with the default's thresholds (q_1 = {th.q:g}, "
                  f"tau_1 = {th.tau:g}) instead of their own: {right}/{total} = {right / total:.2f} exact."]
    lines += ["", "Exact maps per cell, every candidate and pooling (ratio classifier, its fitted thresholds):", "",
              "| cell | " + " | ".join(f"{name}, {pooling}" for name, pooling in ranked) + " |",
              "|---" * (len(ranked) + 1) + "|"]
    lines += [f"| {c.name} | " + " | ".join("{}/{}".format(*results[key]["per_cell"][c.name]) for key in ranked) + " |"
              for c in CELLS]
    lines.append("")
    (ROOT / "docs" / "tuning.md").write_text("\n".join(lines), encoding="utf-8")


if __name__ == "__main__":
    main()
