"""The accuracy benchmark's regression slice against the count docs/accuracy.md records.

The first ``accuracy.SLICE_PER_CELL`` reporting cases of every cell of the frozen suite
(26 maps), mapped by the default pipeline and read by the shipped ``default``
classifier, as ``swarmtopo bench accuracy`` maps them.  Two checks, each failing the
run (exit 1):

* accuracy: with the recorded k of n maps exactly right and p = (k + 1) / (n + 2)
  (Laplace: a recorded 26/26 does not prove a rate of 1), the count must not fall below
  the 1 % quantile of Bin(n, p) -- a pipeline as good as recorded falls below it in
  about 1 % of runs.  The maps are seeded, so on the platform that recorded k the count
  is k exactly; the margin absorbs a map another platform's floating point turns;
* calibration: the mean beta_1 confidence and the fraction of maps with beta_1 right
  agree within 0.15 (about 2.5 standard deviations of a fraction near 0.9 over n = 26).

The unit suite pins the exact output of a few small maps instead
(``tests/test_golden.py``); this script is the statistical check, run after a change
that is meant to move the maps (and before recording a new count in docs/accuracy.md,
which ``swarmtopo bench accuracy`` writes).  About 2.5 min on one core.

    python benchmarks/bench_accuracy_slice.py [--workers N]
"""

from __future__ import annotations

import argparse
import re
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from functools import partial
from multiprocessing import get_context
from pathlib import Path

import numpy as np
from scipy.stats import binom

from _measure import machine, revision
from swarmtopo.experiments import accuracy as acc
from swarmtopo.experiments.sweep import run_job
from swarmtopo.experiments.store import decode_regions
from swarmtopo.readers.registry import load_classifier

DOC = Path(__file__).resolve().parent.parent / "docs" / "accuracy.md"
QUANTILE = 0.01
"""A pipeline as good as recorded falls below this binomial quantile in about 1 % of runs."""
CALIBRATION_GAP = 0.15
"""Largest gap between the mean beta_1 confidence and the fraction of maps with beta_1 right."""


def recorded_slice(doc: Path = DOC) -> tuple[int, int]:
    """(k, n) of docs/accuracy.md's line ``Regression slice: k/n exact``."""
    match = re.search(r"Regression slice: (\d+)/(\d+) exact", doc.read_text(encoding="utf-8"))
    if match is None:
        sys.exit(f"error: {doc}: no line 'Regression slice: k/n exact' recording the slice's count")
    return int(match.group(1)), int(match.group(2))


def slice_records(workers: int) -> list[dict]:
    """The slice's outcome records (:func:`accuracy.outcomes`), its maps run on ``workers`` processes."""
    jobs = acc.reporting_jobs(per_cell=acc.SLICE_PER_CELL, pipelines={"default": acc.PIPELINES["default"]})
    run = partial(run_job, keep="windows")  # each window's diagram, for the classifier to read
    if workers == 1:
        rows = [run(job) for job in jobs]
    else:  # spawned, not forked: numba's threading layer is not fork-safe
        with ProcessPoolExecutor(workers, mp_context=get_context("spawn")) as pool:
            rows = list(pool.map(run, jobs))
    for row in rows:  # a job's row holds its diagrams encoded, as the store keeps them
        if row["diagrams"] is not None:
            row["diagrams"] = decode_regions(row["diagrams"])
    return acc.outcomes(rows, load_classifier("default"))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--workers", type=int, default=1, help="processes mapping the cases (default 1)")
    args = parser.parse_args()
    if args.workers < 1:
        parser.error(f"--workers must be at least 1, got {args.workers}")
    k, n = recorded_slice()
    print(f"machine: {machine()}; swarmtopo {revision()}")
    start = time.perf_counter()
    records = slice_records(args.workers)
    seconds = time.perf_counter() - start
    right = sum(bool(r["right"]) for r in records)
    floor = int(binom.ppf(QUANTILE, n, (k + 1) / (n + 2)))
    confidences = np.array([r["confidence_betti1"] for r in records], dtype=float)
    gap = abs(confidences.mean() - np.mean([r["betti1_right"] for r in records]))
    print(f"regression slice: {right}/{len(records)} exact in {seconds:.0f} s (recorded {k}/{n} in {DOC.name}; "
          f"fails below {floor})")
    print(f"calibration: mean beta_1 confidence {confidences.mean():.3f}, beta_1 right on "
          f"{np.mean([r['betti1_right'] for r in records]):.3f} (gap {gap:.3f}, at most {CALIBRATION_GAP})")
    for r in records:
        if not r["right"]:
            print(f"  wrong: {r['cell']}, case {r['index']}: beta = ({r['est_betti0']}, {r['est_betti1']}), "
                  f"true ({r['true_betti0']}, {r['true_betti1']})")
    failures = []
    if len(records) != n:
        failures.append(f"the slice has {len(records)} maps, {DOC.name} records {n}: record the new slice's count")
    if right < floor:
        failures.append(f"{right}/{len(records)} exact is below {floor}, the {QUANTILE:.0%} quantile of the "
                        f"recorded {k}/{n}")
    if not np.all((confidences >= 0) & (confidences <= 1)):
        failures.append("a beta_1 confidence missing or outside [0, 1]")
    if gap > CALIBRATION_GAP:
        failures.append(f"confidence and accuracy differ by {gap:.3f} > {CALIBRATION_GAP}")
    for failure in failures:
        print(f"REGRESSION: {failure}")
    print("ok" if not failures else f"{len(failures)} regression(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
