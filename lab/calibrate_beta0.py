"""Fit beta_0's confidence model on the benchmark's tuning cases cut short; check it on reporting cases.

Full-length benchmark logs always give the right beta_0, so they cannot calibrate it.
Cut short, they can: in the first seconds a room's agents are many groups not yet
linked, and beta_0 counts too many regions (or, in the two-rooms cell, misses a room
whose few encounters are all fragments).  Each case of every cell is simulated once and
its log cut to its first ``CUTS`` seconds (and kept whole); each cut is split into
regions as ``swarmtopo map`` does (``pipeline.split_regions``, default options), and
its beta_0 and :class:`~swarmtopo.readers.beta0.Beta0Evidence` recorded.  The logistic model
(:class:`~swarmtopo.readers.beta0.Beta0Model`) is fitted on the tuning cases (inside
``tuning_session``) and written to ``src/swarmtopo/data/beta0-confidence.json``; the
reliability table on the reporting cases, cut the same way, is printed as Markdown
(docs/accuracy.md, "Confidence") beside the previous rule, a constant 0.9992 (the
tuning maps' rate), and a constant equal to the reporting cuts' own rate.  A cut with no
region is a map refused ("too little data"), not a beta_0: it is counted apart.

Usage::

    python lab/calibrate_beta0.py [--tuning-per-cell 96] [--reporting-per-cell 30] [--processes 2]
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
from sklearn.linear_model import LogisticRegression

from swarmtopo import __version__
from swarmtopo.readers.beta0 import Beta0Evidence, Beta0Model
from swarmtopo.errors import SwarmtopoError
from swarmtopo.experiments.accuracy import (CELLS, REPORTING_PER_CELL, SUITE, TUNING_PER_CELL, built_case, reliability,
                                            tuning_arena)
from swarmtopo.experiments.sweep import stripped_log
from swarmtopo.io.logs import write_json
from swarmtopo.pipeline import MapConfig
from swarmtopo.pipeline.regions import split_regions
from swarmtopo.sim import simulate

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "src" / "swarmtopo" / "data" / "beta0-confidence.json"
CUTS = (0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 13.0, 20.0, None)
"""Seconds of each log kept (None: the whole log)."""
PREVIOUS_RATE = 0.9992
"""The previous rule: beta_0's confidence was the tuning maps' rate, whatever the log."""


def _cuts(task) -> list[dict]:
    split, cell_index, index = task
    cell = CELLS[cell_index]
    _, _, arena, stream = tuning_arena(cell, index) if split == "tuning" else built_case(cell, "reporting", index)
    log = stripped_log(simulate(arena, cell.agents, cell.duration, rng=stream).log)
    rows = []
    for cut in CUTS:
        part = log if cut is None else log.window(0.0, cut)
        row = {"cell": cell.name, "index": index, "cut": cut, "true_betti0": arena.betti[0]}
        try:
            evidence = split_regions(part, MapConfig()).beta0
        except SwarmtopoError:
            row["evidence"] = None  # refused: too little data
        else:
            row["evidence"] = evidence.to_json()
        rows.append(row)
    return rows


def _run(split: str, per_cell: int, processes: int) -> list[dict]:
    tasks = [(split, c, i) for i in range(per_cell) for c in range(len(CELLS))]
    with ProcessPoolExecutor(processes) as pool:
        return [row for rows in pool.map(_cuts, tasks, chunksize=4) for row in rows]


def _outcomes(rows: list[dict]) -> tuple[list[Beta0Evidence], np.ndarray]:
    mapped = [r for r in rows if r["evidence"] is not None]
    evidence = [Beta0Evidence(**r["evidence"]) for r in mapped]
    right = np.array([e.regions == r["true_betti0"] for e, r in zip(evidence, mapped)])
    return evidence, right


def fit(evidence: list[Beta0Evidence], right: np.ndarray, provenance: dict) -> Beta0Model:
    """The two logistic models of :class:`Beta0Model` (one feature each)."""
    pairs = {}
    for part, chosen in (("one", [e.regions == 1 for e in evidence]), ("several", [e.regions >= 2 for e in evidence])):
        chosen = np.array(chosen)
        x = np.array([[Beta0Model.feature(e)] for e, keep in zip(evidence, chosen) if keep])
        y = right[chosen]
        if len(np.unique(y)) < 2:
            raise SystemExit(f"the {part}-region cuts are all {'right' if y.all() else 'wrong'} ({len(y)} cuts): "
                             "too few to fit; use a larger --tuning-per-cell")
        model = LogisticRegression(C=1.0).fit(x, y)
        pairs[part] = (float(model.intercept_[0]), float(model.coef_[0, 0]))
        provenance[f"{part}_maps"], provenance[f"{part}_right"] = int(len(y)), int(y.sum())
    return Beta0Model(pairs["one"], pairs["several"], provenance)


def _table(records: list[dict]) -> tuple[str, dict]:
    rel = reliability(records, 0)
    lines = ["| confidence | maps | mean confidence | fraction right [Wilson 95 %] |", "|---|---|---|---|"]
    for b in rel["bins"]:
        lo, hi = b["wilson95"]
        lines.append(f"| {b['low']:.2f}-{b['high']:.2f} | {b['maps']} | {b['mean_confidence']:.3f} | "
                     f"{b['fraction_right']:.3f} [{lo:.2f}, {hi:.2f}] |")
    return "\n".join(lines), rel


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tuning-per-cell", type=int, default=TUNING_PER_CELL)
    parser.add_argument("--reporting-per-cell", type=int, default=REPORTING_PER_CELL)
    parser.add_argument("--processes", type=int, default=2)
    args = parser.parse_args()
    start = time.perf_counter()
    tuning = _run("tuning", args.tuning_per_cell, args.processes)
    evidence, right = _outcomes(tuning)
    model = fit(evidence, right, {
        "name": "beta0-confidence", "suite": SUITE, "swarmtopo": __version__, "script": "lab/calibrate_beta0.py",
        "data": f"tuning cases, {args.tuning_per_cell} per cell, cut to their first {list(CUTS[:-1])} s and whole",
        "refused_cuts": sum(r["evidence"] is None for r in tuning)})
    write_json(model.to_json(), OUT)
    print(f"fitted on {len(right)} tuning cuts ({model.provenance['refused_cuts']} refused as too little data): "
          f"one {model.one}, several {model.several}; wrote {OUT.relative_to(ROOT)}")

    reporting = _run("reporting", args.reporting_per_cell, args.processes)
    evidence, right = _outcomes(reporting)
    for name, confidences in (("fitted model", [model.confidence(e) for e in evidence]),
                              (f"previous rule (constant {PREVIOUS_RATE})", [PREVIOUS_RATE] * len(evidence))):
        records = [{"confidence_betti0": p, "betti0_right": bool(ok)} for p, ok in zip(confidences, right)]
        table, rel = _table(records)
        print(f"\nreporting cuts, {name}: {int(right.sum())}/{len(right)} right "
              f"({sum(r['evidence'] is None for r in reporting)} refused); Brier {rel['brier']:.4f} against "
              f"{rel['brier_constant']:.4f} for a constant equal to the rate\n{table}")
    whole = [r for r in reporting if r["cut"] is None and r["evidence"] is not None]
    p_whole = [model.confidence(Beta0Evidence(**r["evidence"])) for r in whole]
    print(f"\nwhole reporting logs: {len(whole)} maps, confidence {min(p_whole):.4f}-{max(p_whole):.4f}; "
          f"{time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
