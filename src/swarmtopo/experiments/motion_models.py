"""The motion benchmark: the accuracy benchmark's arenas walked by swarms that are not
all cockroaches (``swarmtopo bench motion``).

Suite ``SUITE`` (frozen: changing anything here is a new suite name).  Cells are a
motion model (``MODELS``: the paper's cockroach and the five walkers of
:mod:`swarmtopo.sim.walkers`) x 0-3 holes, 300 agents x 40 s.  Each case draws from
its own seed an arena as the accuracy benchmark's 300 x 40 s cells do (one hole family
for all its holes, the outer wall, a scale in [0.75, 1.25]) and the model's parameters
uniformly from ``PARAMETER_RANGES``: ranges in which a swarm of 300 crosses the arena
in 40 s (a Brownian agent with D = 150 mm^2/s still walks sqrt(4 D T) = 150 mm).

Each job maps only the log's encounters, as a contact trace (``TRACE_PIPELINE``): no
status rows, no r_d, no speeds, no model name, so the map reads the motion from the
encounters alone.  Seeds are split into tuning and reporting cases as in the accuracy
benchmark (:mod:`.accuracy`); the held-out hole family is left out of tuning.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..arena import HOLE_SHAPES, OUTER_SHAPES
from .accuracy import HELD_OUT_FAMILY, SCALE_RANGE, TRACE_PIPELINE, Rate, brier_gain, failures_text, percent_text
from .grid import Job, suite_case_seed
from .sweep import run_suite, suite_case, suite_jobs

SUITE = "swarmtopo-motion/1"
MODELS = ("cockroach", "billiard", "run-and-tumble", "brownian", "levy", "flocking")
HOLES = (0, 1, 2, 3)
BUDGET = (300, 40.0)
PARAMETER_RANGES: dict[str, dict[str, tuple[float, float]]] = {
    "cockroach": {},
    "billiard": {"speed": (10.0, 20.0)},
    "run-and-tumble": {"speed": (10.0, 20.0), "tumble_rate": (0.1, 1.0)},
    "brownian": {"diffusion": (150.0, 400.0)},
    "levy": {"speed": (10.0, 20.0), "levy_exponent": (1.5, 3.0)},
    "flocking": {"speed": (10.0, 20.0), "align_radius": (30.0, 60.0), "noise": (0.5, 1.5)},
}
"""Per model, the range each parameter (``[swarm]`` option names) is drawn from; the
others keep the model's defaults (Lévy l_0 = 10 mm)."""
REPORTING_PER_CELL = 12
QUICK_PER_CELL = 2
MAX_ATTEMPTS = 20
CONFIDENT = 0.9
"""A hole-free arena read with a hole at this confidence or more is a confident false hole."""


@dataclass(frozen=True)
class Cell:
    """One row of the table: a motion model and a hole count."""

    model: str
    holes: int

    @property
    def name(self) -> str:
        return f"{self.model}, {self.holes} hole{'' if self.holes == 1 else 's'}"


CELLS: tuple[Cell, ...] = tuple(Cell(m, h) for m in MODELS for h in HOLES)


def case_config(cell: Cell, split: str, index: int, attempt: int = 0) -> dict[str, Any]:
    """The ``[arena]`` and ``[swarm]`` tables of one case (module docstring)."""
    rng = np.random.default_rng(suite_case_seed(SUITE, cell.name, split, index, attempt))
    families = [s for s in HOLE_SHAPES if split == "reporting" or s != HELD_OUT_FAMILY]
    arena = {"generator": "random", "holes": cell.holes, "shapes": [families[int(rng.integers(len(families)))]],
             "scale": float(np.round(rng.uniform(*SCALE_RANGE), 4)),
             "outer": OUTER_SHAPES[int(rng.integers(len(OUTER_SHAPES)))]}
    swarm: dict[str, Any] = {"agents": BUDGET[0], "duration": BUDGET[1], "static_fraction": 0.0}
    if cell.model != "cockroach":
        swarm["motion"] = cell.model
        for name, (lo, hi) in PARAMETER_RANGES[cell.model].items():
            swarm[name] = float(np.round(rng.uniform(lo, hi), 3))
    return {"arena": arena, "swarm": swarm}


def case(cell: Cell, split: str, index: int) -> tuple[dict[str, Any], int]:
    """(config tables, case seed) of a case whose holes fit."""
    return suite_case(SUITE, cell, split, index, case_config, MAX_ATTEMPTS)


def jobs(split: str, per_cell: int, cells=CELLS, pipeline: dict[str, Any] = TRACE_PIPELINE) -> list[Job]:
    """The jobs of ``per_cell`` cases of every cell, mapped by ``pipeline`` (default: the
    default pipeline on the encounters only)."""
    return suite_jobs(SUITE, "motion", split, per_cell, cells, case, pipeline)


def records(rows) -> list[dict[str, Any]]:
    """One record per row (a failed job scores as wrong, with no confidence)."""
    out = []
    for row in rows:
        config = row["config"]
        model = config["swarm"].get("motion", "cockroach")
        holes = config["arena"]["holes"]
        ok = row["status"] == "ok"
        estimate = row.get("motion_estimate") or {}
        out.append({"cell": Cell(model, holes).name, "model": model, "holes": holes, "index": row["replicate"],
                    "parameters": {k: v for k, v in config["swarm"].items() if k in PARAMETER_RANGES[model]},
                    "status": row["status"], "error": row["error"],
                    "estimated": [row["est_betti0"], row["est_betti1"]] if ok else None,
                    "exact": ok and row["est_betti0"] == row["true_betti0"] and row["est_betti1"] == holes,
                    "beta1_exact": ok and row["est_betti1"] == holes,
                    "confidence": row["confidence_betti1"] if ok else None,
                    "regime": estimate.get("regime"), "recontact_share": estimate.get("recontact_share"),
                    "seconds": row["t_total"]})
    return out


def table(recs: list[dict[str, Any]]) -> dict[str, Any]:
    """Per cell, per model and overall: exact (beta_0, beta_1), the regime read, confident
    false holes on hole-free arenas, and the beta_1 confidence's Brier gain over a constant."""
    def summarise(subset):
        scored = [r for r in subset if r["confidence"] is not None]
        p = np.array([r["confidence"] for r in scored])
        y = np.array([r["beta1_exact"] for r in scored], dtype=float)
        gain = float(brier_gain(p, y)) if len(scored) >= 2 else None
        rho = [r["recontact_share"] for r in subset if r["recontact_share"] is not None]
        return {"logs": len(subset), "exact": Rate(sum(r["exact"] for r in subset), len(subset)).to_json(),
                "flickering": sum(r["regime"] == "flickering" for r in subset),
                "recontact_share": [min(rho), max(rho)] if rho else None,
                "confident_false_holes": sum(r["holes"] == 0 and r["estimated"] is not None and r["estimated"][1] > 0
                                             and r["confidence"] is not None and r["confidence"] > CONFIDENT
                                             for r in subset),
                "mean_confidence": float(p.mean()) if len(p) else None, "brier_gain": gain}
    cells = {cell.name: summarise([r for r in recs if r["cell"] == cell.name]) for cell in CELLS}
    models = {m: summarise([r for r in recs if r["model"] == m]) for m in MODELS}
    return {"overall": summarise(recs), "models": {k: v for k, v in models.items() if v["logs"]},
            "cells": {k: v for k, v in cells.items() if v["logs"]}}


def run_benchmark(store, *, quick: bool = False, split: str = "reporting", per_cell: int | None = None,
                  scheduler: str | None = None, workers: int | None = None, progress=None, cells=CELLS,
                  keep: str = "map") -> dict[str, Any]:
    """Run (or resume) the cases of ``split``; the summary document (records and :func:`table`)."""
    per_cell = per_cell or (QUICK_PER_CELL if quick else REPORTING_PER_CELL)
    return run_suite(SUITE, split, per_cell, jobs(split, per_cell, cells), store, records, table,
                     {"budget": list(BUDGET)}, scheduler=scheduler, workers=workers, progress=progress, keep=keep)


def markdown(summary: dict[str, Any], command: str) -> str:
    """The benchmark's report as Markdown."""
    def gain(x):
        return "–" if x is None else f"{x:+.2f}"

    def row(name, t):
        conf = "–" if t["mean_confidence"] is None else f"{t['mean_confidence']:.2f}"
        rho = "–" if t["recontact_share"] is None else "{:.2f}-{:.2f}".format(*t["recontact_share"])
        return (f"| {name} | {t['logs']} | {percent_text(t['exact'])} | {t['flickering']} | {rho} | "
                f"{t['confident_false_holes']} | {conf} | {gain(t['brier_gain'])} |")

    head = ["| {} | logs | exact (beta_0, beta_1) | read as flickering | re-contact share | confident false holes "
            "| mean beta_1 confidence | Brier gain |", "|---|---|---|---|---|---|---|---|"]
    n, seconds = summary["budget"]
    lines = [f"# Motion benchmark ({summary['suite']}, {summary['split']} cases)", "",
             f"`{command}`: {summary['cases_per_cell']} cases per cell, {n} agents x {seconds:g} s, the encounters "
             f"only; {summary['jobs_run']} maps run in {summary['seconds']:.0f} s on {summary['workers']} workers.", "",
             head[0].format("model"), head[1]]
    lines += [row(name, t) for name, t in summary["table"]["models"].items()]
    lines.append(row("**all**", summary["table"]["overall"]))
    lines += ["", f"Confident false holes: hole-free arenas read with a hole at a beta_1 confidence above {CONFIDENT:g}. "
              "Brier gain: the Brier score of a constant equal to the share of exact beta_1 minus that of the beta_1 "
              "confidence (above 0: the confidence tells right maps from wrong ones better than the constant)."]
    lines += ["", head[0].format("cell"), head[1]]
    lines += [row(name, t) for name, t in summary["table"]["cells"].items()]
    return "\n".join(lines + failures_text(summary["records"], "wrong")) + "\n"
