"""The timeline benchmark: arenas that change once, and static controls (``swarmtopo bench timeline``).

Suite ``SUITE`` (frozen: changing anything here is a new suite name).  Cells are the
kinds of change (:data:`~swarmtopo.changing.CHANGES`: a hole appears, a hole
disappears, a door between two rooms closes, and ``none``, the static controls) x the
swarm sizes ``AGENTS``.  Each case draws from its own seed: the log's duration
uniformly in ``DURATION_RANGE``, the change time uniformly in ``CHANGE_SHARE`` of it,
the holes (0-2 besides the one that changes; 0-2 in all for a door), one hole family
from ``HOLE_SHAPES``, the outer wall, and the scale (``SCALE_RANGE``; two rooms
``DOOR_SCALE_RANGE``, so their area stays within twice one room's).

Seeds are split into tuning and reporting cases as in the accuracy benchmark
(:mod:`.accuracy`): the change penalty of :mod:`swarmtopo.pipeline.timeline` was chosen
on the tuning cases (``lab/tune_timeline.py``), never on the reported ones.

Scoring (:func:`score`).  A true change is *found* when the map has a change point of
the same dimension, from the same count to the same count; its time error is
|t - t_true| of the nearest such point; it is *found within* ``WITHIN`` s when that
error is at most ``WITHIN``.  Every other change point of a log is a false change; a
static control with any change point is a false alarm.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..arena import HOLE_SHAPES, OUTER_SHAPES
from .accuracy import PIPELINES, Rate, failures_text, percent_text
from .grid import Job, suite_case_seed
from .sweep import run_suite, suite_case, suite_jobs

SUITE = "swarmtopo-timeline/1"
KINDS = ("appear", "disappear", "door", "none")
AGENTS = (200, 300, 400)
DURATION_RANGE = (120.0, 300.0)
CHANGE_SHARE = (0.3, 0.7)
"""The change time is drawn uniformly in this share of the log's duration."""
SCALE_RANGE = (0.75, 1.25)
DOOR_SCALE_RANGE = (0.75, 1.0)
WITHIN = 15.0
"""Seconds within which a found change counts as on time (the issue's target)."""
REPORTING_PER_CELL = 20
QUICK_PER_CELL = 5
TUNING_PER_CELL = 8
MAX_ATTEMPTS = 20


@dataclass(frozen=True)
class Cell:
    """One row of the table: a kind of change and a swarm size."""

    kind: str
    agents: int

    @property
    def name(self) -> str:
        what = {"appear": "hole appears", "disappear": "hole disappears", "door": "door closes",
                "none": "static control"}[self.kind]
        return f"{what}, {self.agents} agents"


CELLS: tuple[Cell, ...] = tuple(Cell(kind, n) for kind in KINDS for n in AGENTS)


def case_config(cell: Cell, split: str, index: int, attempt: int = 0) -> dict[str, Any]:
    """The ``[arena]`` and ``[swarm]`` tables of one case (module docstring)."""
    rng = np.random.default_rng(suite_case_seed(SUITE, cell.name, split, index, attempt))
    duration = float(np.round(rng.uniform(*DURATION_RANGE), 1))
    change_time = float(np.round(rng.uniform(*CHANGE_SHARE) * duration, 1))
    holes = int(rng.integers(0, 3))
    shapes = [HOLE_SHAPES[int(rng.integers(len(HOLE_SHAPES)))]]
    scale = float(np.round(rng.uniform(*(DOOR_SCALE_RANGE if cell.kind == "door" else SCALE_RANGE)), 4))
    outer = OUTER_SHAPES[int(rng.integers(len(OUTER_SHAPES)))]
    arena: dict[str, Any] = {"generator": "changing", "change": cell.kind, "holes": holes, "shapes": shapes,
                             "outer": outer, "scale": scale}
    if cell.kind != "none":
        arena["change_time"] = change_time
    return {"arena": arena, "swarm": {"agents": cell.agents, "duration": duration, "static_fraction": 0.0}}


def case(cell: Cell, split: str, index: int) -> tuple[dict[str, Any], int]:
    """(config tables, case seed) of a case whose arena can be built (the next attempt's
    draw replaces one whose holes do not fit)."""
    return suite_case(SUITE, cell, split, index, case_config, MAX_ATTEMPTS)


def jobs(split: str, per_cell: int, cells=CELLS) -> list[Job]:
    """The default pipeline's jobs of ``per_cell`` cases of every cell of ``split``."""
    return suite_jobs(SUITE, "timeline", split, per_cell, cells, case, PIPELINES["default"])


def true_changes(truth: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The changes of a true Betti timeline: ``{"dimension", "t", "from", "to"}``."""
    out = []
    for before, after in zip(truth[:-1], truth[1:]):
        for n in (0, 1):
            if before[f"beta_{n}"] != after[f"beta_{n}"]:
                out.append({"dimension": n, "t": after["from"], "from": before[f"beta_{n}"],
                            "to": after[f"beta_{n}"]})
    return out


def score(truth: list[dict[str, Any]], changes: list[dict[str, Any]]) -> dict[str, Any]:
    """One log's changes scored against its true timeline (module docstring)."""
    expected = true_changes(truth)
    unused = list(changes)
    matched = []
    for true in expected:
        same = [c for c in unused if (c["dimension"], c["from"], c["to"]) == (true["dimension"], true["from"], true["to"])]
        if not same:
            matched.append(None)
            continue
        best = min(same, key=lambda c: abs(c["t"] - true["t"]))
        unused.remove(best)
        matched.append({"error": abs(best["t"] - true["t"]),
                        "covered": best["interval"][0] <= true["t"] <= best["interval"][1],
                        "confidence": best["confidence"]})
    return {"expected": len(expected), "found": sum(m is not None for m in matched),
            "within": sum(m is not None and m["error"] <= WITHIN for m in matched),
            "errors": [m["error"] for m in matched if m is not None],
            "covered": sum(m is not None and m["covered"] for m in matched),
            "false": len(unused)}


def records(rows) -> list[dict[str, Any]]:
    """One record per row: cell, truth, the map's changes, and their score (a failed job
    scores as nothing found)."""
    out = []
    for row in rows:
        config = row["config"]
        cell = Cell(config["arena"]["change"], config["swarm"]["agents"])
        timeline = row.get("timeline") or {}
        changes = timeline.get("changes", []) if row["status"] == "ok" else []
        truth = timeline.get("truth") or [{"from": 0.0, "until": config["swarm"]["duration"], "beta_0": None,
                                           "beta_1": None}]
        scored = score(truth, changes) if row["status"] == "ok" else {
            "expected": 0 if cell.kind == "none" else 1, "found": 0, "within": 0, "errors": [], "covered": 0, "false": 0}
        out.append({"cell": cell.name, "kind": cell.kind, "agents": cell.agents, "index": row["replicate"],
                    "duration": config["swarm"]["duration"], "change_time": config["arena"].get("change_time"),
                    "status": row["status"], "error": row["error"], "changes": changes, **scored,
                    "pooled_right": row["status"] == "ok" and cell.kind == "none"
                    and (row["est_betti0"], row["est_betti1"]) == (row["true_betti0"], row["true_betti1"]),
                    "seconds": row["t_total"]})
    return out


def table(recs: list[dict[str, Any]]) -> dict[str, Any]:
    """Per cell and overall: changes found, found within ``WITHIN`` s, the time error's
    median and 90th percentile, the intervals' coverage, false changes, and the static
    controls' false alarms."""
    def summarise(subset):
        changing = [r for r in subset if r["kind"] != "none"]
        static = [r for r in subset if r["kind"] == "none"]
        errors = [e for r in changing for e in r["errors"]]
        expected = sum(r["expected"] for r in changing)
        return {
            "logs": len(subset),
            "found": Rate(sum(r["found"] for r in changing), expected).to_json(),
            "found_within": Rate(sum(r["within"] for r in changing), expected).to_json(),
            "error_median": float(np.median(errors)) if errors else None,
            "error_p90": float(np.percentile(errors, 90)) if errors else None,
            "interval_coverage": Rate(sum(r["covered"] for r in changing),
                                      sum(r["found"] for r in changing)).to_json(),
            "false_changes_on_changing": sum(r["false"] for r in changing),
            "false_alarms": Rate(sum(r["false"] > 0 for r in static), len(static)).to_json(),
            "static_pooled_right": Rate(sum(r["pooled_right"] for r in static), len(static)).to_json(),
        }
    cells = {cell.name: summarise([r for r in recs if r["cell"] == cell.name]) for cell in CELLS}
    return {"overall": summarise(recs), "cells": {k: v for k, v in cells.items() if v["logs"]},
            "agents": {str(n): summarise([r for r in recs if r["agents"] == n]) for n in AGENTS}}


def run_benchmark(store, *, quick: bool = False, split: str = "reporting", per_cell: int | None = None,
                  scheduler: str | None = None, workers: int | None = None, progress=None, cells=CELLS,
                  keep: str = "map") -> dict[str, Any]:
    """Run (or resume) the cases of ``split``; the summary document (records and :func:`table`)."""
    per_cell = per_cell or (QUICK_PER_CELL if quick else REPORTING_PER_CELL)
    return run_suite(SUITE, split, per_cell, jobs(split, per_cell, cells), store, records, table,
                     {"within_seconds": WITHIN}, scheduler=scheduler, workers=workers, progress=progress, keep=keep)


def markdown(summary: dict[str, Any], command: str) -> str:
    """The benchmark's report as Markdown."""
    pct = percent_text

    def sec(x):
        return "–" if x is None else f"{x:.1f} s"

    lines = [f"# Timeline benchmark ({summary['suite']}, {summary['split']} cases)", "",
             f"`{command}`: {summary['cases_per_cell']} cases per cell, {summary['jobs_run']} maps run in "
             f"{summary['seconds']:.0f} s on {summary['workers']} workers.", "",
             f"| cell | logs | changes found | within {summary['within_seconds']:g} s | time error median | "
             "90th pct | interval holds it | false changes | static: false alarms |",
             "|---|---|---|---|---|---|---|---|---|"]
    rows = [*summary["table"]["cells"].items(), *((f"**{n} agents**", v) for n, v in summary["table"]["agents"].items()
                                                  if v["logs"]), ("**all**", summary["table"]["overall"])]
    for name, t in rows:
        lines.append(f"| {name} | {t['logs']} | {pct(t['found'])} | {pct(t['found_within'])} | "
                     f"{sec(t['error_median'])} | {sec(t['error_p90'])} | {pct(t['interval_coverage'])} | "
                     f"{t['false_changes_on_changing']} | {pct(t['false_alarms'])} |")
    return "\n".join(lines + failures_text(summary["records"], "nothing found")) + "\n"
