"""The accuracy benchmark: a frozen suite of simulated arenas, split once into tuning
and reporting seeds.

Suite ``SUITE`` (frozen: changing anything here is a new suite name).  Cells are 0, 1,
2 and 3 holes x the data budgets ``BUDGETS`` (agents x seconds), plus ``two rooms``
(two disjoint square rooms, 0-2 holes in all, 300 agents x 40 s).  Within a cell each
case draws, from its own seed: the family of its holes uniformly from ``HOLE_SHAPES``,
the outer wall uniformly from ``OUTER_SHAPES`` (square, rectangle, random polygon),
and the scale uniformly in [0.75, 1.25].

Seed split.  A case is (cell, split, index); its seed is the SHA-256 of
(``SUITE``, cell, split, index), so tuning and reporting cases never share a seed and
adding cases never changes old ones.  The shape family ``HELD_OUT_FAMILY`` is left
out of tuning entirely (tuning arenas draw their holes from the other four
families) and reporting cases that contain it are reported on their own line.
Tuning code runs inside :func:`tuning_session`, in which :func:`reporting_jobs`
refuses to run: defaults cannot be chosen by looking at the reported table.

Every case becomes a sweep :class:`~.grid.Job` per pipeline (``PIPELINES``: the
default and the paper's best), so the benchmark runs on Dask with a resumable DuckDB
store like any sweep, and each job maps a log folder stripped of ground truth
(:func:`~.sweep.stripped_log`).
"""

from __future__ import annotations

import json
from contextlib import contextmanager
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
from scipy.stats import bootstrap

from ..arena import HOLE_SHAPES, OUTER_SHAPES
from ..topology.cycles import wilson_interval
from ..errors import SwarmtopoError
from ..readers.paper import published_paper_classifier
from ..readers.registry import load_classifier
from ..pipeline import MapConfig
from .grid import Job, canonical_json, case_streams, suite_case_seed
from .sweep import build_arena, first_placeable

SUITE = "swarmtopo-accuracy/1"
BUDGETS: tuple[tuple[int, float], ...] = ((200, 30.0), (300, 40.0), (400, 60.0))
"""Data budgets (agents N, duration T in seconds) of the hole-count cells."""
TWO_ROOMS_BUDGET = (300, 40.0)
HELD_OUT_FAMILY = "L"
"""Hole family never seen by tuning; reported on its own line."""
SCALE_RANGE = (0.75, 1.25)
ROOM_SIDE = 500.0
"""Side (mm, before scaling) of the generators' square of equal area (their default)."""
MAX_ATTEMPTS = 20
REPORTING_PER_CELL = 30
QUICK_PER_CELL = 10
SLICE_PER_CELL = 2
"""The regression slice: the first SLICE_PER_CELL reporting cases of every cell
(default pipeline), rerun by benchmarks/bench_accuracy_slice.py against the rate recorded here."""
TUNING_PER_CELL = 96

PIPELINES: dict[str, dict[str, Any]] = {
    "default": {"metric": "hybrid", "hop_cost": "auto", "diffusion_time": "auto",
                "wall_follow_weight": MapConfig.wall_follow_weight, "window_length": "auto",
                "window_encounters": MapConfig.window_encounters, "window_scales": list(MapConfig.window_scales),
                "window_step": "auto", "landmark_bands": [1.0, 0.5], "classifier": "default"},
    "paper": {"metric": "hybrid", "hop_cost": 0.0, "diffusion_time": "none", "wall_follow_weight": "none",
              "window_length": "none", "classifier": "paper"},
}
"""The pipelines the benchmark compares: swarmtopo's default, and the best
configuration of the paper's own methods (its metric and subsampler, whole log, its
classifier form trained our way: the ``paper`` preset)."""


@dataclass(frozen=True)
class Cell:
    """One row of the table: a hole count (None: two rooms with 0-2 holes), a budget and
    the range the scale of its cases is drawn from."""

    name: str
    generator: str
    holes: int | None
    agents: int
    duration: float
    scale_range: tuple[float, float] = SCALE_RANGE


CELLS: tuple[Cell, ...] = (
    *(Cell(f"{h} holes, {n} x {t:g} s", "random", h, n, t) for h in range(4) for n, t in BUDGETS),
    Cell(f"two rooms, {TWO_ROOMS_BUDGET[0]} x {TWO_ROOMS_BUDGET[1]:g} s", "two_rooms", None, *TWO_ROOMS_BUDGET),
)

PLANNING_BUDGETS: tuple[tuple[int, float], ...] = tuple((n, t) for n in (100, 200, 400, 800) for t in (15.0, 30.0, 60.0, 120.0))
"""Budgets of the planning grid: swarm size and duration each varied on its own, which
the suite's budgets (both rising together) cannot tell apart."""
PLANNING_SCALE_RANGE = (0.75, 2.0)
"""Scales of the planning grid's arenas: areas 0.14-1 m^2, so density varies on its own too."""
PLANNING_CELLS: tuple[Cell, ...] = tuple(
    Cell(f"planning: {h} holes, {n} x {t:g} s", "random", h, n, t, PLANNING_SCALE_RANGE)
    for h in range(4) for n, t in PLANNING_BUDGETS)
"""The planning grid: cases ``plan`` is fitted on besides the reporting cases (split
"planning", seeds of their own; all five hole families; no default is chosen on them)."""
PLANNING_PER_CELL = 3
CALIBRATION_PER_CELL = 3
"""Cases per cell of the calibration grid: the planning grid's cells with seeds of their
own (split "calibration"), on which the confidence is fitted besides the tuning maps
(``lab/tune_accuracy.py``), so that it holds for swarms and logs beyond the suite's
budgets; the planning grid then checks it on cases it was not fitted on."""

_session = {"tuning": False}


@contextmanager
def tuning_session():
    """Mark the code inside as tuning: :func:`reporting_jobs` raises there."""
    previous = _session["tuning"]
    _session["tuning"] = True
    try:
        yield
    finally:
        _session["tuning"] = previous


def case_seed(cell: Cell, split: str, index: int, attempt: int = 0) -> int:
    """64-bit seed of one case, from (SUITE, cell, split, index, attempt)."""
    return suite_case_seed(SUITE, cell.name, split, index, attempt)


def case_arena(cell: Cell, split: str, index: int, attempt: int = 0) -> dict[str, Any]:
    """The ``[arena]`` table of one case: generator, holes, families, outer wall, scale."""
    rng = np.random.default_rng(case_seed(cell, split, index, attempt))
    families = [s for s in HOLE_SHAPES if split == "reporting" or s != HELD_OUT_FAMILY]
    holes = int(rng.integers(0, 3)) if cell.holes is None else cell.holes
    shapes = [families[int(rng.integers(len(families)))]]  # one family for all the case's holes
    scale = float(np.round(rng.uniform(*cell.scale_range), 4))
    arena: dict[str, Any] = {"generator": cell.generator, "holes": holes, "shapes": shapes, "scale": scale}
    if cell.generator == "random":
        arena["outer"] = OUTER_SHAPES[int(rng.integers(len(OUTER_SHAPES)))]
    return arena


@lru_cache(maxsize=None)
def case(cell: Cell, split: str, index: int) -> tuple[dict[str, Any], int]:
    """(arena table, case seed) of a case whose holes fit.

    Some draws cannot hold their holes (three walls in a narrow rectangle); such a
    draw is replaced by the next attempt's, decided once by building the arena, so
    every case of the suite is a valid arena.  Cached: building arenas is the slow part.
    """
    return first_placeable(lambda attempt: (case_arena(cell, split, index, attempt),
                                            case_seed(cell, split, index, attempt)),
                           MAX_ATTEMPTS, f"{SUITE}: {cell.name} case {index}")


def built_case(cell: Cell, split: str, index: int):
    """(arena table, case seed, built arena, simulation stream) of case ``index`` of
    ``cell``: the arena and simulation a job of that case gets (:func:`case_streams`)."""
    table, seed = case(cell, split, index)
    streams = case_streams(seed)
    return table, seed, build_arena(table, streams["arena"]), streams["simulation"]


def tuning_arena(cell: Cell, index: int):
    """:func:`built_case` of tuning case ``index`` of ``cell``, opened inside
    :func:`tuning_session` (the benchmark scripts that simulate tuning cases themselves:
    ``lab/levers.py`` and others)."""
    with tuning_session():
        return built_case(cell, "tuning", index)


def _jobs(split: str, per_cell: int, pipelines: dict[str, dict[str, Any]], cells=CELLS) -> list[Job]:
    jobs = []
    for cell, index in ((cell, index) for cell in cells for index in range(per_cell)):
        arena, seed = case(cell, split, index)
        for name, mapping in pipelines.items():
            config = {"arena": arena, "swarm": {"agents": cell.agents, "duration": cell.duration,
                                                 "static_fraction": 0.0},
                      "map": {"subsample": "maxmin", "landmarks": "auto", "max_landmarks": MapConfig.max_landmarks,
                              "maxdim": 1, **mapping}}
            jobs.append(Job(sweep=f"accuracy-{split}-{name}", config_json=canonical_json(config),
                            replicate=index, salt=f"{SUITE}/{split}/{cell.name}", case_seed=seed))
    return jobs


def tuning_jobs(pipelines: dict[str, dict[str, Any]], per_cell: int = TUNING_PER_CELL, cells=CELLS) -> list[Job]:
    """Jobs of the tuning cases (never the held-out family) under candidate pipelines."""
    return _jobs("tuning", per_cell, pipelines, cells)


def reporting_jobs(per_cell: int = REPORTING_PER_CELL, pipelines=None, cells=CELLS) -> list[Job]:
    """Jobs of the reporting cases; refused inside a :func:`tuning_session`."""
    if _session["tuning"]:
        raise SwarmtopoError("the benchmark's reporting seeds are closed to tuning code (inside tuning_session)")
    return _jobs("reporting", per_cell, pipelines or PIPELINES, cells)


TRACE_PIPELINE = {**{k: v for k, v in PIPELINES["default"].items() if k != "landmark_bands"}, "input": "contact-trace"}
"""The default pipeline reading only a case's encounters, as a real contact trace comes
(``experiments.sweep.contact_trace``: no status changes, no r_d or speeds), with the
whole window's landmarks only: the ``trace`` classifier was fitted so (``map`` reads a
contact trace with the bands of the classifier it was fitted with)."""
READING_PIPELINES = {"log": PIPELINES["default"], "contact-trace": TRACE_PIPELINE}
"""The default pipeline per reading of a case (``experiments.sweep.INPUTS``): its log
folder, or its encounters only."""


def reading_name(reading: str) -> str:
    """The pipeline's name in the sweep names of the default pipeline's maps under
    ``reading`` ("log" -> "default", as before there were readings)."""
    if reading not in READING_PIPELINES:
        raise SwarmtopoError(f"no reading {reading!r}: one of {', '.join(READING_PIPELINES)}")
    return "default" if reading == "log" else reading


def _default_jobs(split: str, per_cell: int, cells, reading: str) -> list[Job]:
    return _jobs(split, per_cell, {reading_name(reading): READING_PIPELINES[reading]}, cells)


def planning_jobs(per_cell: int = PLANNING_PER_CELL, cells=PLANNING_CELLS, reading: str = "log") -> list[Job]:
    """Jobs of the planning grid under the default pipeline (what ``plan`` is fitted on
    besides the reporting maps; the full ``swarmtopo bench accuracy`` runs them), the
    cases read as log folders or (``reading="contact-trace"``) as contact traces."""
    return _default_jobs("planning", per_cell, cells, reading)


def calibration_jobs(per_cell: int = CALIBRATION_PER_CELL, cells=PLANNING_CELLS, reading: str = "log") -> list[Job]:
    """Jobs of the calibration grid under the default pipeline (open to tuning code),
    read as log folders or as contact traces (``reading``, as :func:`planning_jobs`)."""
    return _default_jobs("calibration", per_cell, cells, reading)


def has_held_out_family(config: dict[str, Any]) -> bool:
    """Whether a case's arena has holes of ``HELD_OUT_FAMILY``."""
    arena = config["arena"]
    return arena.get("holes", 0) > 0 and HELD_OUT_FAMILY in arena.get("shapes", ())


def cell_of(config: dict[str, Any], cells=CELLS) -> str:
    """The name of the cell among ``cells`` a job's config is a case of."""
    arena, swarm = config["arena"], config["swarm"]
    for cell in cells:
        if (cell.generator == arena["generator"] and cell.agents == swarm["agents"]
                and cell.duration == swarm["duration"] and cell.holes in (None, arena.get("holes"))):
            return cell.name
    raise SwarmtopoError(f"not a case of {SUITE}: {json.dumps(config)}")


# -- the table ----------------------------------------------------------------------------
@dataclass(frozen=True)
class Rate:
    """k right out of n, with its Wilson 95 % interval."""

    right: int
    total: int

    @property
    def rate(self) -> float:
        return self.right / self.total if self.total else float("nan")

    @property
    def interval(self) -> tuple[float, float]:
        return wilson_interval(self.right, self.total)

    def to_json(self) -> dict[str, Any]:
        """``{"right", "total", "rate", "wilson95"}``; rate and interval null for no maps."""
        if not self.total:
            return {"right": 0, "total": 0, "rate": None, "wilson95": None}
        return {"right": self.right, "total": self.total, "rate": self.rate, "wilson95": list(self.interval)}


def outcomes(rows, classifier, cells=CELLS) -> list[dict[str, Any]]:
    """One record per row (of a case of ``cells``): cell, held-out family, truth, estimate,
    confidences, and whether (beta_0, beta_1) is exactly right.

    beta_1 and its confidence are read from the row's stored per-window diagrams by
    ``classifier`` (each region's windows read as in the pipeline), so the table is
    the given classifier's verdict on the stored maps: the shipped one's, whatever
    classifier ran the job.  beta_0 and its confidence are the job's (graph components,
    :mod:`swarmtopo.readers.beta0`).  A failed job
    (too little data to map) counts as wrong.
    """
    records = []
    for row in rows:
        config = row["config"]
        est0, est1, conf0, conf1 = row["est_betti0"], None, None, None
        if row["error"] is None:
            regions = [[w["diagram"] for w in r["windows"]] for r in row["diagrams"]]
            readings = [classifier.read(windows) for windows in regions]
            est1 = sum(reading.betti.get(1, 0) for reading in readings)
            conf1 = classifier.map_confidence([reading.confidence.get(1) for reading in readings], 1)
            conf0 = row["confidence_betti0"]
        right = row["error"] is None and est0 == row["true_betti0"] and est1 == row["true_betti1"]
        records.append({
            "cell": cell_of(config, cells), "index": row["replicate"], "held_out": has_held_out_family(config),
            "agents": config["swarm"]["agents"], "duration": config["swarm"]["duration"],
            "area": case_area(config), "true_betti0": row["true_betti0"], "true_betti1": row["true_betti1"],
            "est_betti0": est0, "est_betti1": est1, "confidence_betti0": conf0, "confidence_betti1": conf1,
            "right": bool(right), "betti0_right": row["error"] is None and est0 == row["true_betti0"],
            "betti1_right": row["error"] is None and est1 == row["true_betti1"], "error": row["error"],
            "seconds": row["t_total"],
        })
    return records


def accuracy_table(records: list[dict[str, Any]]) -> dict[str, Any]:
    """Exact-match rates: overall, per cell, the held-out family, and the rest."""
    def rate(subset):
        return Rate(sum(r["right"] for r in subset), len(subset))

    return {
        "overall": rate(records),
        "cells": {cell.name: rate([r for r in records if r["cell"] == cell.name]) for cell in CELLS},
        "held_out": rate([r for r in records if r["held_out"]]),
        "seen_families": rate([r for r in records if not r["held_out"]]),
    }


def beta1_misses(records: list[dict[str, Any]]) -> tuple[int, int]:
    """(too many, too few): the mapped records whose beta_1 is above / below the truth."""
    mapped = [r for r in records if r["est_betti1"] is not None]
    return (sum(r["est_betti1"] > r["true_betti1"] for r in mapped),
            sum(r["est_betti1"] < r["true_betti1"] for r in mapped))


def most_windows(rows: list[dict[str, Any]]) -> int:
    """The most time windows any region of these stored maps pooled (their ``diagrams``;
    0 without a map): what ``MapConfig.max_windows`` must stay above to leave them alone."""
    return max((len(region["windows"]) for row in rows if row.get("diagrams") for region in row["diagrams"]),
               default=0)


def rate_text(rate: dict[str, Any]) -> str:
    """A rate as a table cell, "k/n = rate [Wilson 95 %]" ("-" for none); ``Rate.to_json`` form."""
    if not rate["total"]:
        return "-"
    lo, hi = rate["wilson95"]
    return f"{rate['right']}/{rate['total']} = {rate['rate']:.2f} [{lo:.2f}, {hi:.2f}]"


def percent_text(rate: dict[str, Any]) -> str:
    """A rate as a table cell, "rate % (k/n)" ("–" for none); ``Rate.to_json`` form."""
    return "–" if rate["rate"] is None else f"{100 * rate['rate']:.0f} % ({rate['right']}/{rate['total']})"


def failures_text(records: list[dict[str, Any]], outcome: str) -> list[str]:
    """Markdown lines naming the records of maps that failed (none: no line); they count as ``outcome``."""
    failed = [r for r in records if r["status"] != "ok"]
    if not failed:
        return []
    return ["", f"{len(failed)} map(s) failed and count as {outcome}:",
            *(f"- {r['cell']} case {r['index']}: {r['status']}: {r['error']}" for r in failed)]


RELIABILITY_EDGES = (0.0, 0.5, 0.7, 0.8, 0.9, 0.95, 0.99, 1.0)
"""Confidence bins of the reliability table: narrow near 1, where most maps are reported."""


def reliability(records: list[dict[str, Any]], n: int, edges: tuple[float, ...] = RELIABILITY_EDGES) -> dict[str, Any]:
    """Calibration of the beta_n confidence: per confidence bin (``edges``), the mean
    confidence and the fraction right; the Brier score against a constant equal to the
    accuracy, and the 95 % interval of how much lower it is (:func:`brier_gain_interval`)."""
    pairs = [(r[f"confidence_betti{n}"], r[f"betti{n}_right"]) for r in records
             if r[f"confidence_betti{n}"] is not None]
    if not pairs:
        return {"bins": [], "brier": None, "brier_constant": None, "brier_gain95": None, "maps": 0}
    p = np.array([c for c, _ in pairs], dtype=float)
    y = np.array([ok for _, ok in pairs], dtype=float)
    which = np.clip(np.digitize(p, edges[1:-1]), 0, len(edges) - 2)
    table = []
    for b in range(len(edges) - 1):
        inside = which == b
        if inside.any():
            table.append({"low": float(edges[b]), "high": float(edges[b + 1]), "maps": int(inside.sum()),
                          "mean_confidence": float(p[inside].mean()), "fraction_right": float(y[inside].mean()),
                          "wilson95": list(wilson_interval(int(y[inside].sum()), int(inside.sum())))})
    return {"bins": table, "brier": float(np.mean((p - y) ** 2)),
            "brier_constant": float(np.mean((y.mean() - y) ** 2)), "brier_gain95": brier_gain_interval(p, y),
            "maps": int(len(y))}


def brier_gain(p: np.ndarray, y: np.ndarray, axis: int = -1) -> np.ndarray:
    """Brier score of a constant equal to the rate of ``y`` minus that of the confidences
    ``p`` (> 0: the confidence beats the constant), along ``axis``."""
    rate = np.mean(y, axis=axis, keepdims=True)
    return np.mean((rate - y) ** 2, axis=axis) - np.mean((p - y) ** 2, axis=axis)


def brier_gain_interval(p: np.ndarray, y: np.ndarray, level: float = 0.95) -> list[float] | None:
    """Percentile interval of :func:`brier_gain` by the paired bootstrap over maps
    (``scipy.stats.bootstrap``, 9,999 resamples, seed 0; the constant is each resample's
    own rate): with a few wrong maps among hundreds, one draw of the suite says little.
    None for fewer than two maps."""
    if len(y) < 2:
        return None
    result = bootstrap((np.asarray(p, float), np.asarray(y, float)), brier_gain, paired=True, vectorized=True,
                       batch=1000, confidence_level=level, method="percentile", rng=np.random.default_rng(0))
    return [float(result.confidence_interval.low), float(result.confidence_interval.high)]


def reliability_bin_lines(rel: dict[str, Any]) -> list[str]:
    """:func:`reliability`'s bins as indented text lines (what the benchmark scripts print)."""
    return [f"  {b['low']:.2f}-{b['high']:.2f}: {b['maps']} maps, said {b['mean_confidence']:.3f}, right "
            f"{b['fraction_right']:.3f} [{b['wilson95'][0]:.2f}, {b['wilson95'][1]:.2f}]" for b in rel["bins"]]


def case_area(config: dict[str, Any]) -> float:
    """Area (mm^2) inside the outer walls of a case: every outer wall of the suite has
    area (500 scale)^2, and two rooms twice that."""
    arena = config["arena"]
    room = (ROOM_SIDE * arena["scale"]) ** 2
    return 2 * room if arena["generator"] == "two_rooms" else room


def run_benchmark(store, *, quick: bool = False, scheduler: str | None = None, workers: int | None = None,
                  progress=None, per_cell: int | None = None, cells=CELLS, planning_per_cell: int = 0,
                  planning_cells=PLANNING_CELLS) -> dict[str, Any]:
    """Run (or resume) the reporting cases of every pipeline, and ``planning_per_cell``
    cases of each planning cell under the default pipeline; the summary document.

    Returns ``{"suite", "cases_per_cell", "seconds", "jobs_per_minute", "pipelines":
    {name: {"table", "reliability"}}, "records", "planning", "planning_reliability"}``
    with tables as from :func:`accuracy_table` (``Rate`` objects as JSON), the records of
    the default pipeline's reporting maps and of the planning maps (what ``plan`` is
    fitted on), and the beta_1 confidence's reliability on the planning maps.
    Each pipeline's maps are read by its shipped classifier (:func:`outcomes`);
    ``paper-theta`` is the paper pipeline's maps read by the paper's published Theta*.
    """
    from .store import iter_jobs
    from .sweep import run_sweep

    per_cell = per_cell or (QUICK_PER_CELL if quick else REPORTING_PER_CELL)
    jobs = reporting_jobs(per_cell, cells=cells)
    planning = planning_jobs(planning_per_cell, planning_cells) if planning_per_cell else []
    summary = run_sweep(jobs + planning, store, scheduler=scheduler, workers=workers, progress=progress,
                        keep="windows")
    classifiers = {name: load_classifier(PIPELINES[name]["classifier"]) for name in PIPELINES}
    paper_theta = published_paper_classifier()
    found: dict[str, list] = {name: [] for name in (*PIPELINES, "paper-theta", "planning")}  # (key, record)
    planning_keys = {job.key for job in planning}
    maps = 0
    # the rows stream (every window's diagrams: one chunk in memory at a time); each list
    # of records is then sorted by key, whatever order the jobs finished in
    for row in iter_jobs(store, keys=[job.key for job in jobs + planning]):
        if row["key"] in planning_keys:
            found["planning"] += [(row["key"], r) for r in outcomes([row], classifiers["default"], cells=planning_cells)]
            continue
        maps += 1
        name = _pipeline_of(row["config"])
        if name is not None:
            found[name] += [(row["key"], r) for r in outcomes([row], classifiers[name])]
        if name == "paper":
            found["paper-theta"] += [(row["key"], r) for r in outcomes([row], paper_theta)]
    by_key = {name: [r for _, r in sorted(pairs, key=lambda pair: pair[0])] for name, pairs in found.items()}
    planning_records = by_key.pop("planning")
    results = by_key
    return {
        "suite": SUITE, "cases_per_cell": per_cell, "maps": maps,
        "seconds": summary.seconds, "jobs_run": summary.run, "workers": summary.workers,
        "pipelines": {name: {"table": {k: (v.to_json() if isinstance(v, Rate) else {c: r.to_json() for c, r in v.items()})
                                       for k, v in accuracy_table(recs).items()},
                             "reliability": {str(n): reliability(recs, n) for n in (0, 1)},
                             "mean_seconds": float(np.mean([r["seconds"] for r in recs])) if recs else None}
                      for name, recs in results.items()},
        "records": results["default"],
        "planning": planning_records,
        "planning_reliability": reliability(planning_records, 1),
    }


def _pipeline_of(config: dict[str, Any]) -> str | None:
    for name, mapping in PIPELINES.items():
        if all(config["map"].get(k) == v for k, v in mapping.items()):
            return name
    return None


PIPELINE_LABELS = {"default": "swarmtopo default", "paper": "paper's methods, trained our way",
                   "paper-theta": "paper's methods, paper's Theta*"}


def _reliability_lines(rel: dict[str, Any], title: str) -> list[str]:
    gain = rel["brier_constant"] - rel["brier"]
    interval = ("" if rel["brier_gain95"] is None else
                ", 95 % interval [{:+.4f}, {:+.4f}] by the paired bootstrap over maps".format(*rel["brier_gain95"]))
    lines = ["", f"{title} ({rel['maps']} maps): Brier score {rel['brier']:.4f} against {rel['brier_constant']:.4f} "
                 f"for a constant confidence equal to the accuracy (the constant's minus the confidence's: "
                 f"{gain:+.4f}{interval}).", "",
             "| confidence | maps | mean confidence | fraction right [Wilson 95 %] |", "|---|---|---|---|"]
    for b in rel["bins"]:
        lo, hi = b["wilson95"]
        lines.append(f"| {b['low']:.2f}-{b['high']:.2f} | {b['maps']} | {b['mean_confidence']:.3f} | "
                     f"{b['fraction_right']:.3f} [{lo:.2f}, {hi:.2f}] |")
    return lines


def markdown(summary: dict[str, Any], command: str) -> str:
    """The benchmark's tables as Markdown (what docs/accuracy.md quotes)."""
    names = list(summary["pipelines"])

    lines = [f"Suite `{summary['suite']}`, {summary['cases_per_cell']} reporting cases per cell, "
             f"{summary['maps']} maps. Command: `{command}`; {summary['jobs_run']} jobs run in "
             f"{summary['seconds'] / 60:.1f} min on {summary['workers']} Dask workers.", "",
             "Exact (beta_0, beta_1), k/n = rate [Wilson 95 %]:", "",
             "| cell | " + " | ".join(PIPELINE_LABELS.get(n, n) for n in names) + " |",
             "|---|" + "---|" * len(names)]
    for c in CELLS:
        lines.append(f"| {c.name} | " + " | ".join(rate_text(summary["pipelines"][n]["table"]["cells"][c.name])
                                                for n in names) + " |")
    for key, label in (("overall", "**all reporting cases**"), ("seen_families", "families seen in tuning"),
                       ("held_out", f"held-out family ({HELD_OUT_FAMILY}-shaped holes)")):
        lines.append(f"| {label} | " + " | ".join(rate_text(summary["pipelines"][n]["table"][key]) for n in names) + " |")
    lines.append("| mean seconds per map | " + " | ".join(
        f"{summary['pipelines'][n]['mean_seconds']:.2f}" if summary["pipelines"][n]["mean_seconds"] else "-"
        for n in names) + " |")
    in_slice = [r for r in summary["records"] if r["index"] < SLICE_PER_CELL]
    if len(in_slice) == SLICE_PER_CELL * len(summary["pipelines"]["default"]["table"]["cells"]):
        lines += ["", f"Regression slice: {sum(r['right'] for r in in_slice)}/{len(in_slice)} exact (the first "
                      f"{SLICE_PER_CELL} reporting cases of every cell, default pipeline; benchmarks/bench_accuracy_slice.py "
                      "reruns them and fails below the 1 % binomial quantile of this rate, Laplace-smoothed)."]
    if summary.get("planning"):
        lines += ["", f"Planning grid ({len(summary['planning'])} maps, default pipeline, 0-3 holes, scales "
                      f"{PLANNING_SCALE_RANGE[0]:g}-{PLANNING_SCALE_RANGE[1]:g}; with the reporting maps, what "
                      "plan.json is fitted on), exact (beta_0, beta_1) per budget:", "",
                  "| budget | maps right [Wilson 95 %] |", "|---|---|"]
        for n, t in PLANNING_BUDGETS:
            rows = [r for r in summary["planning"] if (r["agents"], r["duration"]) == (n, t)]
            if rows:
                lines.append(f"| {n} x {t:g} s | {rate_text(Rate(sum(r['right'] for r in rows), len(rows)).to_json())} |")
    for n_dim in ("1", "0"):
        rel = summary["pipelines"]["default"]["reliability"][n_dim]
        if rel["maps"]:
            lines += _reliability_lines(rel, f"Reliability of the default pipeline's beta_{n_dim} confidence")
    if summary["planning_reliability"]["maps"]:
        lines += _reliability_lines(summary["planning_reliability"], "Reliability of the beta_1 confidence on the planning grid "
                                    "(swarms and logs beyond the suite's budgets; the confidence is fitted on the "
                                    "tuning maps and the calibration grid, not on these)")
    return "\n".join(lines) + "\n"
