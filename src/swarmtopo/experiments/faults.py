"""The fault benchmark: the accuracy benchmark's arenas, sensed by a faulty radio
(``swarmtopo bench faults``).

Suite ``SUITE`` (frozen: changing anything here is a new suite name).  Each case draws
from its own seed an arena as the accuracy benchmark's 300 x 40 s cells do (0-3 holes
of one hole family, the outer wall, a scale in [0.75, 1.25]) and a cockroach swarm of
300 agents x 40 s.  The same case is then mapped at every fault ``LEVELS`` (its log
perturbed by :func:`~swarmtopo.sim.faults.perturb` with the case's own faults stream,
so one case's levels differ only by the faults), as a contact trace (the encounters
only, ``TRACE_PIPELINE``).  ``CURVES`` vary one fault at a time over its
range; ``TOGETHER`` are faults together (the target: 50 % lost, 1 s jitter, 3 % false
encounters and 20 % of agents dying).  Tuning and reporting seeds are split as in the
accuracy benchmark; the held-out hole family is left out of tuning.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..arena import HOLE_SHAPES, OUTER_SHAPES
from ..sim.faults import FAULT_LEVELS
from .accuracy import HELD_OUT_FAMILY, SCALE_RANGE, TRACE_PIPELINE, Rate, brier_gain, failures_text, percent_text
from .grid import Job, faults_table, suite_case_seed
from .sweep import run_suite, suite_case, suite_jobs

SUITE = "swarmtopo-faults/1"
HOLES = (0, 1, 2, 3)
BUDGET = (300, 40.0)
CURVES: dict[str, tuple[float, ...]] = {
    "lost": (0.15, 0.3, 0.45, 0.6),
    "burst_lost": (0.15, 0.3),
    "false_encounters": (0.005, 0.01, 0.02, 0.03, 0.05),
    "jitter": (0.25, 0.5, 1.0, 2.0),
    "clock_offset": (1.0, 2.5, 5.0),
    "dying": (0.1, 0.2, 0.3),
    "duplicated": (0.1, 0.3),
}
"""Per fault, the levels it is measured at alone (``Faults`` field names)."""
TOGETHER: dict[str, dict[str, float]] = {
    "30 % lost, 0.5 s jitter, 1 % false, 10 % dying": {"lost": 0.3, "jitter": 0.5, "false_encounters": 0.01,
                                                        "dying": 0.1},
    "50 % lost, 1 s jitter, 3 % false, 20 % dying": {"lost": 0.5, "jitter": 1.0, "false_encounters": 0.03,
                                                      "dying": 0.2},
}
"""Faults together; the second is the target mix (``TARGET``: at least 90 % exact)."""
TARGET = "50 % lost, 1 s jitter, 3 % false, 20 % dying"
REPORTING_PER_CELL = 4
TOGETHER_PER_CELL = 10
"""Cases per hole count of a ``TOGETHER`` level (more: the target is judged on them)."""
QUICK_PER_CELL = 1
MAX_ATTEMPTS = 20
CONFIDENT = 0.95
"""A wrong map said at this beta_1 confidence or more is confidently wrong."""


@dataclass(frozen=True)
class Level:
    """One fault level: its name, its faults (``Faults`` fields; empty: none) and, on a
    curve, the fault varied and its value."""

    name: str
    faults: tuple[tuple[str, float], ...]
    fault: str | None = None
    value: float = 0.0


def _level_name(fault: str, value: float) -> str:
    unit = " s" if fault in ("jitter", "clock_offset") else " %"
    shown = f"{value:g}" if unit == " s" else f"{100 * value:g}"
    return f"{fault.replace('_', ' ')} {shown}{unit}"


LEVELS: tuple[Level, ...] = (
    Level("none", ()),
    *(Level(_level_name(fault, v), ((fault, v),), fault, v) for fault, values in CURVES.items() for v in values),
    *(Level(name, tuple(sorted(faults.items()))) for name, faults in TOGETHER.items()),
)


@dataclass(frozen=True)
class Cell:
    """One row of the table: a fault level and a hole count."""

    level: Level
    holes: int

    @property
    def name(self) -> str:
        return f"{self.level.name}, {self.holes} hole{'' if self.holes == 1 else 's'}"


@dataclass(frozen=True)
class _Case:
    """The seed key of a case: its hole count only, so every level maps the same case."""

    holes: int

    @property
    def name(self) -> str:
        return f"{self.holes} holes"


CELLS: tuple[Cell, ...] = tuple(Cell(level, h) for level in LEVELS for h in HOLES)


def case_config(case: _Case, split: str, index: int, attempt: int = 0) -> dict[str, Any]:
    """The ``[arena]`` and ``[swarm]`` tables of one case (module docstring)."""
    rng = np.random.default_rng(suite_case_seed(SUITE, case.name, split, index, attempt))
    families = [s for s in HOLE_SHAPES if split == "reporting" or s != HELD_OUT_FAMILY]
    arena = {"generator": "random", "holes": case.holes, "shapes": [families[int(rng.integers(len(families)))]],
             "scale": float(np.round(rng.uniform(*SCALE_RANGE), 4)),
             "outer": OUTER_SHAPES[int(rng.integers(len(OUTER_SHAPES)))]}
    return {"arena": arena, "swarm": {"agents": BUDGET[0], "duration": BUDGET[1], "static_fraction": 0.0}}


def case(cell: Cell, split: str, index: int) -> tuple[dict[str, Any], int]:
    """(config tables with the level's ``[faults]``, case seed) of a case whose holes fit."""
    config, seed = suite_case(SUITE, _Case(cell.holes), split, index, case_config, MAX_ATTEMPTS)
    if cell.level.faults:
        config["faults"] = faults_table(dict(cell.level.faults))
    return config, seed


def per_cell(level: Level, quick: bool, cases: int | None = None) -> int:
    """Cases per hole count of ``level`` (``cases``: that many at every level)."""
    if cases or quick:
        return cases or QUICK_PER_CELL
    return TOGETHER_PER_CELL if level.fault is None and level.faults else REPORTING_PER_CELL


def jobs(split: str, quick: bool = False, cells=CELLS, pipeline: dict[str, Any] = TRACE_PIPELINE,
         cases: int | None = None) -> list[Job]:
    """Every cell's jobs (:func:`per_cell` cases each), mapped by ``pipeline``."""
    out: list[Job] = []
    for cell in cells:
        out += suite_jobs(SUITE, "faults", split, per_cell(cell.level, quick, cases), [cell], case, pipeline)
    return out


def level_of(config: dict[str, Any]) -> Level:
    """The level a job's config was made for."""
    faults = {name: value for name, value in config.get("faults", {}).items() if name in FAULT_LEVELS}
    return next(level for level in LEVELS if dict(level.faults) == faults)


def records(rows) -> list[dict[str, Any]]:
    """One record per row (a failed job scores as wrong, with no confidence)."""
    out = []
    for row in rows:
        config = row["config"]
        level, holes = level_of(config), config["arena"]["holes"]
        ok = row["status"] == "ok"
        sensing = row.get("sensing") or {}
        out.append({"cell": Cell(level, holes).name, "level": level.name, "holes": holes, "index": row["replicate"],
                    "status": row["status"], "error": row["error"],
                    "estimated": [row["est_betti0"], row["est_betti1"]] if ok else None,
                    "exact": ok and row["est_betti0"] == row["true_betti0"] and row["est_betti1"] == holes,
                    "beta1_exact": ok and row["est_betti1"] == holes,
                    "confidence": row["confidence_betti1"] if ok else None,
                    "uncorroborated_share": sensing.get("uncorroborated_share"),
                    "suspected": bool(sensing.get("suspected")), "dropped": sensing.get("dropped"),
                    "events": row["n_events"], "seconds": row["t_total"]})
    return out


def summarise(subset: list[dict[str, Any]]) -> dict[str, Any]:
    """Exact (beta_0, beta_1), the beta_1 confidence's mean, Brier score and gain over a
    constant, confidently wrong maps, and the fault screen's share and warnings."""
    scored = [r for r in subset if r["confidence"] is not None]
    p = np.array([r["confidence"] for r in scored])
    y = np.array([r["beta1_exact"] for r in scored], dtype=float)
    u = [r["uncorroborated_share"] for r in subset if r["uncorroborated_share"] is not None]
    return {"logs": len(subset), "exact": Rate(sum(r["exact"] for r in subset), len(subset)).to_json(),
            "mean_confidence": float(p.mean()) if len(p) else None,
            "brier": float(np.mean((p - y) ** 2)) if len(p) else None,
            "brier_gain": float(brier_gain(p, y)) if len(p) >= 2 else None,
            "confidently_wrong": sum(not r["beta1_exact"] and r["confidence"] is not None
                                     and r["confidence"] >= CONFIDENT for r in subset),
            "warned": sum(r["suspected"] for r in subset),
            "uncorroborated_share": [float(min(u)), float(np.median(u)), float(max(u))] if u else None}


def table(recs: list[dict[str, Any]]) -> dict[str, Any]:
    """Per level, per cell and overall (:func:`summarise`)."""
    levels = {level.name: summarise([r for r in recs if r["level"] == level.name]) for level in LEVELS}
    cells = {cell.name: summarise([r for r in recs if r["cell"] == cell.name]) for cell in CELLS}
    return {"overall": summarise(recs), "levels": {k: v for k, v in levels.items() if v["logs"]},
            "cells": {k: v for k, v in cells.items() if v["logs"]}}


def run_benchmark(store, *, quick: bool = False, split: str = "reporting", per_cell: int | None = None,
                  scheduler: str | None = None, workers: int | None = None, progress=None, cells=CELLS,
                  keep: str = "map") -> dict[str, Any]:
    """Run (or resume) the cases of ``split`` (``per_cell``: that many per hole count at
    every level); the summary document (records and :func:`table`)."""
    todo = jobs(split, quick, cells, cases=per_cell)
    if per_cell or quick:
        cases = per_cell or QUICK_PER_CELL
    else:
        cases = {"levels": REPORTING_PER_CELL, "together": TOGETHER_PER_CELL}
    return run_suite(SUITE, split, cases, todo, store, records, table, {"budget": list(BUDGET)},
                     scheduler=scheduler, workers=workers, progress=progress, keep=keep)


def markdown(summary: dict[str, Any], command: str) -> str:
    """The benchmark's report as Markdown."""
    def number(x, fmt):
        return "–" if x is None else format(x, fmt)

    def row(name, t):
        u = "–" if t["uncorroborated_share"] is None else "{:.3f} / {:.3f} / {:.3f}".format(*t["uncorroborated_share"])
        return (f"| {name} | {t['logs']} | {percent_text(t['exact'])} | {number(t['mean_confidence'], '.2f')} | "
                f"{number(t['brier'], '.3f')} | {number(t['brier_gain'], '+.3f')} | {t['confidently_wrong']} | "
                f"{t['warned']} | {u} |")

    head = [f"| {{}} | logs | exact (beta_0, beta_1) | mean beta_1 confidence | Brier | Brier gain | "
            f"wrong at >= {CONFIDENT:g} | warned | uncorroborated min / median / max |",
            "|---|---|---|---|---|---|---|---|---|"]
    n, seconds = summary["budget"]
    cases = summary["cases_per_cell"]
    per = (f"{cases['levels']} cases per hole count and level ({cases['together']} for faults together)"
           if isinstance(cases, dict) else f"{cases} case per hole count and level")
    t = summary["table"]
    lines = [f"# Fault benchmark ({summary['suite']}, {summary['split']} cases)", "",
             f"`{command}`: {per}, 0-3 holes, {n} agents x {seconds:g} s, the encounters only; "
             f"{summary['jobs_run']} maps run in {summary['seconds']:.0f} s on {summary['workers']} workers.", ""]
    if TARGET in t["levels"]:
        target = t["levels"][TARGET]
        lines += [f"Target ({TARGET}): {percent_text(target['exact'])} exact (goal: at least 90 %).", ""]
    lines += [head[0].format("faults"), head[1]]
    lines += [row(name, lv) for name, lv in t["levels"].items()]
    lines.append(row("**all**", t["overall"]))
    lines += ["", f"Brier: mean (confidence - [beta_1 exact])^2; Brier gain: a constant equal to the share of exact "
              f"beta_1 minus the confidence's Brier (at least 0: the confidence is as good as a constant or better). "
              f"Wrong at >= {CONFIDENT:g}: maps whose beta_1 is wrong said at a confidence of {CONFIDENT:g} or more. "
              "Warned: maps whose log the fault screen read as faulty (docs/model.md, 'Faulty sensing')."]
    lines += ["", head[0].format("cell"), head[1]]
    lines += [row(name, c) for name, c in t["cells"].items()]
    return "\n".join(lines + failures_text(summary["records"], "wrong")) + "\n"


def plot(summary: dict[str, Any], path) -> None:
    """Per fault, exact share, mean beta_1 confidence and Brier gain against its level
    (the fault-free level at 0), with the levels of faults together as points."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    levels = summary["table"]["levels"]
    base = levels.get("none")
    fig, axes = plt.subplots(2, len(CURVES), figsize=(2.6 * len(CURVES), 5.2), sharey="row", constrained_layout=True)
    for col, (fault, values) in enumerate(CURVES.items()):
        xs, rows = [], []
        for level in LEVELS:
            if (level.fault == fault or level.name == "none") and level.name in levels:
                xs.append(level.value if level.fault else 0.0)
                rows.append(levels[level.name])
        if not rows:
            continue
        scale = 1.0 if fault in ("jitter", "clock_offset") else 100.0
        x = np.array(xs) * scale
        top, bottom = axes[0, col], axes[1, col]
        top.plot(x, [r["exact"]["rate"] for r in rows], "o-", label="exact")
        top.plot(x, [r["mean_confidence"] for r in rows], "s--", label="mean confidence")
        top.set_ylim(-0.02, 1.02)
        top.set_title(fault.replace("_", " "), fontsize=10)
        bottom.plot(x, [np.nan if r["brier_gain"] is None else r["brier_gain"] for r in rows], "o-", color="C2")
        bottom.axhline(0.0, color="0.5", lw=0.8)
        bottom.set_xlabel("s" if scale == 1.0 else "%")
    axes[0, 0].set_ylabel("share / confidence")
    axes[1, 0].set_ylabel("Brier gain over a constant")
    axes[0, 0].legend(fontsize=8, loc="lower left")
    title = "fault benchmark: exact beta_1 and its confidence against each fault alone"
    if base is not None:
        title += f" (no fault: {100 * base['exact']['rate']:.0f} % exact)"
    fig.suptitle(title, fontsize=11)
    fig.savefig(path, dpi=110)
    plt.close(fig)
