"""The paper's Fig. "clust": training the Betti classifier and testing it across scale
and number of holes, as Dask sweeps (``swarmtopo reproduce clust``).

Paper: Theta*_1 fitted on 100 random placements of two square holes in the square
environment (F(Theta*_1) = 0.03 with Theta*_1 = (0.5, 0.7, 3.7)); tested on sets of 100
environments scaled by 0.75, 0.9, 1, 1.1, 1.25 and with 0, 1, 2, 3 holes; sensitivity
degrades for three holes (the third hole missed in 15 % of the cases).

Settings the paper leaves open, fixed here (:data:`CLUST_MAP`, :data:`CLUST_SWARM`):
200 agents for 30 s in the 500 mm square with 125 mm square holes, the contracted
metric (the paper's best without static nodes), maxmin, L = 300 landmarks.  Both
optimizers are fitted on the training set; F, SE and the false-hole rate are reported
on every test set for both and for the paper's published Theta*.

Beside them, swarmtopo's default pipeline (``DEFAULT_MAP``: the accuracy benchmark's
``default``, read with its shipped classifier, nothing fitted here) maps the same test
environments: each of its jobs shares its arena and simulation with the paper's job
(``Job.case_seed``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable

import numpy as np

from .._validate import positive_int
from ..readers.paper import detection_scores, published_paper_classifier
from .accuracy import PIPELINES
from .grid import Job, canonical_json, expand_grid
from .store import read_jobs
from .sweep import SUITE_MAP, build_arena, run_sweep
from .reproduction import output_folder, write_reproduction
from .training import Examples, examples_from_rows, fit_and_select

SCALES = (0.75, 0.9, 1.0, 1.1, 1.25)
HOLES = (0, 1, 2, 3)
RUNS = 100
"""Environments per set (paper: 100)."""
CLUST_SWARM = {"agents": 200, "duration": 30.0}
CLUST_MAP = {"metric": "contracted", "hop_cost": 0.0, "diffusion_time": "none", "wall_follow_weight": "none",
             "window_length": "none", "subsample": "maxmin", "landmarks": 300, "classifier": "paper"}
CLUST_ARENA = {"generator": "random", "shapes": "square", "outer": "square"}
DEFAULT_MAP = {**SUITE_MAP, **PIPELINES["default"]}
"""The ``[map]`` table of the default pipeline's column."""
DEFAULT_COLUMN = "default pipeline"


def clust_sweeps(runs: int = RUNS) -> dict[str, Any]:
    """The training sweep and the two test sweeps (a job in both test sets runs once)."""
    def sweep(name, salt, **arena):
        return expand_grid({"sweep": {"name": name, "salt": salt, "replicates": runs},
                            "arena": {**CLUST_ARENA, **arena}, "swarm": CLUST_SWARM, "map": CLUST_MAP})
    return {
        "train": sweep(f"clust-train-{runs}", "clust-train", holes=2, scale=1.0),
        "scale": sweep(f"clust-scale-{runs}", "clust-test", holes=2, scale=list(SCALES)),
        "holes": sweep(f"clust-holes-{runs}", "clust-test", holes=list(HOLES), scale=1.0),
    }


def default_jobs(paper_jobs) -> list[Job]:
    """The default pipeline's job of each of ``paper_jobs``: its arena and swarm, mapped by
    ``DEFAULT_MAP``, simulating the same arena and swarm (``case_seed``: the paper job's
    seed, whose first two streams are its arena and simulation)."""
    return [Job(sweep=f"{job.sweep}-default", config_json=canonical_json({**job.config, "map": DEFAULT_MAP}),
                replicate=job.replicate, salt=job.salt, case_seed=job.seed) for job in paper_jobs]


def reproduce_clust(out: Path, *, runs: int | None = None, progress: Callable[[int, int, int], None] | None = None,
                    store: Path | None = None, workers: int | None = None, scheduler: str | None = None):
    """Run the sweeps, fit, test, and write ``clust.csv`` and the figures into ``out``."""
    from ..viz.plots import plot_arena, plot_diagram, new_figure, plot_ratio_density, plot_scores_by

    runs = RUNS if runs is None else positive_int("runs", runs)
    out = output_folder(out)
    store = Path(store) if store else out / "clust.duckdb"
    sweeps = clust_sweeps(runs)
    defaults = {name: default_jobs(sweeps[name].jobs) for name in ("scale", "holes")}
    everything = [job for s in sweeps.values() for job in s.jobs] + [job for js in defaults.values() for job in js]
    summary = run_sweep(everything, store, workers=workers, scheduler=scheduler, progress=progress)
    by_key = {row["key"]: row for row in read_jobs(store, keys=[job.key for job in everything])}
    rows = {name: [by_key[key] for key in sorted(job.key for job in s.jobs)] for name, s in sweeps.items()}
    default_rows = {name: [by_key[job.key] for job in js] for name, js in defaults.items()}
    train = examples_from_rows(rows["train"])

    selection = fit_and_select(train, _test_pool(rows), {"name": "clust", "runs": runs})
    models = {**selection.fits, "paper": published_paper_classifier()}

    test_sets = _test_sets(rows)
    table: list[dict[str, Any]] = []
    for name, model in models.items():
        th = model.theta_[1]
        train_f = detection_scores(model.predict(train.diagrams), train.truth).mean_absolute_error
        for label, subset in test_sets:
            estimates = model.predict(subset.diagrams)
            scores = detection_scores(estimates, subset.truth)
            row = {"classifier": name, "q": th.q, "delta": th.delta, "tau": th.tau, "train_F": train_f,
                   "test_set": label, "maps": scores.maps, "F": scores.mean_absolute_error,
                   "SE": scores.sensitivity, "false_hole_rate": scores.false_hole_rate, "exact": scores.exact,
                   "excluded": sum(subset.excluded.values())}
            if label == "holes=3":
                row["third_hole_missed"] = float(np.mean(estimates < 3))
            table.append(row)
    for label, subset in _default_sets(default_rows):
        ok = [r for r in subset if r["status"] == "ok"]
        estimates = np.array([r["est_betti1"] for r in ok])
        scores = detection_scores(estimates, [r["true_betti1"] for r in ok])
        row = {"classifier": DEFAULT_COLUMN, "q": None, "delta": None, "tau": None, "train_F": None,
               "test_set": label, "maps": scores.maps, "F": scores.mean_absolute_error, "SE": scores.sensitivity,
               "false_hole_rate": scores.false_hole_rate, "exact": scores.exact,
               "excluded": len(subset) - len(ok)}
        if label == "holes=3":
            row["third_hole_missed"] = float(np.mean(estimates < 3))
        table.append(row)

    winner = selection.classifier
    fig = new_figure(16, 3.4)
    axes = fig.subplots(1, 5)
    example = next(r for r in rows["train"] if r["error"] is None)
    job = next(j for j in sweeps["train"].jobs if j.key == example["key"])
    plot_arena(build_arena(job.config["arena"], job.stream_seeds()["arena"]), ax=axes[0],
               title="(a) a training environment")
    dgm = example["diagrams"][0]["diagram"]
    plot_diagram(dgm, ax=axes[1], thresholds=winner.thresholds(dgm), title="(b) its diagram")
    plot_ratio_density(train.diagrams, train.truth, winner.theta_[1], ax=axes[2],
                       title="(c) scaled interval lengths, training set")
    for ax, key, values, title in ((axes[3], "scale", SCALES, "(d) SE vs scale (2 holes)"),
                                   (axes[4], "holes", HOLES, "(e) SE vs holes (scale 1)")):
        series = {name: [next(r["SE"] for r in table if r["classifier"] == name and r["test_set"] == f"{key}={v:g}")
                         for v in values] for name in [*models, DEFAULT_COLUMN]}
        plot_scores_by(values, series, ax=ax, xlabel=key, ylabel="SE", title=title)
    figure = out / "clust.png"
    fig.savefig(figure, dpi=100)

    summary_numbers = {
        "jobs": summary.total, "jobs_run": summary.run, "seconds": summary.seconds, "workers": summary.workers,
        "jobs_per_minute": summary.jobs_per_minute if summary.run else None,
        "winner": selection.winner,
        "theta": {name: model.theta_[1].to_json() for name, model in models.items()},
        "train_F": {r["classifier"]: r["train_F"] for r in table if r["test_set"] == "scale=1" and r["train_F"] is not None},
        "third_hole_missed": {r["classifier"]: r["third_hole_missed"] for r in table if r["test_set"] == "holes=3"},
    }
    settings = {"runs": runs, "arena": CLUST_ARENA, "swarm": CLUST_SWARM, "map": CLUST_MAP, "default_map": DEFAULT_MAP,
                "scales": SCALES, "holes": HOLES, "store": str(store),
                "sweeps": {name: s.name for name, s in sweeps.items()}}
    headers = ["classifier", "test set", "maps", "F", "SE", "false holes", "exact"]
    cells = [[r["classifier"], r["test_set"], r["maps"], f"{r['F']:.3f}", f"{r['SE']:.3f}",
              f"{r['false_hole_rate']:.3f}", f"{r['exact']:.3f}"] for r in table]
    return write_reproduction("clust", out, table, headers, cells, [figure], summary_numbers, settings)


def _test_sets(rows) -> list[tuple[str, Examples]]:
    sets = []
    for key, values, column in (("scale", SCALES, "scale"), ("holes", HOLES, "holes")):
        for v in values:
            subset = [r for r in rows[key] if r[column] == v]
            sets.append((f"{key}={v:g}", examples_from_rows(subset)))
    return sets


def _default_sets(rows) -> list[tuple[str, list[dict[str, Any]]]]:
    """The default pipeline's rows per test set (labels as :func:`_test_sets`')."""
    return [(f"{key}={v:g}", [r for r in rows[key] if r[key] == v])
            for key, values in (("scale", SCALES), ("holes", HOLES)) for v in values]


def _test_pool(rows) -> Examples:
    """Every test map once (the shared 2-hole, scale-1 set counted once)."""
    unique = {r["key"]: r for key in ("scale", "holes") for r in rows[key]}
    return examples_from_rows(list(unique.values()))
