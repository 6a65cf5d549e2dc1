"""The exploration benchmark: long halls swept once by a leader (``swarmtopo bench exploration``).

Suite ``SUITE`` (frozen: changing anything here is a new suite name).  Cells are the
number of holes, 1-4 (``HOLES``).  Each case draws from its own seed a hall
(:func:`~swarmtopo.arena.hall_arena`: length uniform in ``LENGTH_RANGE``, width in
``WIDTH_RANGE``, holes of mixed shapes ``HALL_SHAPES`` at random places along it), a
leash R uniform in ``LEASH_RANGE``, and a swarm size uniform in ``AGENTS_RANGE``.  The
leader (:func:`~swarmtopo.beacon.long_axis_track`) waits ``LEADER_SETTLE`` s, then
sweeps the hall once along its middle at ``LEADER_SPEED`` mm/s, from R in from one
end to R in from the other; the log ends ``TAIL`` s after it arrives.

Seeds are split into tuning and reporting cases as in the accuracy benchmark
(:mod:`.accuracy`).  Scoring: the global beta_1 is exact when it equals the number of
holes; each estimated hole's position error is its distance to the nearest true hole's
centroid, and its radius *holds* a hole when that distance is at most the radius.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..arena import HALL_SHAPES
from ..beacon import LEADER_SETTLE, LEADER_SPEED
from .accuracy import PIPELINES, Rate, failures_text, percent_text
from .grid import Job, suite_case_seed
from .sweep import run_suite, suite_case, suite_jobs

SUITE = "swarmtopo-exploration/1"
HOLES = (1, 2, 3, 4)
LENGTH_RANGE = (2400.0, 3600.0)
WIDTH_RANGE = (500.0, 700.0)
LEASH_RANGE = (250.0, 400.0)
AGENTS_RANGE = (200, 400)
TAIL = 20.0
"""Seconds the log runs on after the leader arrives."""
REPORTING_PER_CELL = 12
QUICK_PER_CELL = 2
MAX_ATTEMPTS = 20


@dataclass(frozen=True)
class Cell:
    """One row of the table: halls with this many holes."""

    holes: int

    @property
    def name(self) -> str:
        return f"{self.holes} hole{'s' if self.holes > 1 else ''}"


CELLS: tuple[Cell, ...] = tuple(Cell(n) for n in HOLES)


def case_config(cell: Cell, split: str, index: int, attempt: int = 0) -> dict[str, Any]:
    """The ``[arena]`` and ``[swarm]`` tables of one case (module docstring)."""
    rng = np.random.default_rng(suite_case_seed(SUITE, cell.name, split, index, attempt))
    length = float(np.round(rng.uniform(*LENGTH_RANGE), -1))
    width = float(np.round(rng.uniform(*WIDTH_RANGE), -1))
    leash = float(np.round(rng.uniform(*LEASH_RANGE)))
    agents = int(rng.integers(AGENTS_RANGE[0], AGENTS_RANGE[1] + 1))
    travel = length - 2 * min(leash, length / 2)
    duration = float(math.ceil(LEADER_SETTLE + travel / LEADER_SPEED + TAIL))
    return {"arena": {"generator": "hall", "holes": cell.holes, "shapes": sorted(HALL_SHAPES), "length": length,
                      "width": width},
            "swarm": {"agents": agents, "duration": duration, "static_fraction": 0.0, "leash": leash,
                      "leader_speed": LEADER_SPEED}}


def case(cell: Cell, split: str, index: int) -> tuple[dict[str, Any], int]:
    """(config tables, case seed) of a case whose hall can be built."""
    return suite_case(SUITE, cell, split, index, case_config, MAX_ATTEMPTS)


def jobs(split: str, per_cell: int, cells=CELLS) -> list[Job]:
    """The default pipeline's jobs of ``per_cell`` cases of every cell of ``split``."""
    return suite_jobs(SUITE, "exploration", split, per_cell, cells, case, PIPELINES["default"])


def records(rows) -> list[dict[str, Any]]:
    """One record per row: the cell, the global count, and each estimated hole's error (a
    failed job scores as wrong, with no holes)."""
    out = []
    for row in rows:
        config = row["config"]
        found = row.get("exploration") if row["status"] == "ok" else None
        true = np.asarray(found["true_holes"] if found else [], dtype=float).reshape(-1, 2)
        errors, held = [], 0
        for hole in (found or {}).get("holes", []):
            if len(true):
                error = float(np.hypot(true[:, 0] - hole["x"], true[:, 1] - hole["y"]).min())
                errors.append(error)
                held += error <= hole["radius"]
        out.append({"cell": Cell(config["arena"]["holes"]).name, "holes": config["arena"]["holes"],
                    "index": row["replicate"], "agents": config["swarm"]["agents"], "leash": config["swarm"]["leash"],
                    "length": config["arena"]["length"], "width": config["arena"]["width"],
                    "status": row["status"], "error": row["error"],
                    "estimated": row["est_betti1"] if row["status"] == "ok" else None,
                    "exact": row["status"] == "ok" and row["est_betti1"] == config["arena"]["holes"],
                    "position_errors": errors, "held": held, "warnings": (found or {}).get("warnings", []),
                    "seconds": row["t_total"]})
    return out


def table(recs: list[dict[str, Any]]) -> dict[str, Any]:
    """Per cell and overall: exact global beta_1, and the position errors' median and 90th percentile."""
    def summarise(subset):
        errors = [e for r in subset for e in r["position_errors"]]
        return {"logs": len(subset), "exact": Rate(sum(r["exact"] for r in subset), len(subset)).to_json(),
                "under": sum(r["estimated"] is not None and r["estimated"] < r["holes"] for r in subset),
                "over": sum(r["estimated"] is not None and r["estimated"] > r["holes"] for r in subset),
                "estimates": len(errors),
                "error_median": float(np.median(errors)) if errors else None,
                "error_p90": float(np.percentile(errors, 90)) if errors else None,
                "radius_holds": Rate(sum(r["held"] for r in subset), len(errors)).to_json()}
    cells = {cell.name: summarise([r for r in recs if r["cell"] == cell.name]) for cell in CELLS}
    return {"overall": summarise(recs), "cells": {k: v for k, v in cells.items() if v["logs"]}}


def run_benchmark(store, *, quick: bool = False, split: str = "reporting", per_cell: int | None = None,
                  scheduler: str | None = None, workers: int | None = None, progress=None, cells=CELLS,
                  keep: str = "map") -> dict[str, Any]:
    """Run (or resume) the cases of ``split``; the summary document (records and :func:`table`)."""
    per_cell = per_cell or (QUICK_PER_CELL if quick else REPORTING_PER_CELL)
    return run_suite(SUITE, split, per_cell, jobs(split, per_cell, cells), store, records, table,
                     {"leader_speed": LEADER_SPEED}, scheduler=scheduler, workers=workers, progress=progress, keep=keep)


def markdown(summary: dict[str, Any], command: str) -> str:
    """The benchmark's report as Markdown."""
    pct = percent_text

    def mm(x):
        return "–" if x is None else f"{x:.0f} mm"

    lines = [f"# Exploration benchmark ({summary['suite']}, {summary['split']} cases)", "",
             f"`{command}`: {summary['cases_per_cell']} cases per cell, {summary['jobs_run']} maps run in "
             f"{summary['seconds']:.0f} s on {summary['workers']} workers; the leader moves at "
             f"{summary['leader_speed']:g} mm/s.", "",
             "| cell | logs | exact global beta_1 | too few | too many | holes placed | position error median | "
             "90th pct | radius holds it |", "|---|---|---|---|---|---|---|---|---|"]
    for name, t in [*summary["table"]["cells"].items(), ("**all**", summary["table"]["overall"])]:
        lines.append(f"| {name} | {t['logs']} | {pct(t['exact'])} | {t['under']} | {t['over']} | {t['estimates']} | "
                     f"{mm(t['error_median'])} | {mm(t['error_p90'])} | {pct(t['radius_holds'])} |")
    return "\n".join(lines + failures_text(summary["records"], "wrong")) + "\n"
